//! The `radiant` command line: render, inspect and compare scenes with the
//! built-in modules. A module crate's own binary is the same three lines
//! with its modules registered (see `radiant::cli`).

/// Allocation failure is an error with exit status 1, not an abort.
#[global_allocator]
static ALLOCATOR: radiant::out_of_memory::ExitOnFailure = radiant::out_of_memory::ExitOnFailure;

fn main() -> std::process::ExitCode {
    radiant::cli::run(radiant::builtin_registry())
}
