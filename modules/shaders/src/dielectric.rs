//! The `dielectric` shader: the interface between two dielectrics (glass,
//! water), smooth with exact Fresnel reflection and total internal
//! reflection (two delta lobes), or rough after Walter et al. (2007) with
//! GGX visible-normal sampling. Mitsuba 3's `dielectric` and
//! `roughdielectric` in one module, in radiance transport: refracted
//! radiance is scaled by (η_i/η_t)².

use crate::fresnel;
use crate::gpu;
use crate::inputs::{
    BK7, Ior, ROUGHNESS_DOCS, Roughness, anisotropy, fraction, one, relative_ior, roughness,
    scalar, texture_effects,
};
use crate::lobes::{interface_eval, interface_sample, mirror_sample};
use crate::microfacet::Ggx;
use radiant_core::glam::Vec3;
use radiant_core::params::Spanned;
use radiant_core::{
    BsdfEval, BsdfSample, BuildContext, Effects, GpuModule, GpuParams, ParamDoc, ParamError,
    Params, Registry, ShadeContext, Shader, SurfaceBatch, TextureId, TextureInput,
};
use serde::Deserialize;

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct DielectricParams {
    int_ior: Option<Spanned<Ior>>,
    ext_ior: Option<Spanned<Ior>>,
    #[serde(default = "one")]
    specular_reflectance: Spanned<TextureInput>,
    #[serde(default = "one")]
    specular_transmittance: Spanned<TextureInput>,
    alpha: Option<Spanned<TextureInput>>,
    alpha_u: Option<Spanned<TextureInput>>,
    alpha_v: Option<Spanned<TextureInput>>,
}

pub(crate) const INT_IOR_DOC: ParamDoc = ParamDoc {
    name: "int_ior",
    ty: "number ≥ 1 | name (bk7, water, diamond, acrylic glass, … as Mitsuba 3)",
    default: "1.5046 (bk7)",
    doc: "Index of refraction of the inside (the side the normal points away from).",
};

pub(crate) const EXT_IOR_DOC: ParamDoc = ParamDoc {
    name: "ext_ior",
    ty: "number ≥ 1 | name",
    default: "1.000277 (air)",
    doc: "Index of refraction of the outside.",
};

const DOCS: &[ParamDoc] = &[
    INT_IOR_DOC,
    EXT_IOR_DOC,
    ParamDoc {
        name: "specular_reflectance",
        ty: "rgb | number | texture name, [0, 1]",
        default: "1",
        doc: "Factor on reflection (physically 1).",
    },
    ParamDoc {
        name: "specular_transmittance",
        ty: "rgb | number | texture name, [0, 1]",
        default: "1",
        doc: "Factor on refraction (physically 1).",
    },
    ROUGHNESS_DOCS[0],
    ROUGHNESS_DOCS[1],
    ROUGHNESS_DOCS[2],
];

/// A smooth or rough dielectric interface; the shading normal points out.
struct Dielectric {
    eta: f32,
    reflectance: TextureId,
    transmittance: TextureId,
    rough: Roughness,
    effects: Effects,
}

impl Shader for Dielectric {
    fn sample(
        &self,
        ctx: &mut ShadeContext<'_>,
        surface: SurfaceBatch<'_>,
        u: &[Vec3],
        out: &mut [BsdfSample],
    ) {
        let [kr, kt, au, av] = ctx.lookup(
            [
                self.reflectance,
                self.transmittance,
                self.rough.u,
                self.rough.v,
            ],
            surface.uv,
        );
        for (i, o) in out.iter_mut().enumerate() {
            let wo = surface.wo[i];
            *o = BsdfSample::default();
            if wo.z == 0.0 || !wo.is_finite() {
                continue;
            }
            if self.rough.smooth {
                let f = fresnel::dielectric(wo.z, self.eta);
                *o = if u[i].x <= f.r {
                    mirror_sample(wo, kr[i], f.r)
                } else {
                    BsdfSample {
                        wi: Vec3::new(-f.eta_ti * wo.x, -f.eta_ti * wo.y, f.cos_t),
                        weight: kt[i] * (f.eta_ti * f.eta_ti),
                        pdf: 1.0 - f.r,
                        delta: true,
                        eta: f.eta_it,
                    }
                };
                continue;
            }
            let ggx = Ggx::new(scalar(au[i]), scalar(av[i]));
            if let Some(s) = interface_sample(&ggx, self.eta, wo, u[i]) {
                let tint = if s.transmitted { kt[i] } else { kr[i] };
                *o = BsdfSample {
                    wi: s.wi,
                    weight: tint * s.weight,
                    pdf: s.pdf,
                    delta: false,
                    eta: match (s.transmitted, wo.z > 0.0) {
                        (false, _) => 1.0,
                        (true, true) => self.eta,
                        (true, false) => 1.0 / self.eta,
                    },
                };
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
        if self.rough.smooth {
            out.fill(BsdfEval::default());
            return;
        }
        let [kr, kt, au, av] = ctx.lookup(
            [
                self.reflectance,
                self.transmittance,
                self.rough.u,
                self.rough.v,
            ],
            surface.uv,
        );
        for (i, o) in out.iter_mut().enumerate() {
            let ggx = Ggx::new(scalar(au[i]), scalar(av[i]));
            let (value, pdf, transmitted) = interface_eval(&ggx, self.eta, surface.wo[i], wi[i]);
            let tint = if transmitted { kt[i] } else { kr[i] };
            *o = BsdfEval {
                value: tint * value,
                pdf,
            };
        }
    }

    fn effects(&self) -> Effects {
        self.effects
    }

    fn gpu(&self) -> Option<GpuModule> {
        let params = GpuParams::new()
            .f32(self.eta)
            .texture(self.reflectance)
            .texture(self.transmittance)
            .u32(u32::from(self.rough.smooth))
            .texture(self.rough.u)
            .texture(self.rough.v);
        Some(gpu::module("dielectric", &[gpu::DIELECTRIC], params))
    }
}

fn build(params: &Params, ctx: &mut BuildContext<'_>) -> Result<Dielectric, ParamError> {
    let p: DielectricParams = params.parse()?;
    let eta = relative_ior(&p.int_ior, &p.ext_ior, BK7);
    let reflectance = fraction(ctx, &p.specular_reflectance, "specular_reflectance")?;
    let transmittance = fraction(ctx, &p.specular_transmittance, "specular_transmittance")?;
    let mut rough = roughness(&p.alpha, &p.alpha_u, &p.alpha_v, ctx)?;
    // An index-matched interface deflects no ray whatever its microfacets
    // (and the generalised half vector of Walter et al. vanishes): smooth.
    rough.smooth |= eta == 1.0;
    let lobes = if rough.smooth {
        Effects::DELTA_LOBES
    } else {
        Effects::SMOOTH_LOBES | Effects::GLOSSY
    };
    Ok(Dielectric {
        eta,
        reflectance,
        transmittance,
        rough,
        effects: lobes
            | Effects::TRANSMISSION
            | texture_effects(ctx, &[reflectance, transmittance, rough.u, rough.v])
            | anisotropy(ctx, rough.u, rough.v),
    })
}

pub(crate) fn register(registry: &mut Registry) {
    crate::register_shader(
        registry,
        "dielectric",
        "Glass-like interface: smooth (exact Fresnel, total internal reflection) or rough (Walter et al. 2007, GGX visible normals).",
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
        check_param_docs::<DielectricParams>(DOCS).unwrap();
    }
}
