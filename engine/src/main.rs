//! The `radiant` command line: render, inspect and compare scenes.

mod cli;

fn main() -> std::process::ExitCode {
    cli::run()
}
