//! The `normal_map` shader: wraps a material and replaces its shading
//! normal by one read from a texture (RGB in [0, 1] encoding a
//! tangent-space normal as 2·c − 1: +x along ∂p/∂u, +y along n × x, +z
//! out of the surface — uv tangent space as Mitsuba 3's `normalmap` reads
//! it, which matches bakers' maps except on mirrored uv islands, whose
//! green comes out inverted, in Mitsuba too). See [`crate::perturb`] for
//! the frame.

use crate::perturb::{self, NormalSource, PerturbOptions, Perturbed};
use radiant_core::glam::Vec3;
use radiant_core::params::Spanned;
use radiant_core::{
    BuildContext, GpuParams, ParamDoc, ParamError, Params, Registry, ShadeContext, SurfaceBatch,
    TextureId, TextureInput,
};
use serde::Deserialize;
use serde::de::IgnoredAny;

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct NormalMapParams {
    normals: Spanned<TextureInput>,
    #[serde(default = "perturb::yes")]
    flip_invalid_normals: bool,
    #[serde(default = "perturb::yes")]
    use_shadowing_function: bool,
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
    perturb::FLIP_DOC,
    perturb::SHADOWING_DOC,
];

/// Normals read from a texture.
struct MapNormals {
    normals: TextureId,
}

impl NormalSource for MapNormals {
    /// Mitsuba 3's `normalmap`: n′ = normalize(2·c − 1) in the shading
    /// frame.
    fn normals(&self, ctx: &mut ShadeContext<'_>, surface: SurfaceBatch<'_>) -> Vec<Vec3> {
        let mut normals = ctx.take::<Vec3>(surface.len());
        let [c] = ctx.lookup([self.normals], surface.uv);
        for (normal, c) in normals.iter_mut().zip(c) {
            *normal = perturb::sanitise(2.0 * *c - Vec3::ONE);
        }
        normals
    }

    fn gpu(&self) -> (&'static str, &'static str, GpuParams) {
        let params = GpuParams::new().texture(self.normals);
        ("normal_map", include_str!("normal_map.wgsl"), params)
    }
}

fn build(params: &Params, ctx: &mut BuildContext<'_>) -> Result<Perturbed<MapNormals>, ParamError> {
    let p: NormalMapParams = params.parse()?;
    let normals = ctx.texture(&p.normals)?;
    let options = PerturbOptions {
        flip_invalid_normals: p.flip_invalid_normals,
        use_shadowing_function: p.use_shadowing_function,
    };
    Perturbed::new(MapNormals { normals }, normals, options, params, ctx)
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
