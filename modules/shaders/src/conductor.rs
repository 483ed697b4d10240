//! The `conductor` shader: a metal, as a smooth mirror (a delta lobe) or
//! rough after the GGX microfacet model with visible-normal sampling
//! (Heitz 2018), isotropic or anisotropic; reflectance from the exact
//! Fresnel equations of a complex index (named metal presets) or an RGB
//! colour. Mitsuba 3's `conductor` and `roughconductor` in one module.

use crate::fresnel;
use crate::gpu;
use crate::inputs::{
    ROUGHNESS_DOCS, Roughness, anisotropy, fraction, one, roughness, scalar, texture_effects,
};
use crate::lobes::{mirror_sample, reflection_sample};
use crate::metals;
use crate::microfacet::{Ggx, reflect};
use radiant_core::glam::{Vec2, Vec3};
use radiant_core::params::Spanned;
use radiant_core::{
    BsdfEval, BsdfSample, Color, Effects, GpuModule, GpuParams, ParamDoc, ParamError, Params,
    Registry, Rgb, ShadeContext, Shader, SurfaceBatch, TextureId, TextureInput,
};
use serde::Deserialize;

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct ConductorParams {
    material: Option<Spanned<String>>,
    eta: Option<Spanned<Color>>,
    k: Option<Spanned<Color>>,
    #[serde(default = "one")]
    specular_reflectance: Spanned<TextureInput>,
    alpha: Option<Spanned<TextureInput>>,
    alpha_u: Option<Spanned<TextureInput>>,
    alpha_v: Option<Spanned<TextureInput>>,
}

const DOCS: &[ParamDoc] = &[
    ParamDoc {
        name: "material",
        ty: "name: a-C, Ag, Al, Au, Be, Cr, Cu, Hg, Ir, K, Li, Mo, Na, Nb, Ni, Rh, Ta, TiN, V, W or none",
        default: "none",
        doc: "Complex index of refraction from a metal's measured data (Mitsuba 3's RGB values); `none` is a perfect mirror whose colour is `specular_reflectance`.",
    },
    ParamDoc {
        name: "eta",
        ty: "rgb | number",
        default: "from `material`",
        doc: "Real part of the index of refraction (with `k`, instead of `material`).",
    },
    ParamDoc {
        name: "k",
        ty: "rgb | number",
        default: "from `material`",
        doc: "Imaginary part (absorption coefficient) of the index of refraction.",
    },
    ParamDoc {
        name: "specular_reflectance",
        ty: "rgb | number | texture name, [0, 1]",
        default: "1",
        doc: "Factor on the Fresnel reflectance (the colour of a `none` mirror).",
    },
    ROUGHNESS_DOCS[0],
    ROUGHNESS_DOCS[1],
    ROUGHNESS_DOCS[2],
];

/// Where the Fresnel reflectance comes from.
#[derive(Debug, Clone, Copy, PartialEq)]
enum Reflectance {
    /// A perfect mirror (reflectance 1 at every angle).
    Mirror,
    /// The exact Fresnel equations for the complex index η + ik.
    Complex { eta: Rgb, k: Rgb },
}

impl Reflectance {
    #[inline]
    fn at(self, cos: f32) -> Rgb {
        match self {
            Reflectance::Mirror => Rgb::ONE,
            Reflectance::Complex { eta, k } => fresnel::conductor(cos, eta, k),
        }
    }
}

/// A smooth or rough metal (one-sided: black from below).
struct Conductor {
    fresnel: Reflectance,
    specular: TextureId,
    rough: Roughness,
    effects: Effects,
}

