//! `radiant render`: render a scene to an image file.

use super::diagnostic::report;
use super::film_args::FilmArgs;
use clap::Args;
use indicatif::{ProgressBar, ProgressStyle};
use radiant::Registry;
use radiant::backend::cpu::{self, Progress};
use radiant::extract::{Overrides, extract};
use std::path::PathBuf;

/// Options of `radiant render`.
#[derive(Args)]
pub struct RenderArgs {
    /// The scene file (YAML).
    scene: PathBuf,
    /// Output image: .png (tone-mapped sRGB) or .exr (linear float RGB).
    #[arg(short, long)]
    output: PathBuf,
    /// Samples per pixel, at least 1 (overrides the scene's sampler).
    #[arg(long, value_parser = clap::value_parser!(u32).range(1..))]
    spp: Option<u32>,
    /// Longest path in segments; -1 for unlimited (overrides the scene).
    #[arg(long, allow_negative_numbers = true, value_parser = clap::value_parser!(i32).range(-1..))]
    max_depth: Option<i32>,
    /// Sampler seed.
    #[arg(long)]
    seed: Option<u64>,
    #[command(flatten)]
    film: FilmArgs,
}

/// Renders as the arguments say.
pub fn run(registry: &Registry, args: &RenderArgs) -> miette::Result<()> {
    let ext = args
        .output
        .extension()
        .and_then(|e| e.to_str())
        .map(str::to_ascii_lowercase);
    if !matches!(ext.as_deref(), Some("png" | "exr")) {
        miette::bail!(
            "cannot write `{}`: the output name must end in .png or .exr",
            args.output.display()
        );
    }
    if args.output.is_dir() {
        miette::bail!("cannot write `{}`: it is a folder", args.output.display());
    }
    if let Some(dir) = args.output.parent().filter(|d| !d.as_os_str().is_empty()) {
        if !dir.exists() {
            miette::bail!(
                "cannot write `{}`: the folder `{}` does not exist",
                args.output.display(),
                dir.display()
            );
        }
        if !dir.is_dir() {
            miette::bail!(
                "cannot write `{}`: `{}` is not a folder",
                args.output.display(),
                dir.display()
            );
        }
    }
    let scene = radiant::scene::load(&args.scene).map_err(report)?;
    let overrides = Overrides {
        spp: args.spp,
        max_depth: args.max_depth,
        seed: args.seed,
        width: args.film.width,
        height: args.film.height,
        ..Default::default()
    };
    let render_scene = extract(&scene, registry, &overrides).map_err(report)?;
    for (shape, what) in &render_scene.stats.repaired_shapes {
        eprintln!("warning: {shape}: {}", what.describe());
    }
    let pool = args.film.thread_pool()?;

    let s = &render_scene.settings;
    let bar = ProgressBar::new(s.width as u64 * s.height as u64 * s.spp as u64);
    bar.set_style(
        ProgressStyle::with_template("{bar:40} {percent:>3}% {elapsed_precise} eta {eta}")
            .expect("the template is valid"),
    );
    let update = |done: u64, _total: u64| bar.set_position(done);
    let rendered = pool.install(|| cpu::render(&render_scene, &Progress::new(&update)));
    bar.finish_and_clear();

    radiant::film::output::write(&args.output, &rendered.image)
        .map_err(|e| miette::miette!("{e}"))?;
    if rendered.invalid_samples > 0 {
        eprintln!(
            "warning: {} samples were NaN or infinite and were recorded as black",
            rendered.invalid_samples
        );
    }
    let secs = rendered.time.as_secs_f64();
    eprintln!(
        "rendered {}x{}, {} spp in {:.2} s ({:.2} Msamples/s, {:.2} Mrays/s)",
        s.width,
        s.height,
        s.spp,
        secs,
        rendered.samples as f64 / secs / 1e6,
        rendered.rays as f64 / secs / 1e6
    );
    Ok(())
}
