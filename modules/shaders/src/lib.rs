//! # radiant-shaders: built-in shader (BSDF) modules
//!
//! In the wavefront, hits are sorted by material and each shader processes
//! its whole slice: sampling continuation directions and evaluating the BSDF
//! for next-event estimation.

mod diffuse;

pub use diffuse::Diffuse;

use radiant_core::Registry;

/// Registers every built-in shader type.
pub fn register(registry: &mut Registry) {
    diffuse::register(registry);
}
