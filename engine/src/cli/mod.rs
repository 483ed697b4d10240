//! The `radiant` command line as a library entry point: parsing (clap), the
//! subcommands, the progress bar and the located diagnostics (miette), for
//! any [`Registry`]. The `radiant` binary runs it with the built-in
//! modules; a module crate's binary registers its own modules as well and
//! gets every subcommand for them:
//!
//! ```no_run,standalone_crate
//! #[global_allocator]
//! static ALLOCATOR: radiant::cli::ExitOnFailure = radiant::cli::ExitOnFailure;
//!
//! fn main() -> std::process::ExitCode {
//!     let mut registry = radiant::builtin_registry();
//!     // my_modules::register(&mut registry);
//!     radiant::cli::run(registry)
//! }
//! ```

mod accuracy;
mod compare;
mod diagnostic;
mod farm;
mod film_args;
mod info;
mod merge;
mod modules;
mod output_args;
mod render;
mod sampling_args;
mod sheet;

pub use crate::out_of_memory::ExitOnFailure;
use clap::{Parser, Subcommand};
use radiant::Registry;
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
    /// Compare an image against a reference (RMSE, relative MSE, mean ratio,
    /// FLIP) in any format Radiant writes; `--diff` writes a FLIP heat map.
    Compare(compare::CompareArgs),
}

/// Parses the command line and runs the command with the modules of
/// `registry`; errors print as diagnostics and give a non-zero exit status.
pub fn run(registry: Registry) -> ExitCode {
    let cli = Cli::parse();
    // Keep each message on one line so `file:line:column` stays greppable.
    miette::set_hook(Box::new(|_| {
        Box::new(miette::MietteHandlerOpts::new().wrap_lines(false).build())
    }))
    .ok();
    let result = match cli.command {
        Command::Render(args) => render::run(&registry, &args.with_default_output()),
        Command::Accuracy(args) => accuracy::run(&registry, &args),
        Command::Info(args) => info::run(&registry, &args),
        Command::Sheet(args) => sheet::run(&args),
        Command::Merge(args) => merge::run(&args),
        Command::Farm(command) => farm::run(&command),
        Command::Modules => {
            modules::run(&registry);
            Ok(())
        }
        Command::Compare(args) => compare::run(&args),
    };
    match result {
        Ok(()) => ExitCode::SUCCESS,
        Err(report) => {
            eprintln!("{report:?}");
            ExitCode::FAILURE
        }
    }
}