impl Shader for Conductor {
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
        let [spec, au, av] = ctx.lookup([self.specular, self.rough.u, self.rough.v], surface.uv);
        for (i, o) in out.iter_mut().enumerate() {
            let wo = surface.wo[i];
            *o = BsdfSample::default();
            if wo.z <= 0.0 {
                continue;
            }
            if self.rough.smooth {
                *o = mirror_sample(wo, self.fresnel.at(wo.z) * spec[i], 1.0);
                continue;
            }
            let ggx = Ggx::new(scalar(au[i]), scalar(av[i]));
            let m = ggx.sample_visible(wo, Vec2::new(u[i].y, u[i].z));
            let wi = reflect(wo, m);
            let pdf = ggx.pdf_visible(wo, m) / (4.0 * wo.dot(m));
            if wi.z <= 0.0 || !(pdf > 0.0 && pdf.is_finite()) {
                continue;
            }
            *o = reflection_sample(
                wi,
                self.fresnel.at(wo.dot(m)) * spec[i] * ggx.g1(wi, m),
                pdf,
            );
        }
    }

    fn eval(
        &self,
        ctx: &mut ShadeContext<'_>,
        surface: SurfaceBatch<'_>,
        wi: &[Vec3],
        out: &mut [BsdfEval],
    ) {
        if self.rough.smooth {
            out.fill(BsdfEval::default());
            return;
        }
        let [spec, au, av] = ctx.lookup([self.specular, self.rough.u, self.rough.v], surface.uv);
        for (i, o) in out.iter_mut().enumerate() {
            let (wo, wi) = (surface.wo[i], wi[i]);
            *o = BsdfEval::default();
            if wo.z <= 0.0 || wi.z <= 0.0 {
                continue;
            }
            let Some(m) = (wo + wi).try_normalize() else {
                continue;
            };
            let ggx = Ggx::new(scalar(au[i]), scalar(av[i]));
            let d = ggx.d(m);
            let value =
                self.fresnel.at(wo.dot(m)) * spec[i] * (d * ggx.g(wo, wi, m) / (4.0 * wo.z));
            let pdf = ggx.g1(wo, m) * d / (4.0 * wo.z);
            if value.is_finite() && pdf.is_finite() {
                *o = BsdfEval { value, pdf };
            }
        }
    }

    fn effects(&self) -> Effects {
        self.effects
    }

    fn gpu(&self) -> Option<GpuModule> {
        let (kind, eta, k) = match self.fresnel {
            Reflectance::Mirror => (0, Rgb::ZERO, Rgb::ZERO),
            Reflectance::Complex { eta, k } => (1, eta, k),
        };
        let params = GpuParams::new()
            .u32(kind)
            .rgb(eta)
            .rgb(k)
            .texture(self.specular)
            .u32(u32::from(self.rough.smooth))
            .texture(self.rough.u)
            .texture(self.rough.v);
        Some(gpu::module("conductor", &[gpu::CONDUCTOR], params))
    }
}

fn build(
    params: &Params,
    ctx: &mut radiant_core::BuildContext<'_>,
) -> Result<Conductor, ParamError> {
    let p: ConductorParams = params.parse()?;
    let fresnel = match (&p.material, &p.eta, &p.k) {
        (Some(m), None, None) if m.eq_ignore_ascii_case("none") => Reflectance::Mirror,
        (Some(m), None, None) => {
            let (eta, k) = metals::lookup(m).ok_or_else(|| {
                ParamError::at(
                    m.span(),
                    format!(
                        "unknown metal `{}`; expected one of: {}, none",
                        &**m,
                        metals::names().join(", ")
                    ),
                )
            })?;
            Reflectance::Complex { eta, k }
        }
        (None, Some(eta), Some(k)) => {
            if !(eta.0.is_finite() && eta.0.min_element() > 0.0) {
                return Err(ParamError::at(
                    eta.span(),
                    "`eta` must be positive and finite",
                ));
            }
            if !(k.0.is_finite() && k.0.min_element() >= 0.0) {
                return Err(ParamError::at(
                    k.span(),
                    "`k` must be non-negative and finite",
                ));
            }
            Reflectance::Complex { eta: eta.0, k: k.0 }
        }
        (None, None, None) => Reflectance::Mirror,
        (Some(m), _, _) => {
            return Err(ParamError::at(
                m.span(),
                "give either `material` or both `eta` and `k`, not both",
            ));
        }
        (None, Some(x), None) | (None, None, Some(x)) => {
            return Err(ParamError::at(
                x.span(),
                "a complex index of refraction needs both `eta` and `k`",
            ));
        }
    };
    let specular = fraction(ctx, &p.specular_reflectance, "specular_reflectance")?;
    let rough = roughness(&p.alpha, &p.alpha_u, &p.alpha_v, ctx)?;
    let lobes = if rough.smooth {
        Effects::DELTA_LOBES
    } else {
        Effects::SMOOTH_LOBES | Effects::GLOSSY
    };
    Ok(Conductor {
        fresnel,
        specular,
        rough,
        effects: lobes
            | texture_effects(ctx, &[specular, rough.u, rough.v])
            | anisotropy(ctx, rough.u, rough.v),
    })
}

pub(crate) fn register(registry: &mut Registry) {
    crate::register_shader(
        registry,
        "conductor",
        "Metal: smooth mirror or rough GGX (visible-normal sampling), isotropic or anisotropic, complex-IOR presets.",
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
        check_param_docs::<ConductorParams>(DOCS).unwrap();
    }
}
