//! The `bump` shader: wraps a material and tilts its shading normal by the
//! gradient of a height texture, n′ ∝ (−scale·∂h/∂u, −scale·∂h/∂v, 1),
//! with the gradient taken by central differences of step [`STEP`] in
//! (u, v). See [`crate::perturb`] for the frame and its limits (u and v
//! are taken along the shading frame's tangents at unit scale).

use crate::inputs::scalar;
use crate::perturb;
use radiant_core::glam::{Vec2, Vec3};
use radiant_core::params::Spanned;
use radiant_core::{
    BsdfEval, BsdfSample, BuildContext, Effects, ModuleInfo, ParamDoc, ParamError, Params,
    Registry, ShadeContext, Shader, SurfaceBatch, TextureId, TextureInput,
};
use serde::Deserialize;
use serde::de::IgnoredAny;

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct BumpParams {
    height: Spanned<TextureInput>,
    #[serde(default = "one")]
    scale: f32,
    // Read through `BuildContext::material`; listed for key checking.
    #[serde(rename = "material")]
    _material: IgnoredAny,
}

fn one() -> f32 {
    1.0
}

const DOCS: &[ParamDoc] = &[
    ParamDoc {
        name: "height",
        ty: "number | texture name (mean of the channels)",
        default: "required",
        doc: "Height field over (u, v).",
    },
    ParamDoc {
        name: "scale",
        ty: "number (height units per uv unit)",
        default: "1",
        doc: "Factor on the height gradient; negative values invert the relief.",
    },
    ParamDoc {
        name: "material",
        ty: "material (a name under `materials:` or inline `{type: …}`)",
        default: "required",
        doc: "The material whose shading normal is tilted.",
    },
];

/// Finite-difference step in (u, v).
pub const STEP: f32 = 1.0 / 1024.0;

struct Bump {
    height: TextureId,
    scale: f32,
    nested: Box<dyn Shader>,
    effects: Effects,
}

impl Bump {
    fn normals(&self, ctx: &mut ShadeContext<'_>, uv: &[Vec2]) -> Vec<Vec3> {
        let n = uv.len();
        let mut shifted = ctx.take::<Vec2>(4 * n);
        for (i, uv) in uv.iter().enumerate() {
            shifted[i] = *uv + Vec2::new(STEP, 0.0);
            shifted[n + i] = *uv - Vec2::new(STEP, 0.0);
            shifted[2 * n + i] = *uv + Vec2::new(0.0, STEP);
            shifted[3 * n + i] = *uv - Vec2::new(0.0, STEP);
        }
        let mut normals = ctx.take::<Vec3>(n);
        let [h] = ctx.lookup([self.height], &shifted);
        let k = self.scale / (2.0 * STEP);
        for (i, normal) in normals.iter_mut().enumerate() {
            let du = (scalar(h[i]) - scalar(h[n + i])) * k;
            let dv = (scalar(h[2 * n + i]) - scalar(h[3 * n + i])) * k;
            *normal = perturb::sanitise(Vec3::new(-du, -dv, 1.0));
        }
        ctx.recycle(shifted);
        normals
    }
}

impl Shader for Bump {
    fn sample(
        &self,
        ctx: &mut ShadeContext<'_>,
        surface: SurfaceBatch<'_>,
        u: &[Vec3],
        out: &mut [BsdfSample],
    ) {
        let normals = self.normals(ctx, surface.uv);
        perturb::sample(&*self.nested, ctx, surface, &normals, u, out);
        ctx.recycle(normals);
    }

    fn eval(
        &self,
        ctx: &mut ShadeContext<'_>,
        surface: SurfaceBatch<'_>,
        wi: &[Vec3],
        out: &mut [BsdfEval],
    ) {
        let normals = self.normals(ctx, surface.uv);
        perturb::eval(&*self.nested, ctx, surface, &normals, wi, out);
        ctx.recycle(normals);
    }

    fn effects(&self) -> Effects {
        self.effects
    }
}

fn build(params: &Params, ctx: &mut BuildContext<'_>) -> Result<Bump, ParamError> {
    let p: BumpParams = params.parse()?;
    if !p.scale.is_finite() {
        return Err(ParamError {
            message: format!("`scale` must be a finite number, found {}", p.scale),
            location: params.location_of("scale"),
        });
    }
    let height = ctx.texture(&p.height)?;
    let nested = ctx.material(params, "material")?;
    let effects = nested.effects() | ctx.textures.effects(height);
    Ok(Bump {
        height,
        scale: p.scale,
        nested,
        effects,
    })
}

pub(crate) fn register(registry: &mut Registry) {
    registry.register::<dyn Shader>(
        ModuleInfo {
            type_name: "bump",
            summary: "Wraps a material, tilting its shading normal by the gradient of a height texture.",
            params: DOCS,
        },
        |params: &Params, ctx| Ok(Box::new(build(params, ctx)?) as Box<dyn Shader>),
    );
}

#[cfg(test)]
mod tests {
    use super::*;
    use radiant_core::params::check_param_docs;

    #[test]
    fn documented_parameters_match() {
        check_param_docs::<BumpParams>(DOCS).unwrap();
    }
}
