//! The `blend` shader: a mix of two materials by a weight texture,
//! (1 − w)·A + w·B.
//!
//! Sampling chooses A or B with probabilities 1 − w and w and samples it
//! (each on its own sub-batch); for a non-delta sample the value and
//! density are then those of the whole mix, so that multiple importance
//! sampling sees the same density as [`Shader::eval`]. A delta sample
//! keeps its component's weight, which is unbiased for the mix (a delta
//! lobe of one component is not evaluated through the other).
//!
//! On the GPU a blend calls its parts' functions directly: its WGSL is
//! made from `blend.wgsl` for the pair of part types, and its parameters
//! hold the parts'. WGSL has no recursion, so the kernel's generic
//! `bsdf_sample` dispatcher (which dispatches to blends too) cannot be
//! used; a part's code must be in libraries (as every built-in type's is,
//! see [`crate::gpu`]) or be a composite's (a blend, a normal or bump map),
//! whose code is included renamed.

use crate::gpu;
use crate::inputs::{fraction, half, scalar, texture_effects};
use radiant_core::glam::{Vec2, Vec3};
use radiant_core::params::Spanned;
use radiant_core::{
    BsdfEval, BsdfSample, BuildContext, Effects, GpuModule, GpuParams, ParamDoc, ParamError,
    Params, Registry, ShadeContext, Shader, SurfaceBatch, TextureId, TextureInput,
};
use serde::Deserialize;
use serde::de::IgnoredAny;

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct BlendParams {
    #[serde(default = "half")]
    weight: Spanned<TextureInput>,
    // Read through `BuildContext::material_at`; listed for key checking.
    #[serde(rename = "materials")]
    _materials: IgnoredAny,
}

const DOCS: &[ParamDoc] = &[
    ParamDoc {
        name: "weight",
        ty: "number | texture name, [0, 1]",
        default: "0.5",
        doc: "Fraction of the second material (0: only the first, 1: only the second).",
    },
    ParamDoc {
        name: "materials",
        ty: "list of two materials (names under `materials:` or inline `{type: …}`)",
        default: "required",
        doc: "The two materials to mix.",
    },
];

/// A texture-weighted mix of two shaders.
struct Blend {
    weight: TextureId,
    parts: [Box<dyn Shader>; 2],
    effects: Effects,
}

impl Blend {
    /// Gathers the points of `idx` into a sub-batch, samples `part` on it
    /// and scatters the samples back (scaling delta densities by the
    /// choice probability).
    #[allow(clippy::too_many_arguments)]
    fn sample_part(
        &self,
        part: usize,
        ctx: &mut ShadeContext<'_>,
        surface: SurfaceBatch<'_>,
        idx: &[u32],
        u: &[Vec3],
        prob: &[f32],
        out: &mut [BsdfSample],
    ) {
        if idx.is_empty() {
            return;
        }
        let mut wo = ctx.take::<Vec3>(idx.len());
        let mut uv = ctx.take::<Vec2>(idx.len());
        let mut uu = ctx.take::<Vec3>(idx.len());
        let mut res = ctx.take::<BsdfSample>(idx.len());
        let derivatives = !surface.dp_du.is_empty();
        let m = if derivatives { idx.len() } else { 0 };
        let (mut du, mut dv) = (ctx.take::<Vec3>(m), ctx.take::<Vec3>(m));
        for (k, &i) in idx.iter().enumerate() {
            let i = i as usize;
            wo[k] = surface.wo[i];
            uv[k] = surface.uv[i];
            uu[k] = u[i];
            if derivatives {
                du[k] = surface.dp_du[i];
                dv[k] = surface.dp_dv[i];
            }
        }
        let part_surface = SurfaceBatch {
            wo: &wo,
            uv: &uv,
            dp_du: &du,
            dp_dv: &dv,
        };
        self.parts[part].sample(ctx, part_surface, &uu, &mut res);
        for (k, &i) in idx.iter().enumerate() {
            let mut s = res[k];
            s.pdf *= prob[i as usize];
            out[i as usize] = s;
        }
        ctx.recycle(wo);
        ctx.recycle(uv);
        ctx.recycle(uu);
        ctx.recycle(res);
        ctx.recycle(du);
        ctx.recycle(dv);
    }
}

