//! # radiant-cameras: built-in camera modules
//!
//! Cameras turn film positions into primary rays (the first stage of the
//! wavefront). The engine parses the camera's pose (`look_at` or
//! `transform`) itself and passes it as
//! [`BuildContext::camera_to_render`](radiant_core::BuildContext); a camera
//! module only parses its projection parameters. What the projections share
//! (field of view, film to image plane) lives in `projection`.

mod orthographic;
mod perspective;
mod projection;
mod spherical;
mod thin_lens;

pub use orthographic::Orthographic;
pub use perspective::Perspective;
pub use projection::{FovAxis, InvalidParam};
pub use spherical::Spherical;
pub use thin_lens::ThinLens;

use radiant_core::Registry;

/// Registers every built-in camera type.
pub fn register(registry: &mut Registry) {
    perspective::register(registry);
    thin_lens::register(registry);
    orthographic::register(registry);
    spherical::register(registry);
}

#[cfg(test)]
mod tests;
