//! The `bump` shader: wraps a material and tilts its shading normal by the
//! gradient of a height texture, as Mitsuba 3's `bumpmap`: the surface's
//! ∂p/∂u and ∂p/∂v get normal components scale·∂h/∂u and scale·∂h/∂v in
//! place of their own, and the perturbed normal is their cross product
//! (turned to the side of the shading normal), so the relief depends on
//! the parametrisation's real scale, not on the frame. The gradient is
//! taken by central differences of step [`STEP`] in (u, v). See
//! [`crate::perturb`] for the frame.

use crate::inputs::scalar;
use crate::perturb::{self, NormalSource, PerturbOptions, Perturbed};
use radiant_core::glam::{Vec2, Vec3};
use radiant_core::params::Spanned;
use radiant_core::{
    BuildContext, GpuParams, ParamDoc, ParamError, Params, Registry, ShadeContext, SurfaceBatch,
    TextureId, TextureInput,
};
use serde::Deserialize;
use serde::de::IgnoredAny;

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct BumpParams {
    height: Spanned<TextureInput>,
    #[serde(default = "one")]
    scale: f32,
    #[serde(default = "perturb::yes")]
    flip_invalid_normals: bool,
    #[serde(default = "perturb::yes")]
    use_shadowing_function: bool,
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
    perturb::FLIP_DOC,
    perturb::SHADOWING_DOC,
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
        for (i, out) in normals.iter_mut().enumerate() {
            let hu = (scalar(h[i]) - scalar(h[n + i])) * k;
            let hv = (scalar(h[2 * n + i]) - scalar(h[3 * n + i])) * k;
            // The derivatives with their normal (z) components replaced
            // by the height's gradient.
            let (du, dv) = perturb::derivatives(&surface, i);
            let du = Vec3::new(du.x, du.y, hu);
            let dv = Vec3::new(dv.x, dv.y, hv);
            let normal = du.cross(dv).try_normalize().unwrap_or(Vec3::Z);
            let normal = if normal.z < 0.0 { -normal } else { normal };
            *out = perturb::sanitise(normal);
        }
        ctx.recycle(shifted);
        normals
    }

    fn gpu(&self) -> (&'static str, &'static str, GpuParams) {
        let params = GpuParams::new().texture(self.height).f32(self.scale);
        ("bump", include_str!("bump.wgsl"), params)
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
    let options = PerturbOptions {
        flip_invalid_normals: p.flip_invalid_normals,
        use_shadowing_function: p.use_shadowing_function,
    };
    Perturbed::new(source, height, options, params, ctx)
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
