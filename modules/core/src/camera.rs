//! Cameras: where primary rays are born.
//!
//! The engine hands a camera batches of film positions (in raster pixels,
//! origin at the image's top-left corner, +y down) and lens samples; the
//! camera writes ray origins and directions in *render space* (world space
//! shifted so that the camera's pose origin is at 0, see
//! [`BuildContext::camera_to_render`](crate::BuildContext)).

use crate::{Effects, GpuModule};
use glam::{Vec2, Vec3};

/// Output slices of [`Camera::generate`]; all have the batch's length.
pub struct CameraRays<'a> {
    /// Ray origins in render space.
    pub origins: &'a mut [Vec3],
    /// Unit ray directions in render space.
    pub directions: &'a mut [Vec3],
    /// Importance weight of each ray (1 for an ideal pinhole).
    pub weights: &'a mut [f32],
}

/// A camera module.
pub trait Camera: Send + Sync {
    /// Generates one primary ray per film position `film[i]` using the lens
    /// sample `lens[i]` in [0,1)²: writes `out.origins[i]`,
    /// `out.directions[i]` (unit length, pointing into the scene) and
    /// `out.weights[i]` (0 for a position with no ray) for every `i`; the
    /// slices are not cleared between batches.
    fn generate(&self, film: &[Vec2], lens: &[Vec2], out: CameraRays<'_>);

    /// The camera's GPU side (see [`crate::gpu`]), `None` where the type has
    /// none.
    fn gpu(&self) -> Option<GpuModule> {
        None
    }
    /// Effects this camera needs (e.g. depth of field).
    fn effects(&self) -> Effects {
        Effects::empty()
    }
}
