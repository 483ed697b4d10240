//! What the cameras share: the film-to-camera-plane mapping, the rays of
//! central projections, the field of view parameters and their validation.
//!
//! Camera space follows Mitsuba: +z forward, +y up, +x left. Film positions
//! are raster pixels with the origin at the image's top-left corner and +y
//! down. Every camera maps a film position to *normalised device
//! coordinates* in [−1, 1]² (+x right, +y up) first.

use radiant_core::glam::{Mat4, Vec2, Vec3};
use radiant_core::{CameraRays, GpuParams, ParamDoc, ParamError, Params};
use serde::Deserialize;
use std::fmt;

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

/// Documentation of the `fov` parameter.
pub(crate) const FOV_DOC: ParamDoc = ParamDoc {
    name: "fov",
    ty: "degrees, (0, 180)",
    default: "45",
    doc: "Full field of view along `fov_axis`.",
};

/// Documentation of the `fov_axis` parameter.
pub(crate) const FOV_AXIS_DOC: ParamDoc = ParamDoc {
    name: "fov_axis",
    ty: "x | y | smaller | larger | diagonal",
    default: "x",
    doc: "Image axis the field of view is measured along.",
};

/// The default field of view in degrees.
pub(crate) fn default_fov() -> f32 {
    45.0
}

/// Maps raster positions to normalised device coordinates.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct Raster {
    scale: Vec2,
}

impl Raster {
    pub(crate) fn new(resolution: Vec2) -> Self {
        Self {
            scale: 2.0 / resolution,
        }
    }

    /// Appends the raster scale (2 / resolution, two words) for WGSL.
    pub(crate) fn gpu_params(&self, params: GpuParams) -> GpuParams {
        params.f32(self.scale.x).f32(self.scale.y)
    }

    /// The raster scale: 2 / resolution per axis.
    pub(crate) fn scale(&self) -> Vec2 {
        self.scale
    }

    /// Raster pixels (top-left origin, +y down) to NDC ([−1, 1]², +y up).
    #[inline]
    pub(crate) fn ndc(&self, p: Vec2) -> Vec2 {
        Vec2::new(p.x * self.scale.x - 1.0, 1.0 - p.y * self.scale.y)
    }
}

/// The image plane of a pinhole at distance 1: tan(half field of view)
/// along x and y.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct Pinhole {
    raster: Raster,
    tan_half: Vec2,
}

impl Pinhole {
    /// The image plane for a full field of view of `fov_degrees` along
    /// `axis` on a film of `resolution` pixels.
    pub(crate) fn new(
        resolution: Vec2,
        fov_degrees: f32,
        axis: FovAxis,
    ) -> Result<Self, InvalidParam> {
        if !(fov_degrees > 0.0 && fov_degrees < 180.0) {
            return Err(InvalidParam {
                key: "fov",
                message: format!(
                    "`fov` must be between 0 and 180 degrees (exclusive), found {fov_degrees}"
                ),
            });
        }
        let aspect = resolution.x / resolution.y;
        let t = (fov_degrees.to_radians() * 0.5).tan();
        let tan_half = match axis {
            FovAxis::X => Vec2::new(t, t / aspect),
            FovAxis::Y => Vec2::new(t * aspect, t),
            FovAxis::Smaller if aspect <= 1.0 => Vec2::new(t, t / aspect),
            FovAxis::Larger if aspect > 1.0 => Vec2::new(t, t / aspect),
            FovAxis::Smaller | FovAxis::Larger => Vec2::new(t * aspect, t),
            FovAxis::Diagonal => {
                let diag = (1.0 + 1.0 / (aspect * aspect)).sqrt();
                Vec2::new(t / diag, t / diag / aspect)
            }
        };
        Ok(Self {
            raster: Raster::new(resolution),
            tan_half,
        })
    }

