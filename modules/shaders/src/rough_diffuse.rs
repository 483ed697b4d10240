//! The `rough_diffuse` shader: the Oren–Nayar model of a surface made of
//! Lambertian V-cavities, in the full form with the interreflection term
//! as in Mitsuba 3's `roughdiffuse` (after Oren and Nayar 1994); sampled by
//! the cosine-weighted hemisphere.

use crate::gpu;
use crate::inputs::{fraction, half, scalar, texture_effects};
use crate::lobes::reflection_sample;
use radiant_core::glam::{Vec2, Vec3};
use radiant_core::params::Spanned;
use radiant_core::warp::{cosine_hemisphere_pdf, square_to_cosine_hemisphere};
use radiant_core::{
    BsdfEval, BsdfSample, BuildContext, Effects, GpuModule, GpuParams, ParamDoc, ParamError,
    Params, Registry, Rgb, ShadeContext, Shader, SurfaceBatch, TextureId, TextureInput,
};
use serde::Deserialize;
use std::f32::consts::{FRAC_1_PI, SQRT_2};

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct RoughDiffuseParams {
    #[serde(default = "half")]
    reflectance: Spanned<TextureInput>,
    #[serde(default = "point_two")]
    alpha: Spanned<TextureInput>,
}

fn point_two() -> Spanned<TextureInput> {
    TextureInput::spanned_value(Rgb::splat(0.2))
}

const DOCS: &[ParamDoc] = &[
    ParamDoc {
        name: "reflectance",
        ty: "rgb | number | texture name, [0, 1]",
        default: "0.5",
        doc: "Albedo of the Lambertian facets.",
    },
    ParamDoc {
        name: "alpha",
        ty: "number | texture name, [0, 1] (RMS facet slope; σ = α/√2 radians)",
        default: "0.2",
        doc: "Roughness; 0 is Lambertian.",
    },
];

/// Oren–Nayar reflection (one-sided).
struct RoughDiffuse {
    reflectance: TextureId,
    alpha: TextureId,
    effects: Effects,
}

/// f·cos θi of the full Oren–Nayar model.
#[inline]
fn oren_nayar(rho: Rgb, alpha: f32, wo: Vec3, wi: Vec3) -> Rgb {
    if wo.z <= 0.0 || wi.z <= 0.0 {
        return Rgb::ZERO;
    }
    let sigma = alpha / SQRT_2;
    let sigma2 = sigma * sigma;
    let (cos_i, cos_o) = (wi.z.min(1.0), wo.z.min(1.0));
    let sin_i = (1.0 - cos_i * cos_i).max(0.0).sqrt();
    let sin_o = (1.0 - cos_o * cos_o).max(0.0).sqrt();
    let cos_phi_diff = if sin_i > 1e-4 && sin_o > 1e-4 {
        ((wi.x * wo.x + wi.y * wo.y) / (sin_i * sin_o)).clamp(-1.0, 1.0)
    } else {
        0.0
    };
    let (theta_i, theta_o) = (cos_i.acos(), cos_o.acos());
    let alpha_ang = theta_i.max(theta_o);
    let beta = theta_i.min(theta_o);
    let (sin_alpha, sin_beta, tan_beta) = if cos_i > cos_o {
        (sin_o, sin_i, sin_i / cos_i)
    } else {
        (sin_i, sin_o, sin_o / cos_o)
    };
    let tmp = sigma2 / (sigma2 + 0.09);
    let tmp2 = 4.0 * FRAC_1_PI * FRAC_1_PI * alpha_ang * beta;
    let tmp3 = 2.0 * beta * FRAC_1_PI;
    let c1 = 1.0 - 0.5 * sigma2 / (sigma2 + 0.33);
    let mut c2 = 0.45 * tmp;
    let c3 = 0.125 * tmp * tmp2 * tmp2;
    let c4 = 0.17 * sigma2 / (sigma2 + 0.13);
    if cos_phi_diff > 0.0 {
        c2 *= sin_alpha;
    } else {
        c2 *= sin_alpha - tmp3 * tmp3 * tmp3;
    }
    let tan_half = (sin_alpha + sin_beta)
        / ((1.0 - sin_alpha * sin_alpha).max(0.0).sqrt()
            + (1.0 - sin_beta * sin_beta).max(0.0).sqrt());
    let single =
        rho * (c1 + cos_phi_diff * c2 * tan_beta + (1.0 - cos_phi_diff.abs()) * c3 * tan_half);
    let double = rho * rho * (c4 * (1.0 - cos_phi_diff * tmp3 * tmp3));
    let value = (single + double).max(Rgb::ZERO) * (FRAC_1_PI * cos_i);
    if value.is_finite() { value } else { Rgb::ZERO }
}

