//! The `thin_lens` camera: a pinhole widened to a circular aperture, for
//! depth of field.
//!
//! Rays start at a point of the aperture disk (radius `aperture_radius`,
//! sampled with the concentric map, density 1/(π r²)) and pass through the
//! point of the focal plane z = `focus_distance` that the pinhole ray of
//! the same film position reaches, so that plane is in focus (Mitsuba 3's
//! `thinlens`).

use crate::importance::Lens;
use crate::projection::{
    FOV_AXIS_DOC, FOV_DOC, FovAxis, InvalidParam, Pinhole, check_min, default_fov, gpu_pose,
};
use radiant_core::glam::{Mat4, Vec2};
use radiant_core::warp::square_to_disk_concentric;
use radiant_core::{Camera, CameraRays, Effects, GpuModule, Importance, ParamDoc, Registry};
use serde::Deserialize;

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct ThinLensParams {
    #[serde(default = "default_fov")]
    fov: f32,
    #[serde(default)]
    fov_axis: FovAxis,
    aperture_radius: f32,
    focus_distance: f32,
}

const DOCS: &[ParamDoc] = &[
    FOV_DOC,
    FOV_AXIS_DOC,
    ParamDoc {
        name: "aperture_radius",
        ty: "scene units, ≥ 0",
        default: "required",
        doc: "Radius of the lens aperture (0 is a pinhole).",
    },
    ParamDoc {
        name: "focus_distance",
        ty: "scene units, > 0",
        default: "required",
        doc: "Distance along the view direction of the plane in focus.",
    },
];

/// A thin-lens camera with a circular aperture.
#[derive(Debug, Clone, PartialEq)]
pub struct ThinLens {
    to_render: Mat4,
    pinhole: Pinhole,
    aperture_radius: f32,
    focus_distance: f32,
    lens: Lens,
}

impl ThinLens {
    /// A thin lens of `aperture_radius` focused at `focus_distance`, with a
    /// full field of view of `fov_degrees` along `axis`.
    pub fn new(
        to_render: Mat4,
        resolution: Vec2,
        fov_degrees: f32,
        axis: FovAxis,
        aperture_radius: f32,
        focus_distance: f32,
    ) -> Result<Self, InvalidParam> {
        let pinhole = Pinhole::new(resolution, fov_degrees, axis)?;
        let aperture_radius =
            check_min("aperture_radius", aperture_radius, 0.0, true, "scene units")?;
        let focus_distance =
            check_min("focus_distance", focus_distance, 0.0, false, "scene units")?;
        Ok(Self {
            to_render,
            pinhole,
            aperture_radius,
            focus_distance,
            lens: Lens::new(to_render, pinhole, aperture_radius, focus_distance),
        })
    }

    /// Density of lens positions per unit aperture area, 1/(π r²).
    pub fn lens_pdf(&self) -> f32 {
        1.0 / (std::f32::consts::PI * self.aperture_radius * self.aperture_radius)
    }
}

impl Camera for ThinLens {
    fn generate(&self, film: &[Vec2], lens: &[Vec2], out: CameraRays<'_>) {
        for (i, (p, u)) in film.iter().zip(lens).enumerate() {
            let focus =
                (self.pinhole.plane_point(*p) * self.focus_distance).extend(self.focus_distance);
            let aperture = (square_to_disk_concentric(*u) * self.aperture_radius).extend(0.0);
            out.origins[i] = self.to_render.transform_point3(aperture);
            out.directions[i] = self
                .to_render
                .transform_vector3(focus - aperture)
                .normalize();
            out.weights[i] = 1.0;
        }
    }

    fn effects(&self) -> Effects {
        Effects::DEPTH_OF_FIELD
    }

    fn importance(&self) -> Option<&dyn Importance> {
        Some(&self.lens)
    }

    fn gpu(&self) -> Option<GpuModule> {
        let params = self
            .pinhole
            .gpu_params(gpu_pose(&self.to_render))
            .f32(self.aperture_radius)
            .f32(self.focus_distance);
        Some(GpuModule::new(
            "thin_lens",
            include_str!("thin_lens.wgsl"),
            params,
        ))
    }
}

pub(crate) fn register(registry: &mut Registry) {
    crate::register_camera(
        registry,
        "thin_lens",
        "Thin lens with a circular aperture (depth of field). Pose from `look_at` or `transform`.",
        DOCS,
        |p: ThinLensParams, to_render, resolution| {
            ThinLens::new(
                to_render,
                resolution,
                p.fov,
                p.fov_axis,
                p.aperture_radius,
                p.focus_distance,
            )
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
        check_param_docs::<ThinLensParams>(DOCS).unwrap();
    }

    #[test]
    fn rejects_bad_apertures_and_focus_distances() {
        let res = Vec2::new(64.0, 64.0);
        assert!(ThinLens::new(Mat4::IDENTITY, res, 40.0, FovAxis::X, -0.1, 1.0).is_err());
        assert!(ThinLens::new(Mat4::IDENTITY, res, 40.0, FovAxis::X, 0.1, 0.0).is_err());
        assert!(ThinLens::new(Mat4::IDENTITY, res, 40.0, FovAxis::X, f32::NAN, 1.0).is_err());
        assert!(ThinLens::new(Mat4::IDENTITY, res, 0.0, FovAxis::X, 0.1, 1.0).is_err());
        assert!(ThinLens::new(Mat4::IDENTITY, res, 40.0, FovAxis::X, 0.0, 1.0).is_ok());
    }

    #[test]
    fn declares_depth_of_field() {
        let cam =
            ThinLens::new(Mat4::IDENTITY, Vec2::splat(8.0), 40.0, FovAxis::X, 0.1, 2.0).unwrap();
        assert_eq!(cam.effects(), Effects::DEPTH_OF_FIELD);
    }
}
