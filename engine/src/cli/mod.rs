//! Command-line parsing (clap) and the subcommands.

mod accuracy;
mod diagnostic;
mod info;
mod modules;
mod render;

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
    Info {
        /// The scene file.
        scene: PathBuf,
    },
    /// List every registered module type with its parameters and defaults.
    Modules,
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
        Command::Info { scene } => info::run(&registry, &scene),
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
    let a = read_exr(image).map_err(|e| miette::miette!("{e}"))?;
    let b = read_exr(reference).map_err(|e| miette::miette!("{e}"))?;
    let c = radiant::compare::compare(&a, &b).ok_or_else(|| {
        miette::miette!(
            "the images differ in size: {}x{} and {}x{}",
            a.width,
            a.height,
            b.width,
            b.height
        )
    })?;
    println!("rmse {:.6}", c.rmse);
    println!("relative_mse {:.6}", c.relative_mse);
    println!("mean_ratio {:.6}", c.mean_ratio);
    Ok(())
}
