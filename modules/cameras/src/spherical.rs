//! The `spherical` camera: a 360° equirectangular panorama.
//!
//! The film's x axis is longitude φ ∈ [−π, π] (left edge to right edge,
//! φ = 0 straight ahead, increasing to the right) and its y axis latitude
//! λ ∈ [π/2, −π/2] (top row looks straight up). In camera space (+z
//! forward, +y up, +x left) the direction is
//! (−cos λ sin φ, sin λ, cos λ cos φ). Every pixel covers the same
//! (φ, λ) rectangle, so rays are unweighted and the image is radiance
//! per direction, as an environment map stores it.

use crate::projection::{central_rays, gpu_pose};
use radiant_core::glam::{Mat4, Vec2, Vec3};
use radiant_core::{Camera, CameraRays, GpuModule, GpuParams, Registry};
use serde::Deserialize;
use std::f32::consts::{PI, TAU};

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct SphericalParams {}

/// An equirectangular 360° camera.
#[derive(Debug, Clone, PartialEq)]
pub struct Spherical {
    to_render: Mat4,
    resolution: Vec2,
}

impl Spherical {
    /// A panorama camera at the pose `to_render`.
    pub fn new(to_render: Mat4, resolution: Vec2) -> Self {
        Self {
            to_render,
            resolution,
        }
    }

    /// The camera-space direction seen at raster position `p`.
    #[inline]
    fn direction(&self, p: Vec2) -> Vec3 {
        let phi = (p.x / self.resolution.x - 0.5) * TAU;
        let lambda = (0.5 - p.y / self.resolution.y) * PI;
        let (sp, cp) = phi.sin_cos();
        let (sl, cl) = lambda.sin_cos();
        Vec3::new(-cl * sp, sl, cl * cp)
    }
}

impl Camera for Spherical {
    fn generate(&self, film: &[Vec2], _lens: &[Vec2], out: CameraRays<'_>) {
        central_rays(&self.to_render, film, out, |p| self.direction(p));
    }

    fn gpu(&self) -> Option<GpuModule> {
        let params = GpuParams::new()
            .append(&gpu_pose(&self.to_render))
            .f32(self.resolution.x)
            .f32(self.resolution.y);
        Some(GpuModule::new(
            "spherical",
            include_str!("spherical.wgsl"),
            params,
        ))
    }
}

pub(crate) fn register(registry: &mut Registry) {
    crate::register_camera(
        registry,
        "spherical",
        "360° equirectangular panorama (longitude along x, latitude along y). Pose from `look_at` or `transform`.",
        &[],
        |_: SphericalParams, to_render, resolution| Ok(Spherical::new(to_render, resolution)),
    );
}

#[cfg(test)]
mod tests {
    // `unwrap` in this test code is the assertion: the inputs are the test's
    // own, so a failure is a bug, and the panic reports it with the error.
    use super::*;
    use radiant_core::params::check_param_docs;

    #[test]
    fn documented_parameters_match() {
        check_param_docs::<SphericalParams>(&[]).unwrap();
    }

    #[test]
    fn cardinal_directions() {
        let cam = Spherical::new(Mat4::IDENTITY, Vec2::new(360.0, 180.0));
        let close = |a: Vec3, b: Vec3| (a - b).length() < 1e-5;
        assert!(close(cam.direction(Vec2::new(180.0, 90.0)), Vec3::Z));
        assert!(
            close(cam.direction(Vec2::new(270.0, 90.0)), -Vec3::X),
            "right"
        );
        assert!(close(cam.direction(Vec2::new(90.0, 90.0)), Vec3::X), "left");
        assert!(
            close(cam.direction(Vec2::new(0.0, 90.0)), -Vec3::Z),
            "behind"
        );
        assert!(close(cam.direction(Vec2::new(77.0, 0.0)), Vec3::Y), "up");
        assert!(
            close(cam.direction(Vec2::new(77.0, 180.0)), -Vec3::Y),
            "down"
        );
    }
}
