//! `radiant render`: render a scene, or a range of its frames, to image
//! files.

mod banded;
mod partition;
mod passes;
mod progressive;
mod spp_map;
mod strategies;
mod whole_cpu;

use super::diagnostic::report;
use super::film_args::FilmArgs;
use super::output_args::OutputArgs;
use super::sampling_args::SamplingArgs;
use clap::Args;
use indicatif::{ProgressBar, ProgressStyle};
use radiant::Registry;
use radiant::backend::{Backend, BackendKind, Progress, choose};
use radiant::extract::{Overrides, Sequence, SequenceOptions};
use radiant::world::Timeline;
use radiant::world::systems::substitute_frame;
use std::path::{Path, PathBuf};
use std::time::{Duration, Instant};

/// Options of `radiant render`.
#[derive(Args)]
pub struct RenderArgs {
    /// The scene file (YAML).
    scene: PathBuf,
    /// Output image: .png (tone-mapped sRGB, 8 or 16 bit), .jpg/.jpeg
    /// (tone-mapped sRGB), .exr (linear float or half RGB) or .hdr (linear
    /// Radiance RGBE). A run of `#` in the name becomes the frame number,
    /// zero-padded to the run's length (`out/frame_####.png`). Default: the
    /// scene file's name with .png in the current folder (`NAME_####.png`
    /// for a range of frames).
    #[arg(short = 'o', long = "output", value_name = "OUTPUT")]
    output_arg: Option<PathBuf>,
    /// The output: `--output`, or the default (see
    /// [`RenderArgs::with_default_output`]).
    #[arg(skip)]
    output: PathBuf,
    /// The frames to render: `A..B` (inclusive) or one frame `N` (default:
    /// the scene's first frame).
    #[arg(long, value_parser = parse_frames)]
    frames: Option<(i64, i64)>,
    /// Leave frames whose output file exists (files are written whole or
    /// not at all, so an existing one is finished): resumes an interrupted
    /// sequence.
    #[arg(long)]
    skip_existing: bool,
    /// Use the base seed in every frame (the same noise pattern in each,
    /// for A/B comparisons) instead of one seed per frame.
    #[arg(long)]
    lock_noise: bool,
    #[command(flatten)]
    sampling: SamplingArgs,
    #[command(flatten)]
    encoding: OutputArgs,
    /// Which backend renders: `gpu` (fails where there is no adapter or a
    /// module lacks GPU code), `cpu`, or `auto` (the GPU where a hardware
    /// adapter can render the scene, else the CPU; says which on stderr).
    #[arg(long, value_enum, default_value_t = BackendKind::Auto)]
    backend: BackendKind,
    /// On the GPU, count traversal work too (nodes visited, primitives
    /// tested per ray; slows rendering) and print the rays by kind.
    #[arg(long)]
    gpu_stats: bool,
    /// On the GPU, the kernel: `megakernel` (one invocation traces a whole
    /// path) or `wavefront` (generate, extend, shade, connect and
    /// accumulate stages with queues between them; with `--gpu-stats` both
    /// print their GPU time per stage).
    #[arg(long, value_enum, default_value_t = radiant::backend::GpuKernel::Megakernel)]
    gpu_kernel: radiant::backend::GpuKernel,
    /// On the GPU, the hierarchy layout: `binary` (two child boxes per
    /// 64-byte node) or `wide` (compressed wide BVH: eight quantized child
    /// boxes per 80-byte node).
    #[arg(long, value_enum, default_value_t = radiant::backend::BvhLayout::Binary)]
    gpu_bvh: radiant::backend::BvhLayout,
    /// The widest instruction set the CPU traversal may use: `baseline`,
    /// `avx2` or `avx512` (default: the best the CPU has). Stands in on one
    /// machine for a CPU without the wider ones; the image is the same.
    #[arg(long, value_enum, value_name = "ISA")]
    max_isa: Option<radiant::accel::InstructionSet>,
    /// Render only the K-th of N disjoint sample partitions of one frame
    /// (`3/16`) into a partial EXR file for `radiant merge`.
    #[arg(long, value_parser = clap::value_parser!(radiant::farm::partition::Partition))]
    partition: Option<radiant::farm::partition::Partition>,
    #[command(flatten)]
    progressive: progressive::ProgressiveArgs,
    #[command(flatten)]
    film: FilmArgs,
    #[command(flatten)]
    passes: passes::PassArgs,
    /// Also write a heat map of the samples each pixel took as a PNG
    /// (magma: black none, yellow the most): where adaptive sampling
    /// (`sampler: {adaptive: …}`) spent them. A run of `#` is the frame
    /// number, as in `--output`. Renders on the CPU.
    #[arg(long, value_name = "MAP.png")]
    spp_map: Option<PathBuf>,
    /// Also write one linear EXR per sampling strategy of the integrator
    /// into this folder (`bdpt`: `s{s}_t{t}.exr` for s light and t camera
    /// vertices, every path length up to `max_depth`), each holding that
    /// strategy's MIS-weighted contributions: Veach's per-strategy images,
    /// which sum to the image. A run of `#` is the frame number, as in
    /// `--output`. Renders on the CPU.
    #[arg(long, value_name = "DIR")]
    strategies: Option<PathBuf>,
}

