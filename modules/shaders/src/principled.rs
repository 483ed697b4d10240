//! The `principled` shader: the metalness workflow of seed 000 — base
//! colour, metalness, roughness, specular and transmission, each a texture
//! or a constant — as a weighted sum of three lobes:
//!
//! * a GGX reflection lobe with Schlick's Fresnel, F0 = lerp(0.08 ·
//!   specular, base colour, metalness), weight 1 − (1 − metalness) ·
//!   transmission;
//! * Ashikhmin and Shirley's energy-coupled diffuse term with the base
//!   colour and R0 = 0.08 · specular, weight (1 − metalness)(1 −
//!   transmission);
//! * a rough dielectric interface (Walter et al. 2007) whose index follows
//!   from the specular reflectance (0.5 → η = 1.5) and whose refraction is
//!   tinted by the base colour, weight (1 − metalness) · transmission.
//!
//! GGX α = roughness² (clamped to 10⁻⁴). The reflection and diffuse lobes
//! are one-sided; seen from inside (transmissive objects) only the
//! interface lobe acts. A lobe is chosen in proportion to its weight times
//! an albedo estimate, and the returned density is that of the whole mix.

use crate::fresnel::schlick;
use crate::gpu;
use crate::inputs::{fraction, half, scalar, texture_effects, zero};
use crate::lobes::{glossy_eval, glossy_sample, interface_eval, interface_sample};
use crate::microfacet::Ggx;
use radiant_core::glam::{Vec2, Vec3};
use radiant_core::params::Spanned;
use radiant_core::warp::{cosine_hemisphere_pdf, square_to_cosine_hemisphere};
use radiant_core::{
    BsdfEval, BsdfSample, BuildContext, Effects, GpuModule, GpuParams, ParamDoc, ParamError,
    Params, Registry, Rgb, ShadeContext, Shader, SurfaceBatch, TextureId, TextureInput, luminance,
};
use serde::Deserialize;
use std::f32::consts::PI;

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct PrincipledParams {
    #[serde(default = "half")]
    base_color: Spanned<TextureInput>,
    #[serde(default = "zero")]
    metallic: Spanned<TextureInput>,
    #[serde(default = "half")]
    roughness: Spanned<TextureInput>,
    #[serde(default = "half")]
    specular: Spanned<TextureInput>,
    #[serde(default = "zero")]
    transmission: Spanned<TextureInput>,
}

const DOCS: &[ParamDoc] = &[
    ParamDoc {
        name: "base_color",
        ty: "rgb | number | texture name, [0, 1]",
        default: "0.5",
        doc: "Albedo of dielectrics, F0 of metals, tint of transmission.",
    },
    ParamDoc {
        name: "metallic",
        ty: "number | texture name, [0, 1]",
        default: "0",
        doc: "Metalness: 0 dielectric, 1 metal; blends linearly.",
    },
    ParamDoc {
        name: "roughness",
        ty: "number | texture name, [0, 1] (GGX α = roughness²)",
        default: "0.5",
        doc: "Perceptual roughness of the reflection and transmission lobes.",
    },
    ParamDoc {
        name: "specular",
        ty: "number | texture name, [0, 1] (F0 = 0.08 · specular)",
        default: "0.5",
        doc: "Dielectric reflectance at normal incidence (0.5 → F0 = 0.04, η = 1.5).",
    },
    ParamDoc {
        name: "transmission",
        ty: "number | texture name, [0, 1]",
        default: "0",
        doc: "Fraction of the dielectric part that transmits (rough glass) instead of scattering diffusely.",
    },
];

/// Smallest index of refraction the transmission lobe uses (an index of 1
/// would make refraction a delta lobe).
const MIN_ETA: f32 = 1.01;

struct Principled {
    base: TextureId,
    metallic: TextureId,
    roughness: TextureId,
    specular: TextureId,
    transmission: TextureId,
    effects: Effects,
}

/// The lobes at one surface point.
struct Lobes {
    base: Rgb,
    ggx: Ggx,
    f0: Rgb,
    r0: f32,
    eta: f32,
    weights: [f32; 3],
}

