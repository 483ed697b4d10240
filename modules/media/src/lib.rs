//! # radiant-media: built-in participating media
//!
//! * `medium` kind — [`Homogeneous`]: constant σa and σs (RGB), given
//!   directly or as albedo and density, times a `scale`.
//! * `phase` kind — `isotropic` and `hg` (Henyey–Greenstein,
//!   [`HenyeyGreenstein`]).
//! * the `null` shader ([`Null`]): an index-matched boundary that only
//!   bounds a medium; rays, shadow rays included, pass straight through.
//!
//! Data flow: the engine reads a scene's `media:` (each with an optional
//! `phase:`), builds them here through the registry, and the path
//! integrator reads each medium's coefficients and calls its phase
//! function once per batch of scattering events.

mod homogeneous;
mod null;
mod phase;

pub use homogeneous::Homogeneous;
pub use null::Null;
pub use phase::{HenyeyGreenstein, Isotropic};

use radiant_core::Registry;

/// Builds with a standalone [`radiant_core::BuildContext`] (the media's
/// unit tests: media need no textures or scene data).
#[cfg(test)]
fn build_standalone<T>(build: impl FnOnce(&mut radiant_core::BuildContext<'_>) -> T) -> T {
    let mut textures = radiant_core::TextureTable::default();
    let names = std::collections::HashMap::new();
    let mut ctx =
        radiant_core::BuildContext::standalone(std::path::Path::new("."), &mut textures, &names);
    build(&mut ctx)
}

/// Registers every built-in medium, phase function and the `null` shader.
pub fn register(registry: &mut Registry) {
    homogeneous::register(registry);
    phase::register(registry);
    null::register(registry);
}
