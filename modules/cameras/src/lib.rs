//! # radiant-cameras: built-in camera modules
//!
//! Cameras turn film positions into primary rays (the first stage of the
//! wavefront). The engine parses the camera's pose (`look_at` or
//! `transform`) itself and passes it as
//! [`BuildContext::camera_to_render`](radiant_core::BuildContext); a camera
//! module only parses its projection parameters.

mod perspective;

pub use perspective::Perspective;

use radiant_core::Registry;

/// Registers every built-in camera type.
pub fn register(registry: &mut Registry) {
    perspective::register(registry);
}