    /// Appends what the cameras' WGSL reads of the image plane: the
    /// raster scale, then tan(fov/2) per axis.
    pub(crate) fn gpu_params(&self, params: GpuParams) -> GpuParams {
        self.raster
            .gpu_params(params)
            .f32(self.tan_half.x)
            .f32(self.tan_half.y)
    }

    /// The image plane's area at distance 1.
    pub(crate) fn plane_area(&self) -> f32 {
        4.0 * self.tan_half.x * self.tan_half.y
    }

    /// The raster position that looks through the camera-space point
    /// (x, y) of the plane z = 1 ([`plane_point`](Self::plane_point)'s
    /// inverse), if it lies on the film.
    #[inline]
    pub(crate) fn raster_of(&self, plane: Vec2) -> Option<Vec2> {
        let ndc = Vec2::new(-plane.x / self.tan_half.x, plane.y / self.tan_half.y);
        let raster = Vec2::new(
            (ndc.x + 1.0) / self.raster.scale.x,
            (1.0 - ndc.y) / self.raster.scale.y,
        );
        let size = 2.0 / self.raster.scale;
        (raster.x >= 0.0 && raster.y >= 0.0 && raster.x < size.x && raster.y < size.y)
            .then_some(raster)
    }

    /// The camera-space point (x, y) on the plane z = 1 that raster
    /// position `p` looks through.
    #[inline]
    pub(crate) fn plane_point(&self, p: Vec2) -> Vec2 {
        let ndc = self.raster.ndc(p);
        // Camera space +x is left, NDC +x is right.
        Vec2::new(-ndc.x * self.tan_half.x, ndc.y * self.tan_half.y)
    }
}

/// The pose `to_render` for WGSL: its origin (translation), then its x,
/// y and z axes (twelve words), which the cameras' WGSL applies as
/// [`Mat4::transform_point3`] and [`Mat4::transform_vector3`] do
/// (origin + x·p.x + y·p.y + z·p.z, and the same without the origin).
pub(crate) fn gpu_pose(to_render: &Mat4) -> GpuParams {
    GpuParams::new()
        .vec3(to_render.transform_point3(Vec3::ZERO))
        .vec3(to_render.x_axis.truncate())
        .vec3(to_render.y_axis.truncate())
        .vec3(to_render.z_axis.truncate())
}

/// Writes the rays of a central projection: from the pose's origin along
/// the camera-space directions `direction(film[i])`, normalised after the
/// pose, with weight 1.
#[inline]
pub(crate) fn central_rays(
    to_render: &Mat4,
    film: &[Vec2],
    out: CameraRays<'_>,
    direction: impl Fn(Vec2) -> Vec3,
) {
    let origin = to_render.transform_point3(Vec3::ZERO);
    for (i, p) in film.iter().enumerate() {
        out.origins[i] = origin;
        out.directions[i] = to_render.transform_vector3(direction(*p)).normalize();
        out.weights[i] = 1.0;
    }
}

/// A camera parameter out of its range: which key, and why.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct InvalidParam {
    /// The YAML key of the parameter.
    pub key: &'static str,
    /// What is wrong and what is allowed.
    pub message: String,
}

impl fmt::Display for InvalidParam {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(&self.message)
    }
}

impl std::error::Error for InvalidParam {}

impl InvalidParam {
    /// The error located at the key's value in `params`.
    pub(crate) fn at(self, params: &Params) -> ParamError {
        ParamError {
            location: params.location_of(self.key),
            message: self.message,
        }
    }
}

/// Checks that parameter `key` is finite and above `min` (or at least `min`
/// when `inclusive`).
pub(crate) fn check_min(
    key: &'static str,
    value: f32,
    min: f32,
    inclusive: bool,
    unit: &str,
) -> Result<f32, InvalidParam> {
    if value.is_finite() && (value > min || inclusive && value == min) {
        Ok(value)
    } else {
        let relation = if inclusive {
            "at least"
        } else {
            "greater than"
        };
        Err(InvalidParam {
            key,
            message: format!("`{key}` must be a number {relation} {min} ({unit}), found {value}"),
        })
    }
}
