//! # radiant-media: built-in participating media
//!
//! * `medium` kind — [`Homogeneous`]: constant σa and σs (RGB), given
//!   directly or as albedo and density, times a `scale`; [`HeightFog`]:
//!   density falling exponentially with height (closed forms along rays);
//!   [`Grid`]: density on a 3D grid read from a Mitsuba `.vol` file
//!   ([`VolGrid`]), tracked against a majorant grid ([`DensityGrid`]).
//! * `phase` kind — `isotropic` and `hg` (Henyey–Greenstein,
//!   [`HenyeyGreenstein`]).
//! * the `null` shader ([`Null`]): an index-matched boundary that only
//!   bounds a medium; rays, shadow rays included, pass straight through.
//!
//! Data flow: the engine reads a scene's `media:` (each with an optional
//! `phase:`), builds them here through the registry, and the path
//! integrator reads each medium's coefficients and calls its phase
//! function once per batch of scattering events.

mod coefficients;
mod gpu;
mod grid;
mod height_fog;
mod homogeneous;
mod null;
mod phase;
mod vol;

pub use grid::{DensityGrid, Grid};
pub use height_fog::HeightFog;
pub use homogeneous::Homogeneous;
pub use null::Null;
pub use phase::{HenyeyGreenstein, Isotropic};
pub use vol::VolGrid;

use radiant_core::{BuildContext, Medium, ModuleInfo, ParamDoc, ParamError, Params, Registry};

/// A medium type's build function.
type Build<M> = fn(&Params, &mut BuildContext<'_>) -> Result<M, ParamError>;

/// Registers the medium type `info` built by `build`.
fn register_medium<M: Medium + 'static>(
    registry: &mut Registry,
    info: ModuleInfo,
    build: Build<M>,
) {
    registry.register::<dyn Medium>(info, move |params: &Params, ctx| {
        Ok(Box::new(build(params, ctx)?) as Box<dyn Medium>)
    });
}

/// The module information of a medium type.
const fn medium_info(
    type_name: &'static str,
    summary: &'static str,
    params: &'static [ParamDoc],
) -> ModuleInfo {
    ModuleInfo {
        type_name,
        summary,
        params,
    }
}

/// Builds a medium from the test's own YAML parameters.
#[cfg(test)]
fn built<M>(yaml: &str, build: Build<M>) -> Result<M, ParamError> {
    // The test's own YAML text: it parses.
    let params = Params::from_yaml(yaml).expect("the test's YAML parses");
    build_standalone(|ctx| build(&params, ctx))
}

/// Asserts that each of `cases` (YAML, words of the message) fails to
/// build with a located error containing the words.
#[cfg(test)]
fn assert_located_errors<M>(build: Build<M>, cases: &[(&str, &str)]) {
    for (yaml, what) in cases {
        let Err(e) = built(yaml, build) else {
            panic!("{yaml}: accepted");
        };
        assert!(e.message.contains(what), "{yaml}: {}", e.message);
        assert!(e.location.is_some(), "{yaml}: no location");
    }
}

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
    height_fog::register(registry);
    grid::register(registry);
    phase::register(registry);
    null::register(registry);
}
