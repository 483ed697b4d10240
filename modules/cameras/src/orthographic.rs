//! The `orthographic` camera: parallel rays through a rectangular window.
//!
//! Rays start on the camera-space plane z = 0 and all point along +z. The
//! window is `width` scene units wide (x ∈ [−w/2, w/2]) with the film's
//! aspect ratio; the default 2 is Mitsuba 3's [−1, 1] window, which a scale
//! in the camera's `transform` resizes in both renderers.

use crate::projection::{InvalidParam, Raster, check_min, gpu_pose};
use radiant_core::glam::{Mat4, Vec2, Vec3};
use radiant_core::{
    Camera, CameraRayPdf, CameraRays, GpuModule, Importance, LensSample, ParamDoc, Registry,
};
use serde::Deserialize;

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct OrthographicParams {
    #[serde(default = "default_width")]
    width: f32,
}

fn default_width() -> f32 {
    2.0
}

const DOCS: &[ParamDoc] = &[ParamDoc {
    name: "width",
    ty: "scene units, > 0",
    default: "2",
    doc: "Width of the viewed window; its height follows the film's aspect ratio.",
}];

/// An orthographic camera.
#[derive(Debug, Clone, PartialEq)]
pub struct Orthographic {
    to_render: Mat4,
    /// `to_render`'s inverse, for connections to the window.
    to_camera: Mat4,
    raster: Raster,
    /// Half the window's extent along x and y.
    half: Vec2,
}

impl Orthographic {
    /// An orthographic camera viewing a window `width` units wide.
    pub fn new(to_render: Mat4, resolution: Vec2, width: f32) -> Result<Self, InvalidParam> {
        let width = check_min("width", width, 0.0, false, "scene units")?;
        let half = Vec2::new(width, width * resolution.y / resolution.x) * 0.5;
        Ok(Self {
            to_render,
            to_camera: to_render.inverse(),
            raster: Raster::new(resolution),
            half,
        })
    }

    /// The direction of every ray: the pose's +z, normalised.
    #[inline]
    fn direction(&self) -> Vec3 {
        self.to_render.transform_vector3(Vec3::Z).normalize()
    }
}

/// Connections to the window: each point in front of it is seen along the
/// view direction from exactly one window point, whose density is
/// 1 / window area (pbrt's convention for a delta direction).
impl Importance for Orthographic {
    fn sample_wi(&self, refs: &[Vec3], _u: &[Vec2], out: &mut [LensSample]) {
        let dir = self.direction();
        let area = 4.0 * self.half.x * self.half.y;
        let size = 2.0 / self.raster.scale();
        for (r, o) in refs.iter().zip(out.iter_mut()) {
            *o = LensSample::default();
            let q = self.to_camera.transform_point3(*r);
            if q.z <= 0.0 {
                continue;
            }
            let ndc = Vec2::new(-q.x / self.half.x, q.y / self.half.y);
            let raster = Vec2::new((ndc.x + 1.0) * size.x, (1.0 - ndc.y) * size.y) * 0.5;
            if !(raster.x >= 0.0 && raster.y >= 0.0 && raster.x < size.x && raster.y < size.y) {
                continue;
            }
            *o = LensSample {
                p: self.to_render.transform_point3(Vec3::new(q.x, q.y, 0.0)),
                wi: -dir,
                raster,
                importance: 1.0 / area,
                pdf: 1.0,
            };
        }
    }

    fn pdf_ray(&self, rays: &[(Vec3, Vec3)], out: &mut [CameraRayPdf]) {
        let area = 4.0 * self.half.x * self.half.y;
        for ((origin, _), o) in rays.iter().zip(out.iter_mut()) {
            let q = self.to_camera.transform_point3(*origin);
            let inside = q.x.abs() <= self.half.x && q.y.abs() <= self.half.y;
            *o = CameraRayPdf {
                pdf_pos: if inside { 1.0 / area } else { 0.0 },
                pdf_dir: 1.0,
            };
        }
    }

    fn directional(&self) -> bool {
        true
    }
}

impl Camera for Orthographic {
    fn importance(&self) -> Option<&dyn Importance> {
        Some(self)
    }

    fn uses_lens_samples(&self) -> bool {
        false
    }

    fn generate(&self, film: &[Vec2], _lens: &[Vec2], out: CameraRays<'_>) {
        let dir = self.direction();
        for (i, p) in film.iter().enumerate() {
            let ndc = self.raster.ndc(*p);
            // Camera space +x is left, NDC +x is right.
            let local = Vec3::new(-ndc.x * self.half.x, ndc.y * self.half.y, 0.0);
            out.origins[i] = self.to_render.transform_point3(local);
            out.directions[i] = dir;
            out.weights[i] = 1.0;
        }
    }

    fn gpu(&self) -> Option<GpuModule> {
        let params = self
            .raster
            .gpu_params(gpu_pose(&self.to_render))
            .f32(self.half.x)
            .f32(self.half.y)
            .vec3(self.direction());
        Some(GpuModule::new(
            "orthographic",
            include_str!("orthographic.wgsl"),
            params,
        ))
    }
}

pub(crate) fn register(registry: &mut Registry) {
    crate::register_camera(
        registry,
        "orthographic",
        "Parallel projection along the view direction. Pose from `look_at` or `transform`.",
        DOCS,
        |p: OrthographicParams, to_render, resolution| {
            Orthographic::new(to_render, resolution, p.width)
        },
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
        check_param_docs::<OrthographicParams>(DOCS).unwrap();
    }

    #[test]
    fn rejects_empty_windows() {
        let res = Vec2::new(4.0, 2.0);
        assert!(Orthographic::new(Mat4::IDENTITY, res, 0.0).is_err());
        assert!(Orthographic::new(Mat4::IDENTITY, res, f32::INFINITY).is_err());
        let cam = Orthographic::new(Mat4::IDENTITY, res, 4.0).unwrap();
        assert_eq!(cam.half, Vec2::new(2.0, 1.0));
    }
}
