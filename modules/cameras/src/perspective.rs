//! The `perspective` camera: an ideal pinhole.

use radiant_core::glam::{Mat4, Vec2, Vec3};
use radiant_core::{
    BuildContext, Camera, CameraRays, ModuleInfo, ParamDoc, ParamError, Params, Registry,
};
use serde::Deserialize;

/// Which image axis the field of view is measured along.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum FovAxis {
    /// The horizontal axis.
    #[default]
    X,
    /// The vertical axis.
    Y,
    /// The shorter of the two.
    Smaller,
    /// The longer of the two.
    Larger,
    /// The image diagonal.
    Diagonal,
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct PerspectiveParams {
    #[serde(default = "default_fov")]
    fov: f32,
    #[serde(default)]
    fov_axis: FovAxis,
}

fn default_fov() -> f32 {
    45.0
}

const DOCS: &[ParamDoc] = &[
    ParamDoc {
        name: "fov",
        ty: "degrees, (0, 180)",
        default: "45",
        doc: "Full field of view along `fov_axis`.",
    },
    ParamDoc {
        name: "fov_axis",
        ty: "x | y | smaller | larger | diagonal",
        default: "x",
        doc: "Image axis the field of view is measured along.",
    },
];

/// An ideal pinhole camera (Mitsuba 3's `perspective` without clipping
/// planes): rays start at the pose origin and go through the film.
#[derive(Debug, Clone, PartialEq)]
pub struct Perspective {
    to_render: Mat4,
    /// tan(half field of view) along x and y.
    tan_half: Vec2,
    resolution: Vec2,
}

impl Perspective {
    /// A pinhole camera with full field of view `fov_degrees` along `axis`.
    pub fn new(
        to_render: Mat4,
        resolution: Vec2,
        fov_degrees: f32,
        axis: FovAxis,
    ) -> Result<Self, String> {
        if !(fov_degrees > 0.0 && fov_degrees < 180.0) {
            return Err(format!(
                "fov must be between 0 and 180 degrees (exclusive), found {fov_degrees}"
            ));
        }
        let aspect = resolution.x / resolution.y;
        let t = (fov_degrees.to_radians() * 0.5).tan();
        let along_x = match axis {
            FovAxis::X => true,
            FovAxis::Y => false,
            FovAxis::Smaller => aspect <= 1.0,
            FovAxis::Larger => aspect > 1.0,
            FovAxis::Diagonal => {
                let diag = (1.0 + 1.0 / (aspect * aspect)).sqrt();
                return Ok(Self {
                    to_render,
                    tan_half: Vec2::new(t / diag, t / diag / aspect),
                    resolution,
                });
            }
        };
        let tan_half = if along_x {
            Vec2::new(t, t / aspect)
        } else {
            Vec2::new(t * aspect, t)
        };
        Ok(Self {
            to_render,
            tan_half,
            resolution,
        })
    }
}

impl Camera for Perspective {
    fn generate(&self, film: &[Vec2], _lens: &[Vec2], out: CameraRays<'_>) {
        let origin = self.to_render.transform_point3(Vec3::ZERO);
        let scale = 2.0 / self.resolution;
        for (i, p) in film.iter().enumerate() {
            let ndc = Vec2::new(p.x * scale.x - 1.0, 1.0 - p.y * scale.y);
            // Camera space: +x left, +y up, +z forward.
            let local = Vec3::new(-ndc.x * self.tan_half.x, ndc.y * self.tan_half.y, 1.0);
            out.origins[i] = origin;
            out.directions[i] = self.to_render.transform_vector3(local).normalize();
            out.weights[i] = 1.0;
        }
    }
}

pub(crate) fn register(registry: &mut Registry) {
    registry.register::<dyn Camera>(
        ModuleInfo {
            type_name: "perspective",
            summary: "Ideal pinhole camera. Pose from the camera's `look_at` or `transform`.",
            params: DOCS,
        },
        |params: &Params, ctx: &mut BuildContext<'_>| {
            let p: PerspectiveParams = params.parse()?;
            let camera = Perspective::new(
                ctx.camera_to_render,
                ctx.resolution.as_vec2(),
                p.fov,
                p.fov_axis,
            )
            .map_err(|msg| ParamError {
                message: msg,
                location: params.location_of("fov"),
            })?;
            Ok(Box::new(camera) as Box<dyn Camera>)
        },
    );
}

#[cfg(test)]
mod tests {
    use super::*;
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
