//! The `spherical` camera: a 360° equirectangular panorama.
//!
//! The film's x axis is longitude φ ∈ [−π, π] (left edge to right edge,
//! φ = 0 straight ahead, increasing to the right) and its y axis latitude
//! λ ∈ [π/2, −π/2] (top row looks straight up). In camera space (+z
//! forward, +y up, +x left) the direction is
//! (−cos λ sin φ, sin λ, cos λ cos φ). Every pixel covers the same
//! (φ, λ) rectangle, so rays are unweighted and the image is radiance
//! per direction, as an environment map stores it.
//!
//! Its importance side (for bidirectional integrators): the lens is the
//! camera's centre, a point of area 1 without orientation, so a scene
//! point connects to it with density distance² per unit solid angle. Film
//! positions uniform over the (φ, λ) rectangle of area 2π² give directions
//! of density 1 / (2π² cos λ) per unit solid angle, which is also the
//! importance We of that direction (rays are unweighted: We / (pdf_pos ·
//! pdf_dir) = 1; no lens cosine enters, unlike a perspective camera's).

use crate::projection::{central_rays, gpu_pose};
use radiant_core::glam::{Mat4, Vec2, Vec3};
use radiant_core::{
    Camera, CameraRayPdf, CameraRays, GpuModule, GpuParams, Importance, LensSample, Registry,
};
use serde::Deserialize;
use std::f32::consts::{PI, TAU};

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct SphericalParams {}

/// An equirectangular 360° camera.
#[derive(Debug, Clone, PartialEq)]
pub struct Spherical {
    to_render: Mat4,
    to_camera: Mat4,
    resolution: Vec2,
}

impl Spherical {
    /// A panorama camera at the pose `to_render`.
    pub fn new(to_render: Mat4, resolution: Vec2) -> Self {
        Self {
            to_render,
            to_camera: to_render.inverse(),
            resolution,
        }
    }

    /// The raster position that sees camera-space unit direction `d`, and
    /// the density 1 / (2π² cos λ) of `d` per unit solid angle (0 at the
    /// poles, where no pixel has area).
    #[inline]
    fn raster_of(&self, d: Vec3) -> (Vec2, f32) {
        let cos_lambda = (d.x * d.x + d.z * d.z).sqrt();
        let lambda = d.y.clamp(-1.0, 1.0).asin();
        let phi = (-d.x).atan2(d.z);
        let raster = Vec2::new(
            (phi / TAU + 0.5) * self.resolution.x,
            (0.5 - lambda / PI) * self.resolution.y,
        );
        let pdf = if cos_lambda > 0.0 {
            1.0 / (2.0 * PI * PI * cos_lambda)
        } else {
            0.0
        };
        (raster, pdf)
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
    fn uses_lens_samples(&self) -> bool {
        false
    }

    fn generate(&self, film: &[Vec2], _lens: &[Vec2], out: CameraRays<'_>) {
        central_rays(&self.to_render, film, out, |p| self.direction(p));
    }

    fn importance(&self) -> Option<&dyn Importance> {
        Some(self)
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

impl Importance for Spherical {
    fn sample_wi(&self, refs: &[Vec3], _u: &[Vec2], out: &mut [LensSample]) {
        let p = self.to_render.transform_point3(Vec3::ZERO);
        for (r, o) in refs.iter().zip(out.iter_mut()) {
            *o = LensSample::default();
            let d = self.to_camera.transform_point3(*r).normalize_or_zero();
            let to_lens = p - *r;
            let dist2 = to_lens.length_squared();
            let wi = to_lens / dist2.sqrt();
            if d == Vec3::ZERO || dist2.is_nan() || dist2 <= 0.0 || !wi.is_finite() {
                continue;
            }
            let (raster, we) = self.raster_of(d);
            if we <= 0.0 {
                continue;
            }
            *o = LensSample {
                p,
                wi,
                raster,
                importance: we,
                pdf: dist2,
            };
        }
    }

    fn pdf_ray(&self, rays: &[(Vec3, Vec3)], out: &mut [CameraRayPdf]) {
        for (&(_, dir), o) in rays.iter().zip(out.iter_mut()) {
            let d = self.to_camera.transform_vector3(dir).normalize_or_zero();
            let (_, pdf_dir) = self.raster_of(d);
            *o = CameraRayPdf {
                pdf_pos: 1.0,
                pdf_dir,
            };
        }
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
    fn importance_maps_points_back_to_their_raster_position() {
        // A point on each camera ray (at distance 2) connects back to the
        // ray's raster position, with density distance² and We equal to
        // the ray's direction density 1 / (2π² cos λ); the densities
        // integrate to 1 over the sphere (midpoint rule in φ, λ).
        let pose = Mat4::from_translation(Vec3::new(1.0, -2.0, 0.5)) * Mat4::from_rotation_y(0.7);
        let cam = Spherical::new(pose, Vec2::new(64.0, 32.0));
        let mut total = 0.0f64;
        for y in 0..32 {
            for x in 0..64 {
                let raster = Vec2::new(x as f32 + 0.5, y as f32 + 0.5);
                let (mut o, mut d, mut w) = ([Vec3::ZERO], [Vec3::ZERO], [0.0]);
                cam.generate(
                    &[raster],
                    &[Vec2::ZERO],
                    CameraRays {
                        origins: &mut o,
                        directions: &mut d,
                        weights: &mut w,
                    },
                );
                let point = o[0] + 2.0 * d[0];
                let mut ls = [LensSample::default()];
                cam.sample_wi(&[point], &[Vec2::ZERO], &mut ls);
                let mut pdf = [CameraRayPdf::default()];
                cam.pdf_ray(&[(o[0], d[0])], &mut pdf);
                let ls = ls[0];
                assert!(
                    (ls.raster - raster).length() < 1e-3,
                    "{raster} → {}",
                    ls.raster
                );
                assert!((ls.pdf - 4.0).abs() < 1e-4, "{}", ls.pdf);
                assert!((ls.importance / pdf[0].pdf_dir - 1.0).abs() < 1e-5);
                assert!((ls.p - o[0]).length() < 1e-5 && (ls.wi + d[0]).length() < 1e-5);
                let lambda = (0.5 - raster.y / 32.0) * PI;
                let d_omega = (TAU / 64.0) * (PI / 32.0) * lambda.cos();
                total += f64::from(pdf[0].pdf_dir * d_omega);
            }
        }
        assert!((total - 1.0).abs() < 1e-4, "∫ pdf_dir dω = {total}");
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