impl Lobes {
    fn new(base: Rgb, metallic: f32, roughness: f32, specular: f32, transmission: f32) -> Self {
        let base = base.clamp(Rgb::ZERO, Rgb::ONE);
        let (m, t) = (metallic.clamp(0.0, 1.0), transmission.clamp(0.0, 1.0));
        let r0 = 0.08 * specular.clamp(0.0, 1.0);
        let a = roughness.clamp(0.0, 1.0).powi(2);
        let s = r0.sqrt();
        Self {
            base,
            ggx: Ggx::new(a, a),
            f0: Rgb::splat(r0).lerp(base, m),
            r0,
            eta: ((1.0 + s) / (1.0 - s)).max(MIN_ETA),
            weights: [1.0 - (1.0 - m) * t, (1.0 - m) * (1.0 - t), (1.0 - m) * t],
        }
    }

    /// Probabilities of sampling the reflection, diffuse and interface lobes.
    fn probabilities(&self, wo: Vec3) -> [f32; 3] {
        let [ws, wd, wt] = self.weights;
        let p = if wo.z > 0.0 {
            [
                ws * luminance(schlick(wo.z, self.f0)),
                wd * luminance(self.base) * (1.0 - self.r0),
                wt,
            ]
        } else {
            [0.0, 0.0, wt]
        };
        let sum = p[0] + p[1] + p[2];
        if sum > 0.0 {
            p.map(|x| x / sum)
        } else if wo.z > 0.0 {
            [1.0, 0.0, 0.0]
        } else {
            [0.0; 3]
        }
    }

    /// (f·|cos θi|, pdf) of the whole mix.
    fn eval(&self, wo: Vec3, wi: Vec3) -> (Rgb, f32) {
        let p = self.probabilities(wo);
        let [ws, wd, wt] = self.weights;
        let (mut value, mut pdf) = (Rgb::ZERO, 0.0);
        if wo.z > 0.0 && wi.z > 0.0 {
            if let Some((m, v, q)) = glossy_eval(&self.ggx, wo, wi) {
                value += schlick(wo.dot(m), self.f0) * (ws * v);
                pdf += p[0] * q;
            }
            let fade = |c: f32| {
                let x = 1.0 - 0.5 * c;
                1.0 - x * x * x * x * x
            };
            value += self.base
                * (wd * (1.0 - self.r0) * 28.0 / (23.0 * PI) * fade(wi.z) * fade(wo.z) * wi.z);
            pdf += p[1] * cosine_hemisphere_pdf(wi);
        }
        if wt > 0.0 {
            let (v, q, transmitted) = interface_eval(&self.ggx, self.eta, wo, wi);
            let tint = if transmitted { self.base } else { Rgb::ONE };
            value += tint * (wt * v);
            pdf += p[2] * q;
        }
        if value.is_finite() && pdf.is_finite() {
            (value, pdf)
        } else {
            (Rgb::ZERO, 0.0)
        }
    }

    fn sample(&self, wo: Vec3, u: Vec3) -> BsdfSample {
        let p = self.probabilities(wo);
        let u2 = Vec2::new(u.y, u.z);
        let wi = if u.x < p[0] {
            glossy_sample(&self.ggx, wo, u2).map(|s| s.wi)
        } else if u.x < p[0] + p[1] {
            Some(square_to_cosine_hemisphere(u2))
        } else if p[2] > 0.0 {
            let x = ((u.x - p[0] - p[1]) / p[2]).clamp(0.0, 1.0);
            interface_sample(&self.ggx, self.eta, wo, Vec3::new(x, u.y, u.z)).map(|s| s.wi)
        } else {
            None
        };
        let Some(wi) = wi else {
            return BsdfSample::default();
        };
        let (value, pdf) = self.eval(wo, wi);
        if pdf > 0.0 && wi.z != 0.0 {
            BsdfSample {
                wi,
                weight: value / pdf,
                pdf,
                delta: false,
                eta: match (wi.z * wo.z < 0.0, wo.z > 0.0) {
                    (false, _) => 1.0,
                    (true, true) => self.eta,
                    (true, false) => 1.0 / self.eta,
                },
            }
        } else {
            BsdfSample::default()
        }
    }
}

