//! The `normal_map` shader: wraps a material and replaces its shading
//! normal by one read from a texture (RGB in [0, 1] encoding a
//! tangent-space normal as 2·c − 1: +x along ∂p/∂u, +z out of the
//! surface — uv tangent space, as Mitsuba 3's `normalmap` and normal-map
//! bakers define it). See [`crate::perturb`] for the frame.

use crate::perturb::{self, FrameSource, Perturbed};
use radiant_core::Frame;
use radiant_core::glam::Vec3;
use radiant_core::params::Spanned;
use radiant_core::{
    BuildContext, ParamDoc, ParamError, Params, Registry, ShadeContext, SurfaceBatch, TextureId,
    TextureInput,
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

/// Normals read from a texture.
struct MapNormals {
    normals: TextureId,
}

impl FrameSource for MapNormals {
    /// Mitsuba 3's `normalmap`: n′ = normalize(2·c − 1) in the shading
    /// frame, first tangent ∂p/∂u made orthogonal to n′.
    fn frames(&self, ctx: &mut ShadeContext<'_>, surface: SurfaceBatch<'_>) -> Vec<Frame> {
        let n = surface.len();
        let mut frames = ctx.take::<Frame>(n);
        let [c] = ctx.lookup([self.normals], surface.uv);
        for (i, (f, c)) in frames.iter_mut().zip(c).enumerate() {
            let normal = perturb::sanitise(2.0 * *c - Vec3::ONE);
            *f = perturb::frame_along(normal, perturb::derivatives(&surface, i).0);
        }
        frames
    }
}

fn build(params: &Params, ctx: &mut BuildContext<'_>) -> Result<Perturbed<MapNormals>, ParamError> {
    let p: NormalMapParams = params.parse()?;
    let normals = ctx.texture(&p.normals)?;
    Perturbed::new(MapNormals { normals }, normals, params, ctx)
}

pub(crate) fn register(registry: &mut Registry) {
    crate::register_shader(
        registry,
        "normal_map",
        "Wraps a material, replacing its shading normal by a tangent-space normal map.",
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
        check_param_docs::<NormalMapParams>(DOCS).unwrap();
    }
}
