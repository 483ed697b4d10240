//! `radiant render --partition K/N`: renders one sample partition of one
//! frame into a partial EXR file (the film's sums and what rendered them;
//! `radiant::farm::partial`) for `radiant merge` to add up.

use super::{RenderArgs, check_frames, check_output, frame_path};
use crate::cli::diagnostic::report;
use radiant::Registry;
use radiant::backend::{Progress, choose};
use radiant::extract::{Sequence, SequenceOptions};
use radiant::farm::partial::{self, Header};
use radiant::farm::partition::Partition;
use radiant::film::Film;

/// Renders partition `partition` of the frame `args` names.
pub(super) fn run(
    registry: &Registry,
    args: &RenderArgs,
    partition: Partition,
) -> miette::Result<()> {
    let frame = match args.frames {
        Some((first, last)) if last > first => miette::bail!(
            "--partition renders one frame, not frames {first}..{last}: run one render per frame (`radiant farm slurm … --partitions N` writes those jobs)"
        ),
        frames => frames.map(|(first, _)| first),
    };
    let is_exr = args
        .output
        .extension()
        .is_some_and(|e| e.eq_ignore_ascii_case("exr"));
    if !is_exr {
        miette::bail!(
            "cannot write `{}`: a partition is a partial EXR file for `radiant merge`; name it .exr",
            args.output.display()
        );
    }
    check_output(&frame_path(&args.output, 0))?;
    let mut scene = radiant::scene::load(&args.scene).map_err(report)?;
    super::passes::check(args, &scene.settings)?;
    let scene_bytes = std::fs::read(&args.scene)
        .map_err(|e| miette::miette!("cannot read the scene `{}`: {e}", args.scene.display()))?;
    let timeline = scene.timeline;
    let frame = frame.unwrap_or(timeline.start);
    check_frames(&args.scene, &timeline, (frame, frame))?;
    let output = frame_path(&args.output, frame);
    if args.skip_existing && output.exists() {
        eprintln!(
            "`{}` exists; partition {partition} of frame {frame} skipped",
            output.display()
        );
        return Ok(());
    }
    radiant::world::systems::check_mesh_files(&scene, &[frame]).map_err(report)?;
    let overrides = args.sampling.overrides(&args.film);
    let options = SequenceOptions {
        lock_noise: args.lock_noise,
        ..SequenceOptions::default()
    };
    let (sequence, _) =
        Sequence::new(&mut scene, registry, &overrides, &options, frame).map_err(report)?;
    let s = sequence.scene();
    let settings = &s.settings;
    let samples = partition
        .samples(settings.spp)
        .map_err(|e| miette::miette!("{e}"))?;
    let gpu_options = radiant::backend::GpuOptions::default();
    let mut backend = choose(args.backend, &gpu_options, s, &mut |note| {
        eprintln!("{note}")
    })
    .map_err(|e| miette::miette!("{e}"))?;
    let mut film =
        Film::try_new(settings.width, settings.height).map_err(|e| miette::miette!("{e}"))?;
    let pass = args
        .film
        .thread_pool()?
        .install(|| backend.render_samples(s, &mut film, samples.clone(), &Progress::none()))
        .map_err(|e| miette::miette!("{e}"))?;
    let header = Header {
        invalid_samples: film.invalid_samples,
        ..Header::new(
            &args.scene,
            &scene_bytes,
            frame,
            settings,
            Some(partition),
            samples.clone(),
        )
    };
    partial::write(&output, &header, &film).map_err(|e| miette::miette!("{e}"))?;
    eprintln!(
        "rendered partition {partition} of frame {frame} (samples {}..{} of {}), {}x{} in {:.3} s → {}",
        samples.start,
        samples.end,
        settings.spp,
        settings.width,
        settings.height,
        pass.time.as_secs_f64(),
        output.display()
    );
    Ok(())
}
