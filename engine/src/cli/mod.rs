//! Command-line parsing (clap) and the subcommands.

mod accuracy;
mod diagnostic;
mod farm;
mod film_args;
mod info;
mod merge;
mod modules;
mod render;
mod sampling_args;
mod sheet;

use clap::{Parser, Subcommand};
use std::path::PathBuf;
use std::process::ExitCode;

/// Radiant: a physically based path-tracing scene engine.
#[derive(Parser)]
#[command(name = "radiant", version, about)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand)]
enum Command {
    /// Render a scene to a PNG (tone-mapped sRGB) or EXR (linear) image.
    Render(render::RenderArgs),
    /// Measure error against time for a sweep of settings (CSV, plot, summary).
    Accuracy(accuracy::AccuracyArgs),
    /// Print a scene's triangle and light counts, modules and effect set.
    Info(info::InfoArgs),
    /// List every registered module type with its parameters and defaults.
    Modules,
    /// Show rendered frames as a contact sheet (.png) or an animated GIF (.gif).
    Sheet(sheet::SheetArgs),
    /// Add the partial EXR files of a frame's sample partitions into the frame.
    Merge(merge::MergeArgs),
    /// Render on a cluster: Slurm job scripts, and the state of a sequence.
    #[command(subcommand)]
    Farm(farm::FarmCommand),
    /// Compare an image against a reference (RMSE, relative MSE, mean ratio).
    Compare {
        /// The image to judge (EXR).
        image: PathBuf,
        /// The reference (EXR).
        reference: PathBuf,
    },
}

/// Parses the command line and runs the command; errors print as
/// diagnostics and give a non-zero exit status.
pub fn run() -> ExitCode {
    let cli = Cli::parse();
    // Keep each message on one line so `file:line:column` stays greppable.
    miette::set_hook(Box::new(|_| {
        Box::new(miette::MietteHandlerOpts::new().wrap_lines(false).build())
    }))
    .ok();
    let registry = radiant::builtin_registry();
    let result = match cli.command {
        Command::Render(args) => render::run(&registry, &args),
        Command::Accuracy(args) => accuracy::run(&registry, &args),
        Command::Info(args) => info::run(&registry, &args),
        Command::Sheet(args) => sheet::run(&args),
        Command::Merge(args) => merge::run(&args),
        Command::Farm(command) => farm::run(&command),
        Command::Modules => {
            modules::run(&registry);
            Ok(())
        }
        Command::Compare { image, reference } => compare(&image, &reference),
    };
    match result {
        Ok(()) => ExitCode::SUCCESS,
        Err(report) => {
            eprintln!("{report:?}");
            ExitCode::FAILURE
        }
    }
}

fn compare(image: &std::path::Path, reference: &std::path::Path) -> miette::Result<()> {
    use radiant::film::output::read_exr;
    let read = |path: &std::path::Path| {
        let img = read_exr(path).map_err(|e| miette::miette!("{e}"))?;
        let bad = img.pixels.iter().filter(|p| !p.is_finite()).count();
        if bad > 0 {
            miette::bail!(
                "`{}`: {bad} pixels are NaN or infinite; compare needs finite images",
                path.display()
            );
        }
        Ok(img)
    };
    let (a, b) = (read(image)?, read(reference)?);
    let c = radiant::compare::compare(&a, &b).ok_or_else(|| {
        miette::miette!(
            "the images differ in size: `{}` is {}x{} and `{}` is {}x{}",
            image.display(),
            a.width,
            a.height,
            reference.display(),
            b.width,
            b.height
        )
    })?;
    println!("rmse {:.6}", c.rmse);
    println!("relative_mse {:.6}", c.relative_mse);
    if c.mean_ratio.is_finite() {
        println!("mean_ratio {:.6}", c.mean_ratio);
    } else {
        println!("mean_ratio undefined (the reference's mean is 0)");
    }
    Ok(())
}
