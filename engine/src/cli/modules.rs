//! `radiant modules`: every registered module type with its parameters.

use radiant::Registry;

/// Prints the registry's documentation.
pub fn run(registry: &Registry) {
    let mut last_kind = None;
    for (kind, info) in registry.modules() {
        if last_kind != Some(kind) {
            println!("{kind}s:");
            last_kind = Some(kind);
        }
        println!("  {} — {}", info.type_name, info.summary);
        for p in info.params {
            println!(
                "      {:<12} {:<36} default {:<12} {}",
                p.name, p.ty, p.default, p.doc
            );
        }
    }
}
