//! The `point` light: an isotropic point source.

use crate::delta::sample_delta;
use crate::params::{check_colour, place};
use radiant_core::glam::{DVec3, Vec2, Vec3};
use radiant_core::{
    BuildContext, Color, Effects, GpuModule, GpuParams, Light, LightBounds, LightSample, Numbers,
    ParamDoc, ParamError, Params, Registry, Rgb, luminance,
};
use serde::Deserialize;

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct PointParams {
    position: Numbers<3>,
    intensity: Color,
}

const DOCS: &[ParamDoc] = &[
    ParamDoc {
        name: "position",
        ty: "[x, y, z], world space",
        default: "required",
        doc: "Where the light is (moved by the light's `transform`).",
    },
    ParamDoc {
        name: "intensity",
        ty: "rgb, W/sr",
        default: "required",
        doc: "Radiant intensity, the same in every direction.",
    },
];

/// An isotropic point light.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PointLight {
    position: Vec3,
    intensity: Rgb,
}

impl PointLight {
    /// A point light at `position` (render space) with `intensity`.
    pub fn new(position: Vec3, intensity: Rgb) -> Self {
        Self {
            position,
            intensity,
        }
    }
}

impl Light for PointLight {
    fn power(&self) -> f32 {
        4.0 * std::f32::consts::PI * luminance(self.intensity)
    }

    fn bounds(&self) -> Option<LightBounds> {
        Some(LightBounds::point(
            self.position,
            luminance(self.intensity),
            Vec3::Z,
            -1.0,
            0.0,
        ))
    }

    fn is_delta(&self) -> bool {
        true
    }

    fn uses_point_samples(&self) -> bool {
        false
    }

    fn sample(&self, refs: &[Vec3], _u: &[Vec2], out: &mut [LightSample]) {
        sample_delta(refs, out, |r| {
            let dist2 = (self.position - r).length_squared();
            let radiance = if dist2 > 0.0 {
                self.intensity / dist2
            } else {
                Rgb::ZERO
            };
            (self.position, radiance)
        });
    }

    fn effects(&self) -> Effects {
        Effects::DELTA_LIGHTS
    }

    fn emission(&self) -> Option<&dyn radiant_core::Emission> {
        Some(self)
    }

    fn gpu(&self) -> Option<GpuModule> {
        let params = GpuParams::new().vec3(self.position).rgb(self.intensity);
        Some(GpuModule::new("point", include_str!("point.wgsl"), params))
    }
}

/// Emitted rays: from the light's position, uniformly over the sphere.
impl radiant_core::Emission for PointLight {
    fn kind(&self) -> radiant_core::EmissionKind {
        radiant_core::EmissionKind::Point
    }

    fn sample_emission(
        &self,
        _u_pos: &[Vec2],
        u_dir: &[Vec2],
        out: &mut [radiant_core::EmissionSample],
    ) {
        use radiant_core::warp::{UNIFORM_SPHERE_PDF, square_to_uniform_sphere};
        for (u, o) in u_dir.iter().zip(out.iter_mut()) {
            *o = radiant_core::EmissionSample {
                p: self.position,
                n: Vec3::ZERO,
                dir: square_to_uniform_sphere(*u),
                radiance: self.intensity,
                pdf_pos: 1.0,
                pdf_dir: UNIFORM_SPHERE_PDF,
                kind: radiant_core::EmissionKind::Point,
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
            pdf_pos: 1.0,
            pdf_dir: radiant_core::warp::UNIFORM_SPHERE_PDF,
        };
        out[..rays.len()].fill(pdf);
    }
}

fn build(params: &Params, ctx: &mut BuildContext<'_>) -> Result<PointLight, ParamError> {
    let p: PointParams = params.parse()?;
    check_colour(params, "intensity", p.intensity.0)?;
    let position = place(ctx, DVec3::from(p.position));
    Ok(PointLight::new(position, p.intensity.0))
}

pub(crate) fn register(registry: &mut Registry) {
    crate::register_light(registry, "point", "Isotropic point light.", DOCS, build);
}

#[cfg(test)]
mod tests {
    use super::*;
    use radiant_core::params::check_param_docs;

    #[test]
    fn documented_parameters_match() {
        check_param_docs::<PointParams>(DOCS).unwrap();
    }

    #[test]
    fn falls_off_with_the_square_of_distance() {
        let light = PointLight::new(Vec3::new(0.0, 2.0, 0.0), Rgb::splat(8.0));
        let mut out = [LightSample::default(); 2];
        light.sample(
            &[Vec3::ZERO, Vec3::new(0.0, -2.0, 0.0)],
            &[Vec2::ZERO; 2],
            &mut out,
        );
        assert_eq!(out[0].radiance, Rgb::splat(2.0));
        assert_eq!(out[1].radiance, Rgb::splat(0.5));
        assert!(light.is_delta());
    }
}