impl Shader for Blend {
    fn sample(
        &self,
        ctx: &mut ShadeContext<'_>,
        surface: SurfaceBatch<'_>,
        u: &[Vec3],
        out: &mut [BsdfSample],
    ) {
        let n = surface.len();
        let mut w = ctx.take::<f32>(n);
        {
            let [t] = ctx.lookup([self.weight], surface.uv);
            for (w, t) in w.iter_mut().zip(t) {
                *w = scalar(*t).clamp(0.0, 1.0);
            }
        }
        // Choose a part per point, reusing u.x for the part's own choice.
        let mut idx = [ctx.take::<u32>(0), ctx.take::<u32>(0)];
        let mut uu = ctx.take::<Vec3>(n);
        let mut prob = ctx.take::<f32>(n);
        for i in 0..n {
            let (x, wi) = (u[i].x, w[i]);
            let (part, p, rescaled) = if x < wi {
                (1, wi, x / wi)
            } else {
                (0, 1.0 - wi, (x - wi) / (1.0 - wi))
            };
            idx[part].push(i as u32);
            prob[i] = p;
            uu[i] = Vec3::new(rescaled.clamp(0.0, 1.0), u[i].y, u[i].z);
        }
        for (part, ids) in idx.iter().enumerate() {
            self.sample_part(part, ctx, surface, ids, &uu, &prob, out);
        }
        // The mixture's value and density at the non-delta samples.
        let mut wi = ctx.take::<Vec3>(n);
        for (d, s) in wi.iter_mut().zip(out.iter()) {
            *d = s.wi;
        }
        let mut ea = ctx.take::<BsdfEval>(n);
        let mut eb = ctx.take::<BsdfEval>(n);
        self.parts[0].eval(ctx, surface, &wi, &mut ea);
        self.parts[1].eval(ctx, surface, &wi, &mut eb);
        for i in 0..n {
            let s = &mut out[i];
            if s.delta || s.pdf <= 0.0 {
                continue;
            }
            let value = ea[i].value * (1.0 - w[i]) + eb[i].value * w[i];
            let pdf = ea[i].pdf * (1.0 - w[i]) + eb[i].pdf * w[i];
            *s = if pdf > 0.0 {
                BsdfSample {
                    wi: s.wi,
                    weight: value / pdf,
                    pdf,
                    delta: false,
                    eta: s.eta,
                }
            } else {
                BsdfSample::default()
            };
        }
        for v in [wi, uu] {
            ctx.recycle(v);
        }
        for v in [ea, eb] {
            ctx.recycle(v);
        }
        for v in idx {
            ctx.recycle(v);
        }
        ctx.recycle(w);
        ctx.recycle(prob);
    }

    fn eval(
        &self,
        ctx: &mut ShadeContext<'_>,
        surface: SurfaceBatch<'_>,
        wi: &[Vec3],
        out: &mut [BsdfEval],
    ) {
        let n = surface.len();
        let mut w = ctx.take::<f32>(n);
        {
            let [t] = ctx.lookup([self.weight], surface.uv);
            for (w, t) in w.iter_mut().zip(t) {
                *w = scalar(*t).clamp(0.0, 1.0);
            }
        }
        let mut eb = ctx.take::<BsdfEval>(n);
        self.parts[0].eval(ctx, surface, wi, out);
        self.parts[1].eval(ctx, surface, wi, &mut eb);
        for i in 0..n {
            out[i] = BsdfEval {
                value: out[i].value * (1.0 - w[i]) + eb[i].value * w[i],
                pdf: out[i].pdf * (1.0 - w[i]) + eb[i].pdf * w[i],
            };
        }
        ctx.recycle(eb);
        ctx.recycle(w);
    }

    fn effects(&self) -> Effects {
        self.effects
    }

    /// Where both parts have a GPU side whose code is in libraries or is
    /// a composite's (see the module docs).
    fn gpu(&self) -> Option<GpuModule> {
        let [a, b] = [self.parts[0].gpu()?, self.parts[1].gpu()?];
        // Unique per pair of part types (the length makes it decodable).
        let ident = format!(
            "{}{}_{}_{}",
            gpu::BLEND_PREFIX,
            a.ident.len(),
            a.ident,
            b.ident
        );
        let mut code = gpu::Composite::new(ident, &[gpu::COMMON]);
        let name_a = code.part(&a, "__a")?;
        let name_b = code.part(&b, "__b")?;
        code.template(BLEND_WGSL, &[("$A", &name_a), ("$B", &name_b)]);
        let params = GpuParams::new()
            .texture(self.weight)
            .u32(2 + a.params.len() as u32)
            .append(&a.params)
            .append(&b.params);
        Some(code.finish(params))
    }
}

/// The template of a blend's WGSL (its header comment, up to the first
/// blank line, is left out of the code made from it).
const BLEND_WGSL: &str = include_str!("blend.wgsl");

fn build(params: &Params, ctx: &mut BuildContext<'_>) -> Result<Blend, ParamError> {
    let p: BlendParams = params.parse()?;
    let weight = fraction(ctx, &p.weight, "weight")?;
    let list = params
        .node()
        .as_mapping()
        .and_then(|m| m.get_node("materials"));
    let items = list.and_then(|n| n.as_sequence()).filter(|s| s.len() == 2);
    let Some(items) = items else {
        return Err(ParamError {
            message: "`materials` must be a list of exactly two materials (names or inline `{type: …}` mappings)".into(),
            location: params.location_of("materials"),
        });
    };
    let a = ctx.material_at(&items[0])?;
    let b = ctx.material_at(&items[1])?;
    let effects = a.effects() | b.effects() | texture_effects(ctx, &[weight]);
    Ok(Blend {
        weight,
        parts: [a, b],
        effects,
    })
}

pub(crate) fn register(registry: &mut Registry) {
    crate::register_shader(
        registry,
        "blend",
        "Mix of two materials by a weight texture.",
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
        check_param_docs::<BlendParams>(DOCS).unwrap();
    }
}
