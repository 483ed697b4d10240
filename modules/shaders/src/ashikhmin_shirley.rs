//! The `ashikhmin_shirley` shader: Ashikhmin and Shirley's (2000)
//! anisotropic Phong model, the coupled diffuse term of which seed 000
//! uses: a Fresnel-weighted (Schlick) anisotropic glossy lobe and a
//! diffuse term that takes the energy the glossy lobe leaves,
//!
//! f_s = √((nu+1)(nv+1)) / (8π) · (n·h)^(nu cos²φh + nv sin²φh) / ((h·k) max(cos θi, cos θo)) · F(h·k),
//! f_d = 28 Rd / (23π) · (1 − Rs) · (1 − (1 − cos θi/2)⁵)(1 − (1 − cos θo/2)⁵).
//!
//! The glossy lobe is sampled with the paper's half-vector warp, the
//! diffuse one by the cosine.

use crate::fresnel::schlick;
use crate::gpu;
use crate::half_vector::{HalfVectorLobes, HalfVectorShader, specular_probability};
use crate::inputs::{checked, fraction, half, scalar};
use radiant_core::glam::{Vec2, Vec3};
use radiant_core::params::Spanned;
use radiant_core::warp::cosine_hemisphere_pdf;
use radiant_core::{
    BuildContext, GpuLibrary, ParamDoc, ParamError, Params, Registry, Rgb, TextureInput,
};
use serde::Deserialize;
use std::f32::consts::{FRAC_PI_2, PI};

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct AsParams {
    #[serde(default = "half")]
    diffuse_reflectance: Spanned<TextureInput>,
    #[serde(default = "specular_default")]
    specular_reflectance: Spanned<TextureInput>,
    #[serde(default = "exponent_default")]
    exponent_u: Spanned<TextureInput>,
    #[serde(default = "exponent_default")]
    exponent_v: Spanned<TextureInput>,
}

fn specular_default() -> Spanned<TextureInput> {
    TextureInput::spanned_value(Rgb::splat(0.05))
}

fn exponent_default() -> Spanned<TextureInput> {
    TextureInput::spanned_value(Rgb::splat(100.0))
}

const DOCS: &[ParamDoc] = &[
    ParamDoc {
        name: "diffuse_reflectance",
        ty: "rgb | number | texture name, [0, 1]",
        default: "0.5",
        doc: "Diffuse albedo Rd of the substrate.",
    },
    ParamDoc {
        name: "specular_reflectance",
        ty: "rgb | number | texture name, [0, 1]",
        default: "0.05",
        doc: "Normal-incidence specular reflectance Rs (Schlick's R0).",
    },
    ParamDoc {
        name: "exponent_u",
        ty: "number | texture name, [0, 100000] (Phong exponent)",
        default: "100",
        doc: "Sharpness of the glossy lobe along the first tangent (larger is smoother).",
    },
    ParamDoc {
        name: "exponent_v",
        ty: "number | texture name, [0, 100000] (Phong exponent)",
        default: "100",
        doc: "Sharpness along the second tangent.",
    },
];

const MAX_EXPONENT: f32 = 1e5;

/// Per-point parameters.
#[derive(Clone, Copy)]
struct Lobes {
    rd: Rgb,
    rs: Rgb,
    nu: f32,
    nv: f32,
}

impl Lobes {
    /// The exponent nu cos²φh + nv sin²φh.
    fn exponent(&self, h: Vec3) -> f32 {
        let r2 = h.x * h.x + h.y * h.y;
        if r2 > 0.0 {
            (self.nu * h.x * h.x + self.nv * h.y * h.y) / r2
        } else {
            0.5 * (self.nu + self.nv)
        }
    }

    /// Density of the sampled half-vector per unit solid angle.
    fn half_pdf(&self, h: Vec3) -> f32 {
        if h.z <= 0.0 {
            return 0.0;
        }
        ((self.nu + 1.0) * (self.nv + 1.0)).sqrt() / (2.0 * PI) * h.z.powf(self.exponent(h))
    }
}

