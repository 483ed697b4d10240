//! The `thin_dielectric` shader: a thin slab of dielectric (a window pane,
//! a soap film) with its internal reflections summed in closed form; light
//! passes straight through without refraction. Both lobes are delta lobes
//! (Mitsuba 3's `thindielectric`).

use crate::dielectric::{EXT_IOR_DOC, INT_IOR_DOC};
use crate::fresnel;
use crate::gpu;
use crate::inputs::{BK7, Ior, fraction, one, relative_ior, texture_effects};
use crate::lobes::mirror_sample;
use radiant_core::glam::Vec3;
use radiant_core::params::Spanned;
use radiant_core::{
    BsdfEval, BsdfSample, BuildContext, Effects, GpuModule, GpuParams, ParamDoc, ParamError,
    Params, Registry, ShadeContext, Shader, SurfaceBatch, TextureId, TextureInput,
};
use serde::Deserialize;

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct ThinParams {
    int_ior: Option<Spanned<Ior>>,
    ext_ior: Option<Spanned<Ior>>,
    #[serde(default = "one")]
    specular_reflectance: Spanned<TextureInput>,
    #[serde(default = "one")]
    specular_transmittance: Spanned<TextureInput>,
}

const DOCS: &[ParamDoc] = &[
    INT_IOR_DOC,
    EXT_IOR_DOC,
    ParamDoc {
        name: "specular_reflectance",
        ty: "rgb | number | texture name, [0, 1]",
        default: "1",
        doc: "Factor on reflection.",
    },
    ParamDoc {
        name: "specular_transmittance",
        ty: "rgb | number | texture name, [0, 1]",
        default: "1",
        doc: "Factor on transmission.",
    },
];

/// A thin dielectric slab, the same seen from both sides.
struct ThinDielectric {
    eta: f32,
    reflectance: TextureId,
    transmittance: TextureId,
    effects: Effects,
}

/// Total reflectance of a slab whose faces reflect `r`: r + t²r/(1 − r²).
#[inline]
fn slab_reflectance(r: f32) -> f32 {
    if r < 1.0 {
        r + (1.0 - r) * (1.0 - r) * r / (1.0 - r * r)
    } else {
        1.0
    }
}

impl Shader for ThinDielectric {
    fn sample(
        &self,
        ctx: &mut ShadeContext<'_>,
        surface: SurfaceBatch<'_>,
        u: &[Vec3],
        out: &mut [BsdfSample],
    ) {
        let [kr, kt] = ctx.lookup([self.reflectance, self.transmittance], surface.uv);
        for (i, o) in out.iter_mut().enumerate() {
            let wo = surface.wo[i];
            *o = BsdfSample::default();
            if wo.z == 0.0 || !wo.is_finite() {
                continue;
            }
            let r = slab_reflectance(fresnel::dielectric(wo.z.abs(), self.eta).r);
            *o = if u[i].x <= r {
                mirror_sample(wo, kr[i], r)
            } else {
                BsdfSample {
                    wi: -wo,
                    weight: kt[i],
                    pdf: 1.0 - r,
                    delta: true,
                    eta: 1.0,
                }
            };
        }
    }

    fn eval(
        &self,
        _ctx: &mut ShadeContext<'_>,
        _surface: SurfaceBatch<'_>,
        _wi: &[Vec3],
        out: &mut [BsdfEval],
    ) {
        out.fill(BsdfEval::default());
    }

    fn effects(&self) -> Effects {
        self.effects
    }

    fn gpu(&self) -> Option<GpuModule> {
        let params = GpuParams::new()
            .f32(self.eta)
            .texture(self.reflectance)
            .texture(self.transmittance);
        Some(gpu::module(
            "thin_dielectric",
            &[gpu::THIN_DIELECTRIC],
            params,
        ))
    }
}

fn build(params: &Params, ctx: &mut BuildContext<'_>) -> Result<ThinDielectric, ParamError> {
    let p: ThinParams = params.parse()?;
    let eta = relative_ior(&p.int_ior, &p.ext_ior, BK7);
    let reflectance = fraction(ctx, &p.specular_reflectance, "specular_reflectance")?;
    let transmittance = fraction(ctx, &p.specular_transmittance, "specular_transmittance")?;
    Ok(ThinDielectric {
        eta,
        reflectance,
        transmittance,
        effects: Effects::DELTA_LOBES
            | Effects::TRANSMISSION
            | texture_effects(ctx, &[reflectance, transmittance]),
    })
}

pub(crate) fn register(registry: &mut Registry) {
    crate::register_shader(
        registry,
        "thin_dielectric",
        "Thin dielectric slab: internal reflections summed, no refraction (both lobes delta).",
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
        check_param_docs::<ThinParams>(DOCS).unwrap();
    }

    #[test]
    fn slab_sums_the_internal_reflections() {
        // r + t²r Σ (r²)^k, summed numerically.
        let r = 0.2f32;
        let mut sum = r;
        let mut term = (1.0 - r) * (1.0 - r) * r;
        for _ in 0..50 {
            sum += term;
            term *= r * r;
        }
        assert!((slab_reflectance(r) - sum).abs() < 1e-6);
        assert_eq!(slab_reflectance(1.0), 1.0);
    }
}
