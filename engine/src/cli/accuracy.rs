//! `radiant accuracy`: measure error against time for a sweep of settings
//! and write the CSV, plot and summary (see `radiant::accuracy`).

use super::diagnostic::report;
use super::film_args::FilmArgs;
use clap::Args;
use radiant::Registry;
use radiant::accuracy::{self, AccuracyError, Axis, Config, Reference};
use radiant::extract::Overrides;
use std::path::PathBuf;
use std::time::Duration;

/// Options of `radiant accuracy`.
#[derive(Args)]
pub struct AccuracyArgs {
    /// The scene file (YAML).
    scene: PathBuf,
    /// Reference image (EXR, the film's size); without it a converged
    /// reference of the scene as written is rendered first.
    #[arg(long)]
    reference: Option<PathBuf>,
    /// Wall-time bound of the whole run in seconds: the reference render
    /// (when no --reference is given) and the sweep, which shares the rest.
    #[arg(long, default_value_t = 60.0, allow_negative_numbers = true)]
    budget: f64,
    /// The part of the budget for rendering the reference, in seconds
    /// (default: a quarter of the budget); less than the budget.
    #[arg(long, allow_negative_numbers = true)]
    reference_time: Option<f64>,
    /// Folder for accuracy.csv, accuracy.png, accuracy.md and reference.exr.
    #[arg(long, default_value = "accuracy")]
    out: PathBuf,
    /// Sweep only these axes, comma-separated: spp, max_depth, rr_depth,
    /// filter, filter_sampling, sampler, light_selection, bvh, backend (the
    /// GPU, where a hardware adapter is present), denoise (Open Image
    /// Denoise, where it loads), integrator (every registered integrator),
    /// adaptive (adaptive sampling toward each error goal, relative and
    /// mse, or off); the scene as written is always measured.
    #[arg(long, value_delimiter = ',')]
    only: Vec<String>,
    /// Largest samples per pixel of a setting.
    #[arg(long, default_value_t = 1 << 16)]
    max_spp: u32,
    /// Seed of the first setting (the reference's seeds are fixed apart).
    #[arg(long, default_value_t = 0)]
    seed: u64,
    #[command(flatten)]
    film: FilmArgs,
}

fn seconds(name: &str, value: f64) -> miette::Result<Duration> {
    if value.is_finite() && value > 0.0 && value < 1e9 {
        Ok(Duration::from_secs_f64(value))
    } else {
        miette::bail!("--{name} must be a positive number of seconds, found {value}")
    }
}

fn axes(only: &[String]) -> miette::Result<Vec<Axis>> {
    if only.is_empty() {
        return Ok(Axis::ALL.to_vec());
    }
    only.iter()
        .map(|name| {
            Axis::from_name(name.trim()).ok_or_else(|| {
                let known: Vec<&str> = Axis::ALL.iter().map(|a| a.name()).collect();
                miette::miette!(
                    "--only: unknown axis `{name}`; known axes: {}",
                    known.join(", ")
                )
            })
        })
        .collect()
}

fn error(e: AccuracyError) -> miette::Report {
    match e {
        AccuracyError::Scene(s) => report(s),
        other => miette::miette!("{other}"),
    }
}

/// Runs the sweep as the arguments say.
pub fn run(registry: &Registry, args: &AccuracyArgs) -> miette::Result<()> {
    let budget = seconds("budget", args.budget)?;
    let reference_time = match args.reference_time {
        Some(t) => seconds("reference-time", t)?,
        None => budget / accuracy::REFERENCE_SHARE,
    };
    if args.reference.is_none() && reference_time >= budget {
        miette::bail!(
            "--reference-time ({:.1} s) must be less than --budget ({:.1} s): the budget covers \
             the reference render and the sweep",
            reference_time.as_secs_f64(),
            budget.as_secs_f64()
        );
    }
    if args.max_spp < 2 {
        miette::bail!("--max-spp must be at least 2 (each setting renders two halves)");
    }
    if args.out.exists() && !args.out.is_dir() {
        miette::bail!("--out `{}` exists and is not a folder", args.out.display());
    }
    let config = Config {
        budget,
        reference_time,
        max_spp: args.max_spp,
        axes: axes(&args.only)?,
        overrides: Overrides {
            width: args.film.width,
            height: args.film.height,
            ..Default::default()
        },
        seed: args.seed,
    };
    let mut scene = radiant::scene::load(&args.scene).map_err(report)?;
    let reference = args
        .reference
        .as_deref()
        .map(Reference::read)
        .transpose()
        .map_err(error)?;
    let pool = args.film.thread_pool()?;
    let log = |line: &str| eprintln!("{line}");
    let result = pool.install(|| accuracy::run(&mut scene, registry, &config, reference, &log));
    let result = result.map_err(error)?;
    accuracy::write(&result, &args.out).map_err(error)?;
    eprintln!(
        "sweep of {} settings took {:.1} s ({:.1} s with the reference, budget {:.1} s); wrote {}, {} and {} in {}",
        result.curves.len(),
        result.sweep_time.as_secs_f64(),
        result.total_time.as_secs_f64(),
        budget.as_secs_f64(),
        accuracy::CSV_FILE,
        accuracy::PLOT_FILE,
        accuracy::SUMMARY_FILE,
        args.out.display()
    );
    Ok(())
}
