//! # radiant-lights: built-in light modules
//!
//! Lights serve next-event estimation (the wavefront's NEE stage samples them
//! in batches) and report their emission when a BSDF-sampled ray hits them.

mod area;
mod point;

pub use area::AreaLight;
pub use point::PointLight;

use radiant_core::Registry;

/// Registers every built-in light type.
pub fn register(registry: &mut Registry) {
    area::register(registry);
    point::register(registry);
}