impl HalfVectorLobes for Lobes {
    const GPU_IDENT: &'static str = "ashikhmin_shirley";
    const GPU_CODE: &'static [GpuLibrary] = &[gpu::ASHIKHMIN_SHIRLEY];

    fn new(rd: Rgb, rs: Rgb, nu: Rgb, nv: Rgb) -> Self {
        Self {
            rd,
            rs,
            nu: scalar(nu).clamp(0.0, MAX_EXPONENT),
            nv: scalar(nv).clamp(0.0, MAX_EXPONENT),
        }
    }

    fn specular_probability(&self) -> f32 {
        specular_probability(self.rd, self.rs)
    }

    fn sample_half(&self, u: Vec2) -> Vec3 {
        // φ from the first quadrant's warp, mirrored into the others.
        let q = (u.x * 4.0).floor().min(3.0);
        let x = u.x * 4.0 - q;
        let k = ((self.nu + 1.0) / (self.nv + 1.0)).sqrt();
        let phi0 = (k * (FRAC_PI_2 * x).tan()).atan();
        let phi = match q as u32 {
            0 => phi0,
            1 => PI - phi0,
            2 => PI + phi0,
            _ => 2.0 * PI - phi0,
        };
        let (s, c) = phi.sin_cos();
        let e = self.nu * c * c + self.nv * s * s;
        let cos = (1.0 - u.y).powf(1.0 / (e + 1.0));
        let sin = (1.0 - cos * cos).max(0.0).sqrt();
        Vec3::new(sin * c, sin * s, cos)
    }

    fn eval(&self, wo: Vec3, wi: Vec3) -> (Rgb, f32) {
        if wo.z <= 0.0 || wi.z <= 0.0 {
            return (Rgb::ZERO, 0.0);
        }
        let ps = self.specular_probability();
        let fade = |c: f32| {
            let x = 1.0 - 0.5 * c;
            1.0 - x * x * x * x * x
        };
        let mut value =
            self.rd * (Rgb::ONE - self.rs) * (28.0 / (23.0 * PI) * fade(wi.z) * fade(wo.z) * wi.z);
        let mut pdf = (1.0 - ps) * cosine_hemisphere_pdf(wi);
        if let Some(h) = (wo + wi).try_normalize() {
            let kh = wi.dot(h);
            let ph = self.half_pdf(h);
            if kh > 0.0 && ph > 0.0 {
                let spec = ph / (4.0 * kh * wi.z.max(wo.z));
                value += schlick(kh, self.rs) * (spec * wi.z);
                pdf += ps * ph / (4.0 * kh);
            }
        }
        if value.is_finite() && pdf.is_finite() {
            (value, pdf)
        } else {
            (Rgb::ZERO, 0.0)
        }
    }
}

fn build(
    params: &Params,
    ctx: &mut BuildContext<'_>,
) -> Result<HalfVectorShader<Lobes>, ParamError> {
    let p: AsParams = params.parse()?;
    let diffuse = fraction(ctx, &p.diffuse_reflectance, "diffuse_reflectance")?;
    let specular = fraction(ctx, &p.specular_reflectance, "specular_reflectance")?;
    let nu = checked(ctx, &p.exponent_u, "exponent_u", 0.0, MAX_EXPONENT)?;
    let nv = checked(ctx, &p.exponent_v, "exponent_v", 0.0, MAX_EXPONENT)?;
    Ok(HalfVectorShader::new(ctx, [diffuse, specular, nu, nv]))
}

pub(crate) fn register(registry: &mut Registry) {
    crate::register_shader(
        registry,
        "ashikhmin_shirley",
        "Ashikhmin–Shirley anisotropic Phong glossy lobe with its energy-coupled diffuse term.",
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
        check_param_docs::<AsParams>(DOCS).unwrap();
    }
}
