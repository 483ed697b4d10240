//! # radiant-lights: built-in light modules
//!
//! Lights serve next-event estimation (the wavefront's NEE stage samples them
//! in batches) and report their emission when a BSDF-sampled ray hits them
//! (surface emitters) or leaves the scene (environment lights).

mod area;
mod directional;
mod environment;
mod map_file;
mod params;
mod point;
mod sphere;
mod spot;

pub use area::AreaLight;
pub use directional::DirectionalLight;
pub use environment::EnvironmentLight;
pub use point::PointLight;
pub use spot::SpotLight;

use radiant_core::Registry;

/// Registers every built-in light type.
pub fn register(registry: &mut Registry) {
    area::register(registry);
    directional::register(registry);
    environment::register(registry);
    point::register(registry);
    spot::register(registry);
}
