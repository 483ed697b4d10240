//! The `plastic` shader: a diffuse base under a dielectric coat, smooth
//! (a delta lobe over the base) or rough (GGX), with the internal
//! scattering between base and coat accounted for as in Mitsuba 3's
//! `plastic` and `roughplastic`: the base's albedo is divided by
//! 1 − (its albedo ×) the coat's internal diffuse reflectance, and light
//! crosses the coat twice, weighted by the coat's directional
//! transmittance.

use crate::fresnel;
use crate::gpu;
use crate::inputs::{Ior, fraction, half, one, relative_ior, scalar, texture_effects};
use crate::lobes::{glossy_eval, glossy_sample, mirror_sample, reflection_sample};
use crate::microfacet::{Ggx, reflect, refract};
use radiant_core::glam::{Vec2, Vec3};
use radiant_core::params::Spanned;
use radiant_core::warp::{cosine_hemisphere_pdf, square_to_cosine_hemisphere};
use radiant_core::{
    BsdfEval, BsdfSample, BuildContext, Effects, GpuModule, GpuParams, ParamDoc, ParamError,
    Params, Registry, Rgb, ShadeContext, Shader, SurfaceBatch, TextureId, TextureInput,
};
use serde::Deserialize;
use std::f32::consts::FRAC_1_PI;

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct PlasticParams {
    #[serde(default = "half")]
    diffuse_reflectance: Spanned<TextureInput>,
    #[serde(default = "one")]
    specular_reflectance: Spanned<TextureInput>,
    int_ior: Option<Spanned<Ior>>,
    ext_ior: Option<Spanned<Ior>>,
    #[serde(default)]
    nonlinear: bool,
    alpha: Option<Spanned<f32>>,
}

/// Polypropylene, Mitsuba 3's default for plastics.
const POLYPROPYLENE: f32 = 1.49;

const DOCS: &[ParamDoc] = &[
    ParamDoc {
        name: "diffuse_reflectance",
        ty: "rgb | number | texture name, [0, 1]",
        default: "0.5",
        doc: "Albedo of the diffuse base.",
    },
    ParamDoc {
        name: "specular_reflectance",
        ty: "rgb | number | texture name, [0, 1]",
        default: "1",
        doc: "Factor on the coat's reflection (physically 1).",
    },
    ParamDoc {
        name: "int_ior",
        ty: "number ≥ 1 | name (as `dielectric`)",
        default: "1.49 (polypropylene)",
        doc: "Index of refraction of the coat.",
    },
    crate::dielectric::EXT_IOR_DOC,
    ParamDoc {
        name: "nonlinear",
        ty: "bool",
        default: "false",
        doc: "Account for the colour shift of repeated base–coat bounces (divide by 1 − albedo·F_dr instead of 1 − F_dr).",
    },
    ParamDoc {
        name: "alpha",
        ty: "number, [0, 1] (isotropic GGX α)",
        default: "0 (smooth coat)",
        doc: "Roughness of the coat; a constant, since the coat's transmittance is tabulated per material.",
    },
];

/// Entries of the coat-transmittance table over cos θ ∈ [0, 1].
const TABLE: usize = 64;

/// A diffuse base under a smooth or rough dielectric coat.
struct Plastic {
    eta: f32,
    /// GGX of the coat; `None` for a smooth coat.
    ggx: Option<Ggx>,
    diffuse: TextureId,
    specular: TextureId,
    nonlinear: bool,
    /// Diffuse reflectance of the coat seen from inside.
    internal: f32,
    /// Transmittance of the coat from outside, by cos θ.
    transmittance: [f32; TABLE],
    /// Share of samples steered to the coat, before Fresnel.
    specular_weight: f32,
    effects: Effects,
}

impl Plastic {
    /// Transmittance of the coat for incidence cosine `cos` (linear
    /// interpolation in the table).
    #[inline]
    fn coat_transmittance(&self, cos: f32) -> f32 {
        if self.ggx.is_none() {
            return 1.0 - fresnel::dielectric(cos, self.eta).r;
        }
        let x = cos.clamp(0.0, 1.0) * (TABLE - 1) as f32;
        let i = (x as usize).min(TABLE - 2);
        let t = x - i as f32;
        self.transmittance[i] * (1.0 - t) + self.transmittance[i + 1] * t
    }

