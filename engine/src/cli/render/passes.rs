//! `radiant render --aov LIST` and `--denoise`: renders a frame with its
//! first-hit planes (`radiant::film::aov`) on the CPU, denoises it with
//! Open Image Denoise where asked (`radiant::film::denoise`), and writes
//! the image, with the planes as layers of one EXR where asked
//! (`radiant::film::layers`).

use super::RenderArgs;
use clap::Args;
use radiant::backend::progressive::{self, Controls, Limits, Stop};
use radiant::backend::{BackendKind, Interrupt, Progress, RenderError, Written, cpu};
use radiant::extract::{Overrides, RenderScene};
use radiant::film::aov::{self, AovFilm, AovImage, AovSet};
use radiant::film::denoise::{Denoiser, Guides};
use radiant::film::{Film, Image};
use radiant::film::{layers, output};
use radiant::settings::FilterSampling;
use radiant::settings::RenderSettings;
use std::ops::Range;
use std::path::Path;
use std::sync::atomic::AtomicBool;
use std::time::Instant;

/// The options of the planes and the denoiser.
#[derive(Args, Clone, Default)]
pub struct PassArgs {
    /// Output variables to write as layers of the EXR, comma-separated:
    /// albedo, normal, depth, position, spp (channels `albedo.R/G/B`,
    /// `normal.X/Y/Z`, `depth.Z`, `position.X/Y/Z`, `spp.Y`; the beauty's
    /// alpha goes to `A`). Replaces the scene's `film: {aovs: […]}`
    /// (`--aov ""` writes none). Renders on the CPU.
    #[arg(long, value_parser = parse_aovs)]
    pub aov: Option<AovSet>,
    /// Denoise the image with Intel Open Image Denoise, guided by the
    /// first hits' albedo and normals (see the README, "Denoising").
    #[arg(long)]
    pub denoise: bool,
}

fn parse_aovs(text: &str) -> Result<AovSet, String> {
    aov::parse_list(text)
        .map(|list| list.into_iter().collect())
        .map_err(|e| e.to_string())
}

impl PassArgs {
    /// The output variables to write: `--aov`'s, else the scene's.
    fn aovs(&self, settings: &RenderSettings) -> AovSet {
        self.aov.unwrap_or(settings.output.aovs)
    }

    /// `overrides` as the passes need them: `--aov` replaces the scene's
    /// output variables, and `--denoise` samples the pixel
    /// filter by importance (`film: {filter_sampling: importance}`), since
    /// OIDN expects independent noise in each pixel and splatting
    /// correlates neighbours, which it keeps as detail (16-spp Cornell box:
    /// relMSE 8.5e-4 denoised against 4.6e-3 splatted; `tests/denoise.rs`).
    pub(super) fn overrides(&self, mut overrides: Overrides) -> Overrides {
        if self.aov.is_some() {
            overrides.output.aovs = self.aov;
        }
        if self.denoise {
            overrides.filter_sampling = Some(FilterSampling::Importance);
        }
        overrides
    }

    /// Whether frames of a scene with `settings` render through [`write`].
    pub(super) fn wanted(&self, settings: &RenderSettings) -> bool {
        self.denoise || !self.aovs(settings).is_empty()
    }
}

/// Checks, before anything renders, that the passes can be made as asked
/// for a scene with `settings` (before the flags are applied): by the CPU
/// backend, into an EXR where there are layers, not into a partition.
pub(super) fn check(args: &RenderArgs, settings: &RenderSettings) -> miette::Result<()> {
    let passes = &args.passes;
    if !passes.wanted(settings) {
        return Ok(());
    }
    let what = if passes.denoise {
        "--denoise"
    } else if passes.aov.is_some() {
        "--aov"
    } else {
        "the scene's `film: {aovs: […]}` (`--aov \"\"` leaves them out)"
    };
    if args.backend == BackendKind::Gpu {
        miette::bail!(
            "{what} needs the CPU backend: the GPU kernel does not record first hits yet; \
             use `--backend cpu` (or `auto`, which renders such frames on the CPU)"
        );
    }
    if args.progressive.is_set() {
        miette::bail!(
            "{what} cannot be combined with --time, --checkpoint or --resume yet: the planes \
             are not kept between passes; render a fixed --spp"
        );
    }
    if args.partition.is_some() {
        miette::bail!(
            "{what} cannot be used with --partition: a partition holds sums for `radiant merge`; \
             render the passes with a whole render"
        );
    }
    if !passes.aovs(settings).is_empty() && !is_exr(&args.output) {
        miette::bail!(
            "{what} writes layers of an EXR file, and `{}` is not one: name the output .exr",
            args.output.display()
        );
    }
    Ok(())
}

