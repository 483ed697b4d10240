//! The importance side of the perspective cameras (`perspective`,
//! `thin_lens`): connecting a scene point to the lens for light paths, and
//! the densities of a camera ray (pbrt-v3's `Sample_Wi`, `We` and
//! `Pdf_We` for its perspective camera).
//!
//! A camera ray leaves a lens point (uniform on the aperture disc; a
//! pinhole's single point counts as a lens of area 1) towards the point
//! of the plane in focus that a film position, uniform over the film,
//! looks at through the lens centre. Its direction density over the whole
//! film is 1 / (A cos³θ), with A the image plane's area at distance 1 and
//! θ the angle to the optical axis, and the importance
//! We = 1 / (A · lens area · cos⁴θ), so that We cos θ / (pdf_pos pdf_dir)
//! is 1, the weight `generate` gives.

use crate::projection::Pinhole;
use radiant_core::glam::{Mat4, Vec2, Vec3};
use radiant_core::warp::square_to_disk_concentric;
use radiant_core::{CameraRayPdf, Importance, LensSample};

/// A pinhole or thin lens seen from the scene.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct Lens {
    to_render: Mat4,
    to_camera: Mat4,
    pinhole: Pinhole,
    /// Aperture radius (0: a pinhole).
    radius: f32,
    /// Distance of the plane in focus (1 for a pinhole: any plane will do).
    focus: f32,
}

impl Lens {
    /// The lens of a camera posed by `to_render` with `pinhole`'s image
    /// plane, aperture `radius` and plane in focus at `focus`.
    pub(crate) fn new(to_render: Mat4, pinhole: Pinhole, radius: f32, focus: f32) -> Self {
        let (radius, focus) = if radius > 0.0 {
            (radius, focus)
        } else {
            (0.0, 1.0)
        };
        Self {
            to_render,
            to_camera: to_render.inverse(),
            pinhole,
            radius,
            focus,
        }
    }

    /// The lens area (1 for a pinhole, by convention).
    fn area(&self) -> f32 {
        if self.radius > 0.0 {
            std::f32::consts::PI * self.radius * self.radius
        } else {
            1.0
        }
    }

    /// For a camera-space ray from lens point `o` along `d` (any length,
    /// `d.z > 0`): the raster position it lands on, if on the film.
    fn raster(&self, o: Vec3, d: Vec3) -> Option<Vec2> {
        let focus = o + d * (self.focus / d.z);
        self.pinhole
            .raster_of(Vec2::new(focus.x, focus.y) / self.focus)
    }
}

impl Importance for Lens {
    fn sample_wi(&self, refs: &[Vec3], u: &[Vec2], out: &mut [LensSample]) {
        let area = self.area();
        let a = self.pinhole.plane_area();
        for ((r, u), o) in refs.iter().zip(u).zip(out.iter_mut()) {
            *o = LensSample::default();
            let lens = (square_to_disk_concentric(*u) * self.radius).extend(0.0);
            let q = self.to_camera.transform_point3(*r);
            let d = q - lens;
            if d.z <= 0.0 {
                continue;
            }
            let Some(raster) = self.raster(lens, d) else {
                continue;
            };
            let p = self.to_render.transform_point3(lens);
            let to_lens = p - *r;
            let dist2 = to_lens.length_squared();
            let cos = d.z / d.length();
            let wi = to_lens / dist2.sqrt();
            if dist2.is_nan() || dist2 <= 0.0 || !wi.is_finite() {
                continue;
            }
            let cos2 = cos * cos;
            *o = LensSample {
                p,
                wi,
                raster,
                importance: 1.0 / (a * area * cos2 * cos2),
                pdf: dist2 / (cos * area),
            };
        }
    }

    fn pdf_ray(&self, rays: &[(Vec3, Vec3)], out: &mut [CameraRayPdf]) {
        let a = self.pinhole.plane_area();
        let pdf_pos = 1.0 / self.area();
        for ((origin, dir), o) in rays.iter().zip(out.iter_mut()) {
            let lens = self.to_camera.transform_point3(*origin);
            let d = self.to_camera.transform_vector3(*dir).normalize_or_zero();
            *o = if d.z > 0.0 && self.raster(lens, d).is_some() {
                CameraRayPdf {
                    pdf_pos,
                    pdf_dir: 1.0 / (a * d.z * d.z * d.z),
                }
            } else {
                CameraRayPdf::default()
            };
        }
    }
}
