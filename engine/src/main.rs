//! The `radiant` command line: render, inspect and compare scenes.

mod cli;
mod out_of_memory;

/// Allocation failure is an error with exit status 1, not an abort.
#[global_allocator]
static ALLOCATOR: out_of_memory::ExitOnFailure = out_of_memory::ExitOnFailure;

fn main() -> std::process::ExitCode {
    cli::run()
}