    /// Probability of sampling the coat for outgoing cosine `cos`.
    #[inline]
    fn specular_probability(&self, cos: f32) -> f32 {
        let t = self.coat_transmittance(cos);
        let ps = (1.0 - t) * self.specular_weight;
        let pd = t * (1.0 - self.specular_weight);
        if ps + pd > 0.0 { ps / (ps + pd) } else { 1.0 }
    }

    /// The base's contribution f·cos θi (through the coat both ways).
    #[inline]
    fn base(&self, albedo: Rgb, wo: Vec3, wi: Vec3) -> Rgb {
        let denom = if self.nonlinear {
            Rgb::ONE - albedo * self.internal
        } else {
            Rgb::splat(1.0 - self.internal)
        };
        albedo / denom
            * (self.coat_transmittance(wo.z) * self.coat_transmittance(wi.z) * FRAC_1_PI * wi.z
                / (self.eta * self.eta))
    }

    /// (f·cos θi, pdf) of the non-delta part for a pair of directions.
    #[inline]
    fn eval_point(&self, albedo: Rgb, spec: Rgb, wo: Vec3, wi: Vec3) -> (Rgb, f32) {
        if wo.z <= 0.0 || wi.z <= 0.0 {
            return (Rgb::ZERO, 0.0);
        }
        let ps = self.specular_probability(wo.z);
        let mut value = self.base(albedo, wo, wi);
        let mut pdf = (1.0 - ps) * cosine_hemisphere_pdf(wi);
        if let Some(ggx) = &self.ggx
            && let Some((m, v, p)) = glossy_eval(ggx, wo, wi)
        {
            value += spec * (fresnel::dielectric(wo.dot(m), self.eta).r * v);
            pdf += ps * p;
        }
        (value, pdf)
    }
}

impl Shader for Plastic {
    fn sample(
        &self,
        ctx: &mut ShadeContext<'_>,
        surface: SurfaceBatch<'_>,
        u: &[Vec3],
        out: &mut [BsdfSample],
    ) {
        let [albedo, spec] = ctx.lookup([self.diffuse, self.specular], surface.uv);
        for (i, o) in out.iter_mut().enumerate() {
            let wo = surface.wo[i];
            *o = BsdfSample::default();
            if wo.z <= 0.0 {
                continue;
            }
            let ps = self.specular_probability(wo.z);
            let u2 = Vec2::new(u[i].y, u[i].z);
            let wi = if u[i].x < ps {
                match &self.ggx {
                    None => {
                        let r = fresnel::dielectric(wo.z, self.eta).r;
                        *o = mirror_sample(wo, spec[i] * (r / ps), ps);
                        continue;
                    }
                    Some(ggx) => match glossy_sample(ggx, wo, u2) {
                        Some(s) => s.wi,
                        None => continue,
                    },
                }
            } else {
                square_to_cosine_hemisphere(u2)
            };
            let (value, pdf) = self.eval_point(albedo[i], spec[i], wo, wi);
            if pdf > 0.0 && wi.z > 0.0 {
                *o = reflection_sample(wi, value / pdf, pdf);
            }
        }
    }

    fn eval(
        &self,
        ctx: &mut ShadeContext<'_>,
        surface: SurfaceBatch<'_>,
        wi: &[Vec3],
        out: &mut [BsdfEval],
    ) {
        let [albedo, spec] = ctx.lookup([self.diffuse, self.specular], surface.uv);
        for (i, o) in out.iter_mut().enumerate() {
            let (value, pdf) = self.eval_point(albedo[i], spec[i], surface.wo[i], wi[i]);
            *o = BsdfEval { value, pdf };
        }
    }

    fn effects(&self) -> Effects {
        self.effects
    }

    fn gpu(&self) -> Option<GpuModule> {
        let params = GpuParams::new()
            .f32(self.eta)
            .u32(u32::from(self.ggx.is_some()))
            .f32(self.ggx.map_or(0.0, |g| g.alpha_u))
            .texture(self.diffuse)
            .texture(self.specular)
            .u32(u32::from(self.nonlinear))
            .f32(self.internal)
            .f32(self.specular_weight)
            .f32s(self.transmittance);
        Some(gpu::module("plastic", &[gpu::PLASTIC], params))
    }
}

