//! `radiant render`: render a scene to an image file.

use super::diagnostic::report;
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
    /// Samples per pixel (overrides the scene's sampler).
    #[arg(long)]
    spp: Option<u32>,
    /// Longest path in segments; -1 for unlimited (overrides the scene).
    #[arg(long, allow_negative_numbers = true)]
    max_depth: Option<i32>,
    /// Sampler seed.
    #[arg(long)]
    seed: Option<u64>,
    /// Film width in pixels.
    #[arg(long)]
    width: Option<u32>,
    /// Film height in pixels.
    #[arg(long)]
    height: Option<u32>,
    /// Worker threads (default: all cores).
    #[arg(long)]
    threads: Option<usize>,
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
    if let Some(dir) = args.output.parent().filter(|d| !d.as_os_str().is_empty())
        && !dir.is_dir()
    {
        miette::bail!(
            "cannot write `{}`: the folder `{}` does not exist",
            args.output.display(),
            dir.display()
        );
    }
    for (name, value) in [
        ("spp", args.spp),
        ("width", args.width),
        ("height", args.height),
    ] {
        if value == Some(0) {
            miette::bail!("--{name} must be at least 1");
        }
    }
    if let Some(d) = args.max_depth
        && d < -1
    {
        miette::bail!("--max-depth must be -1 (unlimited) or at least 0, found {d}");
    }
    if args.threads == Some(0) {
        miette::bail!("--threads must be at least 1");
    }
    let scene = radiant::scene::load(&args.scene).map_err(report)?;
    let overrides = Overrides {
        spp: args.spp,
        max_depth: args.max_depth,
        seed: args.seed,
        width: args.width,
        height: args.height,
        ..Default::default()
    };
    let render_scene = extract(&scene, registry, &overrides).map_err(report)?;
    for (shape, what) in &render_scene.stats.repaired_shapes {
        eprintln!("warning: {shape}: {}", what.describe());
    }
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(args.threads.unwrap_or(0))
        .build()
        .map_err(|e| miette::miette!("cannot start worker threads: {e}"))?;

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