impl RenderArgs {
    /// These arguments with the default output name where none was given:
    /// the scene file's stem with `.png`, in the current folder, and a
    /// frame-number pattern where `--frames` names several frames.
    pub fn with_default_output(mut self) -> Self {
        if let Some(output) = self.output_arg.take() {
            self.output = output;
        } else {
            let stem = self
                .scene
                .file_stem()
                .map(|s| s.to_string_lossy().into_owned())
                .unwrap_or_else(|| "render".into());
            let several = self.frames.is_some_and(|(a, b)| b > a);
            self.output = PathBuf::from(if several {
                format!("{stem}_####.png")
            } else {
                format!("{stem}.png")
            });
        }
        self
    }
}

/// Parses `A..B` or `N`.
pub fn parse_frames(text: &str) -> Result<(i64, i64), String> {
    let number = |s: &str| {
        s.trim()
            .parse::<i64>()
            .map_err(|_| format!("`{s}` is not a frame number; expected A..B or N"))
    };
    let (a, b) = match text.split_once("..") {
        Some((a, b)) => (number(a)?, number(b.trim_start_matches('='))?),
        None => {
            let n = number(text)?;
            (n, n)
        }
    };
    if b < a {
        return Err(format!(
            "the range {a}..{b} is empty; expected A..B with A ≤ B"
        ));
    }
    Ok((a, b))
}

/// Checks that `output` can be written: a name whose extension is a format
/// Radiant writes, in a folder that exists.
pub(super) fn check_output(output: &Path) -> miette::Result<()> {
    if radiant::film::encode::Format::of(output).is_err() {
        miette::bail!(
            "cannot write `{}`: the output name must end in {}",
            output.display(),
            radiant::film::encode::Format::EXTENSIONS
        );
    }
    if output.is_dir() {
        miette::bail!("cannot write `{}`: it is a folder", output.display());
    }
    if let Some(dir) = output.parent().filter(|d| !d.as_os_str().is_empty()) {
        if !dir.exists() {
            miette::bail!(
                "cannot write `{}`: the folder `{}` does not exist",
                output.display(),
                dir.display()
            );
        }
        if !dir.is_dir() {
            miette::bail!(
                "cannot write `{}`: `{}` is not a folder",
                output.display(),
                dir.display()
            );
        }
    }
    Ok(())
}

/// Checks that the frames `first..=last` are among the scene's.
pub(super) fn check_frames(
    scene: &Path,
    timeline: &Timeline,
    (first, last): (i64, i64),
) -> miette::Result<()> {
    if !(timeline.contains(first) && timeline.contains(last)) {
        miette::bail!(
            "frames {first}..{last} are outside the scene's frames {}..{} (`animation: {{frames: [first, last]}}` in `{}` sets them)",
            timeline.start,
            timeline.end,
            scene.display()
        );
    }
    Ok(())
}

/// The output file of `frame`.
pub(super) fn frame_path(output: &Path, frame: i64) -> PathBuf {
    let name = output
        .file_name()
        .map(|n| n.to_string_lossy().into_owned())
        .unwrap_or_default();
    output.with_file_name(substitute_frame(&name, frame))
}

/// Time spent per phase of a sequence.
#[derive(Default)]
struct Totals {
    frames: u64,
    skipped: u64,
    update: Duration,
    bvh: Duration,
    render: Duration,
}