fn is_exr(path: &Path) -> bool {
    path.extension()
        .is_some_and(|e| e.eq_ignore_ascii_case("exr"))
}

/// Renders `scene` with its planes on the CPU, denoises it where asked and
/// writes `path` (atomically); says on stderr how long denoising took.
/// Where `interrupt` is given and the integrator renders in passes, it
/// renders in passes so that Ctrl-C stops it after the pass in progress:
/// a single frame then writes the image and planes of its samples so far
/// (there is no state for `--resume`: the planes are not kept in one), a
/// frame of a sequence writes nothing (its file appears only when it is
/// finished).
pub(super) fn write(
    args: &PassArgs,
    scene: &RenderScene,
    path: &Path,
    progress: &Progress<'_>,
    note: &dyn Fn(&str),
    interrupt: Option<Interrupt<'_>>,
) -> miette::Result<Written> {
    let aovs = scene.settings.output.aovs.list();
    // Loaded before rendering, so that a missing library costs no render.
    let denoiser = args
        .denoise
        .then(Denoiser::load)
        .transpose()
        .map_err(|e| miette::miette!("{e}"))?;
    let in_passes = interrupt.filter(|_| cpu::passes(scene).is_ok());
    let (image, planes, written, stopped) = match &in_passes {
        Some(i) => render_in_passes(scene, progress, i.flag).map_err(|e| miette::miette!("{e}"))?,
        None => {
            let (rendered, planes) =
                cpu::render_with_aovs(scene, progress).map_err(|e| miette::miette!("{e}"))?;
            let written = Written::from(&rendered);
            (rendered.image, planes, written, None)
        }
    };
    let spp = scene.settings.spp;
    match (stopped, &in_passes) {
        (Some(0), _) => {
            note("interrupted before the first pass ended: nothing written");
            return Ok(written);
        }
        (Some(samples), Some(i)) if !i.keep => {
            note(&format!(
                "interrupted: {samples} of {spp} spp of this frame not written (a render with \
                 passes keeps no state for --resume; its file appears only when it is finished)"
            ));
            return Ok(written);
        }
        (Some(samples), _) => note(&format!(
            "interrupted: {samples} of {spp} spp written to {} (with its passes; they keep no \
             state for --resume)",
            path.display()
        )),
        (None, _) => {}
    }
    let image = match &denoiser {
        Some(d) => {
            let start = Instant::now();
            let image = d
                .denoise(&image, &planes, Guides::of(scene))
                .map_err(|e| miette::miette!("{e}"))?;
            note(&format!(
                "denoised in {:.2} s (Open Image Denoise from {})",
                start.elapsed().as_secs_f64(),
                d.path().display()
            ));
            image
        }
        None => image,
    };
    if aovs.is_empty() && scene.settings.output.alpha {
        radiant::film::alpha::write(path, &image, &planes.alpha, &scene.settings.output)
    } else if aovs.is_empty() {
        output::write_encoded(path, &image, &scene.settings.output)
    } else {
        layers::write(path, &image, &planes, &aovs)
    }
    .map_err(|e| miette::miette!("{e}"))?;
    Ok(written)
}

/// Renders `scene` with its planes in passes until its spp are done or
/// `interrupt` is raised: the image, the planes, what was rendered, and
/// the samples per pixel held where it was interrupted.
fn render_in_passes(
    scene: &RenderScene,
    progress: &Progress<'_>,
    interrupt: &AtomicBool,
) -> Result<(Image, AovImage, Written, Option<u32>), RenderError> {
    let s = &scene.settings;
    let mut film = Film::try_new(s.width, s.height)?;
    let mut aovs = AovFilm::try_new(s.width, s.height)?;
    let controls = Controls {
        limits: Limits {
            spp: s.spp,
            time: None,
            checkpoint: None,
            pass_time: progressive::PASS_TIME,
        },
        interrupt,
        progress,
    };
    let mut pass = |film: &mut Film, samples: Range<u32>, progress: &Progress<'_>| {
        Ok(cpu::render_samples_with_aovs(
            scene, film, &mut aovs, samples, progress,
        ))
    };
    let outcome = progressive::render_passes::<RenderError>(
        &mut pass,
        &mut film,
        0,
        &controls,
        &mut |_, _| Ok(()),
    )?;
    let written = Written {
        time: outcome.time,
        samples: u64::from(s.width) * u64::from(s.height) * u64::from(outcome.samples),
        rays: outcome.rays,
        invalid_samples: film.invalid_samples,
    };
    let stopped = (outcome.stop == Stop::Interrupted).then_some(outcome.samples);
    Ok((film.try_develop()?, aovs.develop(), written, stopped))
}
