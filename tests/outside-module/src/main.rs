//! The whole `radiant` command line — render, info, modules, accuracy,
//! every override, the progress bar and the located errors — with this
//! crate's `stripes` texture added to the built-in modules.

/// Allocation failure is an error with exit status 1, not an abort.
#[global_allocator]
static ALLOCATOR: radiant::cli::ExitOnFailure = radiant::cli::ExitOnFailure;

fn main() -> std::process::ExitCode {
    let mut registry = radiant::builtin_registry();
    radiant_example_module::register(&mut registry);
    radiant::cli::run(registry)
}