impl Shader for RoughDiffuse {
    fn uses_lobe_samples(&self) -> bool {
        false
    }

    fn sample(
        &self,
        ctx: &mut ShadeContext<'_>,
        surface: SurfaceBatch<'_>,
        u: &[Vec3],
        out: &mut [BsdfSample],
    ) {
        let [rho, alpha] = ctx.lookup([self.reflectance, self.alpha], surface.uv);
        for (i, o) in out.iter_mut().enumerate() {
            let wo = surface.wo[i];
            let wi = square_to_cosine_hemisphere(Vec2::new(u[i].y, u[i].z));
            let pdf = cosine_hemisphere_pdf(wi);
            *o = if wo.z > 0.0 && pdf > 0.0 {
                reflection_sample(wi, oren_nayar(rho[i], scalar(alpha[i]), wo, wi) / pdf, pdf)
            } else {
                BsdfSample::default()
            };
        }
    }

    fn eval(
        &self,
        ctx: &mut ShadeContext<'_>,
        surface: SurfaceBatch<'_>,
        wi: &[Vec3],
        out: &mut [BsdfEval],
    ) {
        let [rho, alpha] = ctx.lookup([self.reflectance, self.alpha], surface.uv);
        for (i, o) in out.iter_mut().enumerate() {
            let (wo, wi) = (surface.wo[i], wi[i]);
            *o = if wo.z > 0.0 && wi.z > 0.0 {
                BsdfEval {
                    value: oren_nayar(rho[i], scalar(alpha[i]), wo, wi),
                    pdf: cosine_hemisphere_pdf(wi),
                }
            } else {
                BsdfEval::default()
            };
        }
    }

    fn effects(&self) -> Effects {
        self.effects
    }

    fn gpu(&self) -> Option<GpuModule> {
        let params = GpuParams::new()
            .texture(self.reflectance)
            .texture(self.alpha);
        Some(gpu::module("rough_diffuse", &[gpu::ROUGH_DIFFUSE], params))
    }
}

fn build(params: &Params, ctx: &mut BuildContext<'_>) -> Result<RoughDiffuse, ParamError> {
    let p: RoughDiffuseParams = params.parse()?;
    let reflectance = fraction(ctx, &p.reflectance, "reflectance")?;
    let alpha = fraction(ctx, &p.alpha, "alpha")?;
    Ok(RoughDiffuse {
        reflectance,
        alpha,
        effects: Effects::SMOOTH_LOBES | texture_effects(ctx, &[reflectance, alpha]),
    })
}

pub(crate) fn register(registry: &mut Registry) {
    crate::register_shader(
        registry,
        "rough_diffuse",
        "Oren–Nayar rough diffuse reflector (full model with interreflection, as Mitsuba 3).",
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
        check_param_docs::<RoughDiffuseParams>(DOCS).unwrap();
    }

    #[test]
    fn zero_roughness_is_lambertian() {
        let wo = Vec3::new(0.6, 0.0, 0.8);
        let wi = Vec3::new(0.0, -0.28, 0.96);
        let v = oren_nayar(Rgb::splat(0.5), 0.0, wo, wi);
        assert!((v.x - 0.5 * FRAC_1_PI * 0.96).abs() < 1e-6, "{v}");
    }
}
