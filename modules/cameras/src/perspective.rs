//! The `perspective` camera: an ideal pinhole.

use crate::importance::Lens;
use crate::projection::{
    FOV_AXIS_DOC, FOV_DOC, FovAxis, InvalidParam, Pinhole, central_rays, default_fov, gpu_pose,
};
use radiant_core::glam::{Mat4, Vec2};
use radiant_core::{Camera, CameraRays, GpuModule, Importance, ParamDoc, Registry};
use serde::Deserialize;

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct PerspectiveParams {
    #[serde(default = "default_fov")]
    fov: f32,
    #[serde(default)]
    fov_axis: FovAxis,
}

const DOCS: &[ParamDoc] = &[FOV_DOC, FOV_AXIS_DOC];

/// An ideal pinhole camera (Mitsuba 3's `perspective` without clipping
/// planes): rays start at the pose origin and go through the film.
#[derive(Debug, Clone, PartialEq)]
pub struct Perspective {
    to_render: Mat4,
    pinhole: Pinhole,
    lens: Lens,
}

impl Perspective {
    /// A pinhole camera with full field of view `fov_degrees` along `axis`.
    pub fn new(
        to_render: Mat4,
        resolution: Vec2,
        fov_degrees: f32,
        axis: FovAxis,
    ) -> Result<Self, InvalidParam> {
        let pinhole = Pinhole::new(resolution, fov_degrees, axis)?;
        Ok(Self {
            to_render,
            pinhole,
            lens: Lens::new(to_render, pinhole, 0.0, 1.0),
        })
    }
}

impl Camera for Perspective {
    fn uses_lens_samples(&self) -> bool {
        false
    }

    fn generate(&self, film: &[Vec2], _lens: &[Vec2], out: CameraRays<'_>) {
        central_rays(&self.to_render, film, out, |p| {
            self.pinhole.plane_point(p).extend(1.0)
        });
    }

    fn importance(&self) -> Option<&dyn Importance> {
        Some(&self.lens)
    }

    fn gpu(&self) -> Option<GpuModule> {
        Some(GpuModule::new(
            "perspective",
            include_str!("perspective.wgsl"),
            self.pinhole.gpu_params(gpu_pose(&self.to_render)),
        ))
    }
}

pub(crate) fn register(registry: &mut Registry) {
    crate::register_camera(
        registry,
        "perspective",
        "Ideal pinhole camera. Pose from the camera's `look_at` or `transform`.",
        DOCS,
        |p: PerspectiveParams, to_render, resolution| {
            Perspective::new(to_render, resolution, p.fov, p.fov_axis)
        },
    );
}

#[cfg(test)]
mod tests {
    use super::*;
    use radiant_core::Params;
    use radiant_core::glam::Vec3;
    use radiant_core::params::check_param_docs;

    #[test]
    fn documented_parameters_match() {
        check_param_docs::<PerspectiveParams>(DOCS).unwrap();
    }

    #[test]
    fn parses_axis_names() {
        let p: PerspectiveParams = Params::from_yaml("fov: 30\nfov_axis: smaller\n")
            .unwrap()
            .parse()
            .unwrap();
        assert_eq!(p.fov_axis, FovAxis::Smaller);
        let err = Params::from_yaml("fov_axis: widest\n")
            .unwrap()
            .parse::<PerspectiveParams>()
            .unwrap_err();
        assert!(err.message.contains("widest"), "{}", err.message);
    }

    #[test]
    fn centre_ray_looks_forward_and_corners_match_fov() {
        let cam =
            Perspective::new(Mat4::IDENTITY, Vec2::new(200.0, 100.0), 90.0, FovAxis::X).unwrap();
        let film = [
            Vec2::new(100.0, 50.0),
            Vec2::new(0.0, 50.0),
            Vec2::new(100.0, 0.0),
        ];
        let (mut o, mut d, mut w) = ([Vec3::ZERO; 3], [Vec3::ZERO; 3], [0.0; 3]);
        cam.generate(
            &film,
            &[Vec2::ZERO; 3],
            CameraRays {
                origins: &mut o,
                directions: &mut d,
                weights: &mut w,
            },
        );
        assert!((d[0] - Vec3::Z).length() < 1e-6);
        // Left edge of the image: 45° towards camera-space +x (left).
        assert!((d[1] - Vec3::new(1.0, 0.0, 1.0).normalize()).length() < 1e-6);
        // Top edge: half the horizontal extent because of the 2:1 aspect.
        assert!((d[2] - Vec3::new(0.0, 0.5, 1.0).normalize()).length() < 1e-6);
        assert!(Perspective::new(Mat4::IDENTITY, Vec2::ONE, 180.0, FovAxis::X).is_err());
    }
}
