//! The `directional` light: parallel light from infinitely far away, such
//! as sunlight. Its next-event samples lie outside the scene's bounding
//! sphere, against the direction of travel.

use crate::delta::sample_delta;
use crate::params::{axis, check_colour};
use radiant_core::glam::{DVec3, Vec2, Vec3};
use radiant_core::{
    BoundingSphere, BuildContext, Color, Effects, GpuModule, GpuParams, Light, LightSample,
    Numbers, ParamDoc, ParamError, Params, Registry, Rgb, luminance,
};
use serde::Deserialize;

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct DirectionalParams {
    direction: Option<Numbers<3>>,
    irradiance: Color,
}

const DOCS: &[ParamDoc] = &[
    ParamDoc {
        name: "direction",
        ty: "[x, y, z]",
        default: "[0, 0, 1]",
        doc: "Direction in which the light travels (turned by the light's `transform`).",
    },
    ParamDoc {
        name: "irradiance",
        ty: "rgb, W/m²",
        default: "required",
        doc: "Irradiance on a surface facing the light.",
    },
];

/// Light arriving from the single direction `-direction` with the same
/// irradiance everywhere.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct DirectionalLight {
    direction: Vec3,
    irradiance: Rgb,
    sphere: BoundingSphere,
}

impl DirectionalLight {
    /// Light travelling along the unit vector `direction` (render space),
    /// for a scene bounded by `sphere`.
    pub fn new(direction: Vec3, irradiance: Rgb, sphere: BoundingSphere) -> Self {
        Self {
            direction,
            irradiance,
            sphere,
        }
    }

    /// From a reference point to its sample point: against the direction
    /// of travel, twice the scene's radius (outside the scene).
    #[inline]
    fn back(&self) -> Vec3 {
        self.direction * (-2.0 * self.sphere.radius)
    }
}

impl Light for DirectionalLight {
    /// The power falling on a disc that covers the scene: π r² E.
    fn power(&self) -> f32 {
        std::f32::consts::PI * self.sphere.radius * self.sphere.radius * luminance(self.irradiance)
    }

    fn is_delta(&self) -> bool {
        true
    }

    fn uses_point_samples(&self) -> bool {
        false
    }

    fn sample(&self, refs: &[Vec3], _u: &[Vec2], out: &mut [LightSample]) {
        let back = self.back();
        sample_delta(refs, out, |r| (r + back, self.irradiance));
    }

    fn effects(&self) -> Effects {
        Effects::DELTA_LIGHTS
    }

    fn emission(&self) -> Option<&dyn radiant_core::Emission> {
        Some(self)
    }

    fn gpu(&self) -> Option<GpuModule> {
        let params = GpuParams::new().vec3(self.back()).rgb(self.irradiance);
        Some(GpuModule::new(
            "directional",
            include_str!("directional.wgsl"),
            params,
        ))
    }
}

/// Emitted rays: along the light's direction from a point drawn uniformly
/// on the disc that covers the scene, upstream of it.
impl radiant_core::Emission for DirectionalLight {
    fn kind(&self) -> radiant_core::EmissionKind {
        radiant_core::EmissionKind::Directional
    }

    fn sample_emission(
        &self,
        u_pos: &[Vec2],
        _u_dir: &[Vec2],
        out: &mut [radiant_core::EmissionSample],
    ) {
        for (u, o) in u_pos.iter().zip(out.iter_mut()) {
            let (p, pdf_pos) = crate::emitted::disc_origin(&self.sphere, self.direction, *u);
            *o = radiant_core::EmissionSample {
                p,
                n: Vec3::ZERO,
                dir: self.direction,
                radiance: self.irradiance,
                pdf_pos,
                pdf_dir: 1.0,
                kind: radiant_core::EmissionKind::Directional,
                primitive: 0,
            };
        }
    }

    fn emission_pdf(
        &self,
        rays: &[radiant_core::EmittedRay],
        out: &mut [radiant_core::EmissionPdf],
    ) {
        let pdf = radiant_core::EmissionPdf {
            pdf_pos: crate::emitted::disc_pdf(&self.sphere),
            pdf_dir: 1.0,
        };
        out[..rays.len()].fill(pdf);
    }
}

fn build(params: &Params, ctx: &mut BuildContext<'_>) -> Result<DirectionalLight, ParamError> {
    let p: DirectionalParams = params.parse()?;
    check_colour(params, "irradiance", p.irradiance.0)?;
    let direction = axis(params, ctx, DVec3::ZERO, p.direction, None)?;
    Ok(DirectionalLight::new(
        direction,
        p.irradiance.0,
        ctx.scene_sphere,
    ))
}

pub(crate) fn register(registry: &mut Registry) {
    crate::register_light(
        registry,
        "directional",
        "Parallel light from infinitely far away (e.g. the sun).",
        DOCS,
        build,
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
        check_param_docs::<DirectionalParams>(DOCS).unwrap();
    }

    #[test]
    fn samples_lie_upstream_outside_the_scene() {
        let sphere = BoundingSphere {
            centre: Vec3::new(1.0, 0.0, 0.0),
            radius: 3.0,
        };
        let d = Vec3::new(0.0, -1.0, 0.0);
        let light = DirectionalLight::new(d, Rgb::new(1.0, 2.0, 3.0), sphere);
        let refs = [Vec3::new(1.0, 0.0, 0.0), Vec3::new(3.9, -1.0, 0.5)];
        let mut out = [LightSample::default(); 2];
        light.sample(&refs, &[Vec2::ZERO; 2], &mut out);
        for (s, r) in out.iter().zip(&refs) {
            // Straight up from the reference point, beyond the sphere.
            let to = (s.p - *r).normalize();
            assert!((to - (-d)).length() < 1e-6);
            assert!((s.p - sphere.centre).length() > sphere.radius);
            assert_eq!(
                (s.radiance, s.pdf, s.n),
                (Rgb::new(1.0, 2.0, 3.0), 1.0, Vec3::ZERO)
            );
        }
        let expected = std::f32::consts::PI * 9.0 * luminance(Rgb::new(1.0, 2.0, 3.0));
        assert!((light.power() - expected).abs() < 1e-4);
    }
}
