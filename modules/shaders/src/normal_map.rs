//! The `normal_map` shader: wraps a material and replaces its shading
//! normal by one read from a texture (RGB in [0, 1] encoding a
//! tangent-space normal as 2·c − 1, +z out of the surface). See
//! [`crate::perturb`] for the frame and its limits.

use crate::perturb;
use radiant_core::glam::Vec3;
use radiant_core::params::Spanned;
use radiant_core::{
    BsdfEval, BsdfSample, BuildContext, Effects, ModuleInfo, ParamDoc, ParamError, Params,
    Registry, ShadeContext, Shader, SurfaceBatch, TextureId, TextureInput,
};
use serde::Deserialize;
use serde::de::IgnoredAny;

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct NormalMapParams {
    normals: Spanned<TextureInput>,
    // Read through `BuildContext::material`; listed for key checking.
    #[serde(rename = "material")]
    _material: IgnoredAny,
}

const DOCS: &[ParamDoc] = &[
    ParamDoc {
        name: "normals",
        ty: "rgb | texture name (tangent-space normal encoded as 0.5·n + 0.5)",
        default: "required",
        doc: "The normal map; [0.5, 0.5, 1] leaves the surface unchanged.",
    },
    ParamDoc {
        name: "material",
        ty: "material (a name under `materials:` or inline `{type: …}`)",
        default: "required",
        doc: "The material whose shading normal is replaced.",
    },
];

struct NormalMap {
    normals: TextureId,
    nested: Box<dyn Shader>,
    effects: Effects,
}

impl NormalMap {
    fn normals(&self, ctx: &mut ShadeContext<'_>, surface: SurfaceBatch<'_>) -> Vec<Vec3> {
        let mut normals = ctx.take::<Vec3>(surface.len());
        let [c] = ctx.lookup([self.normals], surface.uv);
        for (n, c) in normals.iter_mut().zip(c) {
            *n = perturb::sanitise(2.0 * *c - Vec3::ONE);
        }
        normals
    }
}

impl Shader for NormalMap {
    fn sample(
        &self,
        ctx: &mut ShadeContext<'_>,
        surface: SurfaceBatch<'_>,
        u: &[Vec3],
        out: &mut [BsdfSample],
    ) {
        let normals = self.normals(ctx, surface);
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
        let normals = self.normals(ctx, surface);
        perturb::eval(&*self.nested, ctx, surface, &normals, wi, out);
        ctx.recycle(normals);
    }

    fn effects(&self) -> Effects {
        self.effects
    }
}

fn build(params: &Params, ctx: &mut BuildContext<'_>) -> Result<NormalMap, ParamError> {
    let p: NormalMapParams = params.parse()?;
    let normals = ctx.texture(&p.normals)?;
    let nested = ctx.material(params, "material")?;
    let effects = nested.effects() | ctx.textures.effects(normals);
    Ok(NormalMap {
        normals,
        nested,
        effects,
    })
}

pub(crate) fn register(registry: &mut Registry) {
    registry.register::<dyn Shader>(
        ModuleInfo {
            type_name: "normal_map",
            summary: "Wraps a material, replacing its shading normal by a tangent-space normal map.",
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
        check_param_docs::<NormalMapParams>(DOCS).unwrap();
    }
}