impl Principled {
    /// Calls `f` with the lobes of every point of the batch.
    fn for_each(&self, ctx: &mut ShadeContext<'_>, uv: &[Vec2], mut f: impl FnMut(usize, &Lobes)) {
        let mut base = ctx.take::<Vec3>(uv.len());
        let mut scalars = ctx.take::<Vec3>(uv.len());
        {
            let [b, m, r, s] = ctx.lookup(
                [self.base, self.metallic, self.roughness, self.specular],
                uv,
            );
            for i in 0..uv.len() {
                base[i] = b[i];
                scalars[i] = Vec3::new(scalar(m[i]), scalar(r[i]), scalar(s[i]));
            }
        }
        let [t] = ctx.lookup([self.transmission], uv);
        for i in 0..uv.len() {
            let s = scalars[i];
            f(i, &Lobes::new(base[i], s.x, s.y, s.z, scalar(t[i])));
        }
        ctx.recycle(base);
        ctx.recycle(scalars);
    }
}

impl Shader for Principled {
    fn sample(
        &self,
        ctx: &mut ShadeContext<'_>,
        surface: SurfaceBatch<'_>,
        u: &[Vec3],
        out: &mut [BsdfSample],
    ) {
        self.for_each(ctx, surface.uv, |i, lobes| {
            out[i] = lobes.sample(surface.wo[i], u[i]);
        });
    }

    fn eval(
        &self,
        ctx: &mut ShadeContext<'_>,
        surface: SurfaceBatch<'_>,
        wi: &[Vec3],
        out: &mut [BsdfEval],
    ) {
        self.for_each(ctx, surface.uv, |i, lobes| {
            let (value, pdf) = lobes.eval(surface.wo[i], wi[i]);
            out[i] = BsdfEval { value, pdf };
        });
    }

    fn effects(&self) -> Effects {
        self.effects
    }

    fn gpu(&self) -> Option<GpuModule> {
        let params = GpuParams::new()
            .texture(self.base)
            .texture(self.metallic)
            .texture(self.roughness)
            .texture(self.specular)
            .texture(self.transmission);
        Some(gpu::module("principled", &[gpu::PRINCIPLED], params))
    }
}

fn build(params: &Params, ctx: &mut BuildContext<'_>) -> Result<Principled, ParamError> {
    let p: PrincipledParams = params.parse()?;
    let base = fraction(ctx, &p.base_color, "base_color")?;
    let metallic = fraction(ctx, &p.metallic, "metallic")?;
    let roughness = fraction(ctx, &p.roughness, "roughness")?;
    let specular = fraction(ctx, &p.specular, "specular")?;
    let transmission = fraction(ctx, &p.transmission, "transmission")?;
    let transmits = !matches!(&*p.transmission, TextureInput::Value(v) if *v == Rgb::ZERO);
    let mut effects = Effects::SMOOTH_LOBES
        | Effects::GLOSSY
        | texture_effects(ctx, &[base, metallic, roughness, specular, transmission]);
    if transmits {
        effects |= Effects::TRANSMISSION;
    }
    Ok(Principled {
        base,
        metallic,
        roughness,
        specular,
        transmission,
        effects,
    })
}

pub(crate) fn register(registry: &mut Registry) {
    crate::register_shader(
        registry,
        "principled",
        "Metalness workflow: GGX reflection, coupled diffuse and rough transmission mixed by metalness and transmission.",
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
        check_param_docs::<PrincipledParams>(DOCS).unwrap();
    }

    #[test]
    fn specular_half_is_glass_of_index_one_and_a_half() {
        let l = Lobes::new(Rgb::ONE, 0.0, 0.5, 0.5, 1.0);
        assert!((l.eta - 1.5).abs() < 1e-5);
        assert!((l.f0.x - 0.04).abs() < 1e-6);
        assert_eq!(l.weights, [0.0, 0.0, 1.0]);
    }
}