/// Transmittance into a rough interface from outside, and reflectance,
/// for incidence cosine `mu`: averages over the visible normals of
/// (1 − F)·G1(refracted) and F·G1(reflected).
fn rough_interface_albedo(ggx: &Ggx, eta: f32, mu: f32) -> (f32, f32) {
    let mu = mu.max(1e-6);
    let wo = Vec3::new((1.0 - mu * mu).max(0.0).sqrt(), 0.0, mu);
    let n = 48;
    let (mut t, mut r) = (0.0f64, 0.0f64);
    for j in 0..n * n {
        let u = Vec2::new(
            ((j % n) as f32 + 0.5) / n as f32,
            ((j / n) as f32 + 0.5) / n as f32,
        );
        let m = ggx.sample_visible(wo, u);
        let f = fresnel::dielectric(wo.dot(m), eta);
        let wr = reflect(wo, m);
        r += (f.r * ggx.g1(wr, m)) as f64;
        if f.r < 1.0 {
            let wt = refract(wo, m, f.cos_t, f.eta_ti);
            t += ((1.0 - f.r) * ggx.g1(wt, m)) as f64;
        }
    }
    let k = (n * n) as f64;
    ((t / k) as f32, (r / k) as f32)
}

fn build(params: &Params, ctx: &mut BuildContext<'_>) -> Result<Plastic, ParamError> {
    let p: PlasticParams = params.parse()?;
    let eta = relative_ior(&p.int_ior, &p.ext_ior, POLYPROPYLENE);
    let alpha = p.alpha.as_ref().map_or(0.0, |a| **a);
    if let Some(a) = &p.alpha
        && !(0.0..=1.0).contains(&alpha)
    {
        return Err(ParamError::at(
            a.span(),
            format!("`alpha` must lie in [0, 1], found {alpha}"),
        ));
    }
    let diffuse = fraction(ctx, &p.diffuse_reflectance, "diffuse_reflectance")?;
    let specular = fraction(ctx, &p.specular_reflectance, "specular_reflectance")?;
    let d_mean = scalar(ctx.textures.mean(diffuse));
    let s_mean = scalar(ctx.textures.mean(specular));
    let specular_weight = if d_mean + s_mean > 0.0 {
        s_mean / (d_mean + s_mean)
    } else {
        0.5
    };
    let ggx = (alpha > 0.0).then(|| Ggx::new(alpha, alpha));
    let mut transmittance = [0.0f32; TABLE];
    let internal = match &ggx {
        None => fresnel::diffuse_reflectance(1.0 / eta),
        Some(g) => {
            for (i, t) in transmittance.iter_mut().enumerate() {
                *t = rough_interface_albedo(g, eta, i as f32 / (TABLE - 1) as f32).0;
            }
            // 2∫ R_inside(μ) μ dμ, midpoint rule.
            let n = 64;
            (0..n)
                .map(|i| {
                    let mu = (i as f32 + 0.5) / n as f32;
                    rough_interface_albedo(g, 1.0 / eta, mu).1 * mu
                })
                .sum::<f32>()
                * 2.0
                / n as f32
        }
    };
    let lobes = if ggx.is_some() {
        Effects::GLOSSY
    } else {
        Effects::DELTA_LOBES
    };
    Ok(Plastic {
        eta,
        ggx,
        diffuse,
        specular,
        nonlinear: p.nonlinear,
        internal,
        transmittance,
        specular_weight,
        effects: lobes | Effects::SMOOTH_LOBES | texture_effects(ctx, &[diffuse, specular]),
    })
}

pub(crate) fn register(registry: &mut Registry) {
    crate::register_shader(
        registry,
        "plastic",
        "Diffuse base under a smooth or rough (GGX) dielectric coat, as Mitsuba 3's plastic/roughplastic.",
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
        check_param_docs::<PlasticParams>(DOCS).unwrap();
    }

    #[test]
    fn rough_coat_tends_to_the_smooth_fresnel() {
        // A nearly smooth coat transmits 1 − F and reflects F.
        let ggx = Ggx::new(1e-3, 1e-3);
        for mu in [0.9f32, 0.5, 0.2] {
            let (t, r) = rough_interface_albedo(&ggx, 1.5, mu);
            let f = fresnel::dielectric(mu, 1.5).r;
            assert!((t - (1.0 - f)).abs() < 2e-3, "{mu}: {t} vs {}", 1.0 - f);
            assert!((r - f).abs() < 2e-3, "{mu}: {r} vs {f}");
        }
    }
}
