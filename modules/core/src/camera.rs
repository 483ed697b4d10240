//! Cameras: where primary rays are born.
//!
//! The engine hands a camera batches of film positions (in raster pixels,
//! origin at the image's top-left corner, +y down) and lens samples; the
//! camera writes ray origins and directions in *render space* (world space
//! shifted so that the camera's pose origin is at 0, see
//! [`BuildContext::camera_to_render`](crate::BuildContext)).
//!
//! Bidirectional integrators also connect scene points to the lens: a
//! camera that supports this answers [`Camera::importance`] with its
//! [`Importance`] side. Densities follow pbrt: per unit lens area (a
//! pinhole's lens counts as area 1) and per unit solid angle, over the
//! whole image (a camera ray's direction density integrates to 1 over the
//! film), so one light path per camera path weighs as one sample of the
//! whole image.

use crate::{Effects, GpuModule};
use glam::{Vec2, Vec3};

/// A point connected to the lens, as [`Importance::sample_wi`] gives it.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct LensSample {
    /// The point on the lens, render space (the visibility ray ends there).
    pub p: Vec3,
    /// Unit direction from the reference point towards `p`.
    pub wi: Vec3,
    /// Raster position (pixels, top-left origin) where the ray from the
    /// reference point through `p` lands.
    pub raster: Vec2,
    /// Importance We of the camera ray from `p` towards the reference point.
    pub importance: f32,
    /// Density of `p` per unit solid angle seen from the reference point
    /// (distance² / (|cos θ| · lens area)); 0 marks a point that no camera
    /// ray sees (behind the camera, outside the film).
    pub pdf: f32,
}

/// The densities of a camera ray (see [`Importance::pdf_ray`]).
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct CameraRayPdf {
    /// Density of the origin per unit lens area.
    pub pdf_pos: f32,
    /// Density of the direction per unit solid angle, over the whole film
    /// (0 outside it).
    pub pdf_dir: f32,
}

/// The importance side of a camera: connecting points to the lens.
pub trait Importance: Send + Sync {
    /// For each render-space point `refs[i]` and lens sample `u[i]`, a
    /// point on the lens and where its ray lands on the film, writing every
    /// `out[i]`.
    fn sample_wi(&self, refs: &[Vec3], u: &[Vec2], out: &mut [LensSample]);

    /// The densities with which [`Camera::generate`], fed film positions
    /// uniform over the whole film and uniform lens samples, produces each
    /// ray (`origin`, unit `dir`) of `rays`, writing every `out[i]`.
    fn pdf_ray(&self, rays: &[(Vec3, Vec3)], out: &mut [CameraRayPdf]);

    /// Whether every camera ray has the same direction (`orthographic`):
    /// `pdf_dir` is then a delta, reported as 1, a scene point's density
    /// from the camera is `pdf_pos` · |cos θ| at the point, and
    /// [`sample_wi`](Self::sample_wi) finds the one lens point of each
    /// reference point with density 1 and importance `pdf_pos`.
    fn directional(&self) -> bool {
        false
    }
}

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

    /// Whether [`generate`](Self::generate) reads its lens samples. A
    /// camera with one centre of projection (a pinhole) returns `false`,
    /// and the integrator then draws no lens samples for it (their
    /// contents are unspecified). The default, `true`, is always correct.
    fn uses_lens_samples(&self) -> bool {
        true
    }

    /// The camera's importance side, for light paths that reach the lens
    /// (bidirectional path tracing); `None` where the type has none, and
    /// integrators that need it refuse the scene, naming the camera's type.
    fn importance(&self) -> Option<&dyn Importance> {
        None
    }

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
