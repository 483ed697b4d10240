//! The media's GPU side: each medium type's WGSL (`*.wgsl` beside its
//! Rust) with its parameters packed after the shared coefficients, which
//! `radiant_core`'s medium library (`core::medium`) reads as the first
//! nine words.

use radiant_core::gpu::MEDIUM;
use radiant_core::{Coefficients, GpuModule, GpuParams};

/// The GPU module of a medium of type `ident` with code `wgsl`: the
/// coefficients `c` (σa, σs, Le), then `own`.
pub(crate) fn medium(
    ident: &'static str,
    wgsl: &'static str,
    c: &Coefficients,
    own: GpuParams,
) -> GpuModule {
    let params = GpuParams::new()
        .rgb(c.sigma_a)
        .rgb(c.sigma_s)
        .rgb(c.emission)
        .append(&own);
    GpuModule::new(ident, wgsl, params).with_libraries(&[MEDIUM])
}