/// Renders as the arguments say.
pub fn run(registry: &Registry, args: &RenderArgs) -> miette::Result<()> {
    // The flags alone first, before the scene is read; then with its keys.
    passes::check(args, &radiant::settings::RenderSettings::default())?;
    whole_cpu::check_flags(args)?;
    if let Some(widest) = args.max_isa {
        radiant::accel::limit_instruction_set(widest);
    }
    if let Some(p) = args.partition {
        return partition::run(registry, args, p);
    }
    let pattern = args.output.to_string_lossy().contains('#');
    check_output(&frame_path(&args.output, 0))?;
    let mut scene = radiant::scene::load(&args.scene).map_err(report)?;
    passes::check(args, &scene.settings)?;
    let progressive = progressive::start(args)?;
    let timeline = scene.timeline;
    let (first, last) = args.frames.unwrap_or((timeline.start, timeline.start));
    check_frames(&args.scene, &timeline, (first, last))?;
    let sequence = args.frames.is_some();
    if last > first && !pattern {
        miette::bail!(
            "cannot write {} frames to `{}`: put a run of `#` in the output name for the frame number, as in `out/frame_####.png`",
            last - first + 1,
            args.output.display()
        );
    }
    let overrides = Overrides {
        output: args.encoding.overrides(),
        ..args.sampling.overrides(&args.film)
    };
    let overrides = args.passes.overrides(overrides);
    let options = SequenceOptions {
        lock_noise: args.lock_noise,
        ..SequenceOptions::default()
    };
    let pool = args.film.thread_pool()?;
    let todo: Vec<i64> = (first..=last)
        .filter(|&f| !(args.skip_existing && frame_path(&args.output, f).exists()))
        .collect();
    // Every deforming mesh's file is there before the first frame renders.
    radiant::world::systems::check_mesh_files(&scene, &todo).map_err(report)?;
    let mut totals = Totals {
        skipped: (last - first + 1) as u64 - todo.len() as u64,
        ..Totals::default()
    };
    let started = Instant::now();
    let mut state: Option<Sequence> = None;
    let mut bar: Option<ProgressBar> = None;
    let mut backend: Option<Box<dyn Backend>> = None;
    for &frame in &todo {
        let update = match &mut state {
            None => {
                let (s, u) = Sequence::new(&mut scene, registry, &overrides, &options, frame)
                    .map_err(report)?;
                let r = s.scene();
                for (shape, what) in &r.stats.repaired_shapes {
                    eprintln!("warning: {shape}: {}", what.describe());
                }
                for warning in radiant::extract::facing::back_facing(r) {
                    eprintln!("warning: {warning}");
                }
                state = Some(s);
                u
            }
            Some(s) => s.go_to(&mut scene, registry, frame).map_err(report)?,
        };
        let s = state.as_ref().expect("built above").scene();
        let settings = &s.settings;
        let backend = match &mut backend {
            Some(b) => b,
            None => backend.insert(
                choose(
                    // First-hit planes, sample counts and strategies are
                    // recorded on the CPU.
                    if args.passes.wanted(settings) || whole_cpu::asked(args).is_some() {
                        BackendKind::Cpu
                    } else {
                        args.backend
                    },
                    &radiant::backend::GpuOptions {
                        stats: args.gpu_stats,
                        kernel: args.gpu_kernel,
                        bvh: args.gpu_bvh,
                        ..Default::default()
                    },
                    s,
                    &mut |note| eprintln!("{note}"),
                )
                .map_err(|e| miette::miette!("{e}"))?,
            ),
        };
        let per_frame = settings.width as u64 * settings.height as u64 * settings.spp as u64;
        let bar = bar.get_or_insert_with(|| {
            let bar = ProgressBar::new(per_frame * todo.len() as u64);
            let template = if todo.len() > 1 {
                "{msg} {bar:40} {percent:>3}% {elapsed_precise} eta {eta}"
            } else {
                "{bar:40} {percent:>3}% {elapsed_precise} eta {eta}"
            };
            bar.set_style(ProgressStyle::with_template(template).expect("the template is valid"));
            bar
        });
        bar.set_message(format!("frame {frame}"));
        let base = totals.frames * per_frame;
        let progress = |done: u64, _total: u64| bar.set_position(base + done);
        let path = frame_path(&args.output, frame);
        if progressive.as_ref().is_some_and(|p| p.asked()) && settings.output.alpha {
            miette::bail!(
                "alpha (film: {{alpha: true}} or --alpha) needs a whole render: --time, \
                 --checkpoint and --resume write the image alone; leave alpha out or render a \
                 fixed --spp"
            );
        }
        // Alpha is the coverage plane, which the passes record.
        let planes = args.passes.wanted(settings) || settings.output.alpha;
        whole_cpu::check_planes(args, planes)?;
        let session = progressive.as_ref().filter(|p| p.takes(s, planes));
        let rendered = pool.install(|| {
            let progress = Progress::new(&progress);
            if let Some(map) = &args.spp_map {
                let note = |line: &str| bar.suspend(|| eprintln!("{line}"));
                spp_map::write(s, &path, &frame_path(map, frame), &progress, &note)
            } else if let Some(dir) = &args.strategies {
                let note = |line: &str| bar.suspend(|| eprintln!("{line}"));
                strategies::write(s, &path, &frame_path(dir, frame), &progress, &note)
            } else if let Some(session) = session {
                let note = |line: &str| bar.suspend(|| eprintln!("{line}"));
                session.render(args, backend.as_mut(), (s, frame), &path, &progress, &note)
            } else if planes {
                let note = |line: &str| bar.suspend(|| eprintln!("{line}"));
                let interrupt = progressive.as_ref().map(|p| p.interrupt()).transpose()?;
                passes::write(&args.passes, s, &path, &progress, &note, interrupt)
            } else if let Some(p) = progressive.as_ref().filter(|_| backend.stops_early(s)) {
                let note = |line: &str| bar.suspend(|| eprintln!("{line}"));
                banded::write(backend.as_mut(), s, &path, &progress, &note, p.interrupt()?)
            } else {
                backend
                    .write(s, &path, &progress)
                    .map_err(|e| miette::miette!("{e}"))
            }
        })?;
        if rendered.invalid_samples > 0 {
            bar.suspend(|| {
                eprintln!(
                    "warning: frame {frame}: {} samples were NaN or infinite and were recorded as black",
                    rendered.invalid_samples
                )
            });
        }
        // A resumed render with nothing left renders for no time.
        let secs = rendered.time.as_secs_f64().max(f64::MIN_POSITIVE);
        let line = format!(
            "rendered {}x{}, {} spp in {:.3} s ({:.2} Msamples/s, {:.2} Mrays/s)",
            settings.width,
            settings.height,
            rendered.samples / (settings.width as u64 * settings.height as u64).max(1),
            secs,
            rendered.samples as f64 / secs / 1e6,
            rendered.rays as f64 / secs / 1e6
        );
        if sequence {
            bar.suspend(|| {
                eprintln!(
                    "frame {frame}: {line}; scene update {:.1} ms (BVH {:.1} ms) → {}",
                    update.update.as_secs_f64() * 1e3,
                    update.bvh.as_secs_f64() * 1e3,
                    path.display()
                )
            });
        } else {
            bar.suspend(|| eprintln!("{line}"));
        }
        if args.gpu_stats
            && let Some(counts) = backend.counts()
        {
            bar.suspend(|| eprintln!("{counts}"));
        }
        totals.frames += 1;
        totals.update += update.update;
        totals.bvh += update.bvh;
        totals.render += rendered.time;
        if progressive.as_ref().is_some_and(|p| p.interrupted()) {
            bar.finish_and_clear();
            std::process::exit(progressive::INTERRUPTED.into());
        }
    }
    if let Some(bar) = bar {
        bar.finish_and_clear();
    }
    if sequence {
        eprintln!(
            "sequence: {} frames in {:.2} s (scene update {:.2} s, of which BVH update {:.2} s; rendering {:.2} s){}",
            totals.frames,
            started.elapsed().as_secs_f64(),
            totals.update.as_secs_f64(),
            totals.bvh.as_secs_f64(),
            totals.render.as_secs_f64(),
            if totals.skipped > 0 {
                format!("; {} existing frames skipped", totals.skipped)
            } else {
                String::new()
            }
        );
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn frame_ranges_parse() {
        assert_eq!(parse_frames("1..10"), Ok((1, 10)));
        assert_eq!(parse_frames("7"), Ok((7, 7)));
        assert_eq!(parse_frames("-2..=3"), Ok((-2, 3)));
        assert!(parse_frames("5..1").is_err());
        assert!(parse_frames("a..b").is_err());
        assert_eq!(
            frame_path(Path::new("out/f_####.png"), 42),
            Path::new("out/f_0042.png")
        );
    }
}
