//! The `bump` shader: wraps a material and tilts its shading normal by the
//! gradient of a height texture, n′ ∝ (−scale·∂h/∂u, −scale·∂h/∂v, 1),
//! with the gradient taken by central differences of step [`STEP`] in
//! (u, v). See [`crate::perturb`] for the frame and its limits (u and v
//! are taken along the shading frame's tangents at unit scale).

use crate::inputs::scalar;
use crate::perturb::{self, NormalSource, Perturbed};
use radiant_core::glam::{Vec2, Vec3};
use radiant_core::params::Spanned;
use radiant_core::{
    BuildContext, ParamDoc, ParamError, Params, Registry, ShadeContext, SurfaceBatch, TextureId,
    TextureInput,
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

/// Normals from the gradient of a height texture.
struct BumpNormals {
    height: TextureId,
    scale: f32,
}

impl NormalSource for BumpNormals {
    fn normals(&self, ctx: &mut ShadeContext<'_>, surface: SurfaceBatch<'_>) -> Vec<Vec3> {
        let uv = surface.uv;
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

fn build(
    params: &Params,
    ctx: &mut BuildContext<'_>,
) -> Result<Perturbed<BumpNormals>, ParamError> {
    let p: BumpParams = params.parse()?;
    if !p.scale.is_finite() {
        return Err(ParamError {
            message: format!("`scale` must be a finite number, found {}", p.scale),
            location: params.location_of("scale"),
        });
    }
    let height = ctx.texture(&p.height)?;
    let source = BumpNormals {
        height,
        scale: p.scale,
    };
    Perturbed::new(source, height, params, ctx)
}

pub(crate) fn register(registry: &mut Registry) {
    crate::register_shader(
        registry,
        "bump",
        "Wraps a material, tilting its shading normal by the gradient of a height texture.",
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
        check_param_docs::<BumpParams>(DOCS).unwrap();
    }
}
