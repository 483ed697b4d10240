//! Per-point lobes shared by several shaders: sample constructors for
//! reflections, GGX reflection without its
//! Fresnel factor, and the rough dielectric interface of Walter et al.
//! (2007) sampled through the visible normals. Values are f·|cos θi| and
//! densities are per unit solid angle, for directions in the local frame.

use crate::fresnel;
use crate::microfacet::{Ggx, reflect, refract};
use radiant_core::glam::{Vec2, Vec3};
use radiant_core::{BsdfSample, Rgb};

pub(crate) use radiant_core::shading::reflection_sample;

/// A delta reflection about the normal, wi = (−wo.x, −wo.y, wo.z), chosen
/// with probability `pdf`.
#[inline]
pub(crate) fn mirror_sample(wo: Vec3, weight: Rgb, pdf: f32) -> BsdfSample {
    BsdfSample {
        wi: Vec3::new(-wo.x, -wo.y, wo.z),
        weight,
        pdf,
        delta: true,
        eta: 1.0,
    }
}

/// A sampled GGX reflection, before the Fresnel factor.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct GlossySample {
    /// The incident direction.
    pub wi: Vec3,
    /// The microfacet normal it reflects about.
    pub m: Vec3,
    /// f·cos/pdf without Fresnel: G1(wi, m).
    pub weight: f32,
    /// Solid-angle density of `wi`.
    pub pdf: f32,
}

/// Samples a GGX reflection for `wo` (upper hemisphere only).
#[inline]
pub(crate) fn glossy_sample(ggx: &Ggx, wo: Vec3, u: Vec2) -> Option<GlossySample> {
    if wo.z <= 0.0 {
        return None;
    }
    let m = ggx.sample_visible(wo, u);
    let wi = reflect(wo, m);
    let pdf = ggx.pdf_visible(wo, m) / (4.0 * wo.dot(m));
    (wi.z > 0.0 && pdf > 0.0 && pdf.is_finite()).then(|| GlossySample {
        wi,
        m,
        weight: ggx.g1(wi, m),
        pdf,
    })
}

/// Evaluates a GGX reflection without Fresnel: (half-vector, D·G/(4 cos θo)
/// = f·cos θi / F, pdf of [`glossy_sample`]).
#[inline]
pub(crate) fn glossy_eval(ggx: &Ggx, wo: Vec3, wi: Vec3) -> Option<(Vec3, f32, f32)> {
    if wo.z <= 0.0 || wi.z <= 0.0 {
        return None;
    }
    let m = (wo + wi).try_normalize()?;
    let d = ggx.d(m);
    let value = d * ggx.g(wo, wi, m) / (4.0 * wo.z);
    let pdf = ggx.g1(wo, m) * d / (4.0 * wo.z);
    (value.is_finite() && pdf.is_finite()).then_some((m, value, pdf))
}

/// A sampled interaction with a rough dielectric interface.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct InterfaceSample {
    /// The incident direction.
    pub wi: Vec3,
    /// f·|cos θi|/pdf (radiance transport: transmission carries
    /// (η_i/η_t)²), before any tint.
    pub weight: f32,
    /// Solid-angle density of `wi`.
    pub pdf: f32,
    /// Whether `wi` is on the other side (refraction).
    pub transmitted: bool,
}

/// Samples reflection or refraction at a rough interface of relative index
/// `eta` (inside over outside) for `wo` on either side (`u.x` chooses the
/// lobe by Fresnel, `u.y, u.z` the visible normal).
#[inline]
pub(crate) fn interface_sample(ggx: &Ggx, eta: f32, wo: Vec3, u: Vec3) -> Option<InterfaceSample> {
    if wo.z == 0.0 {
        return None;
    }
    let up = if wo.z > 0.0 { wo } else { -wo };
    let m = ggx.sample_visible(up, Vec2::new(u.y, u.z));
    let pdf_m = ggx.pdf_visible(up, m);
    let f = fresnel::dielectric(wo.dot(m), eta);
    let (wi, jacobian, lobe, transmitted) = if u.x <= f.r {
        let wi = reflect(wo, m);
        if wi.z * wo.z <= 0.0 {
            return None;
        }
        (wi, 1.0 / (4.0 * wi.dot(m).abs()), f.r, false)
    } else {
        let wi = refract(wo, m, f.cos_t, f.eta_ti);
        if wi.z * wo.z >= 0.0 {
            return None;
        }
        let denom = wo.dot(m) + f.eta_it * wi.dot(m);
        let jacobian = (f.eta_it * f.eta_it * wi.dot(m) / (denom * denom)).abs();
        (wi, jacobian, 1.0 - f.r, true)
    };
    let pdf = pdf_m * lobe * jacobian;
    let mut weight = ggx.g1(wi, m);
    if transmitted {
        weight *= f.eta_ti * f.eta_ti;
    }
    (pdf > 0.0 && pdf.is_finite() && weight.is_finite()).then_some(InterfaceSample {
        wi,
        weight,
        pdf,
        transmitted,
    })
}

/// Evaluates a rough interface: (f·|cos θi|, pdf of
/// [`interface_sample`], whether the pair refracts).
#[inline]
pub(crate) fn interface_eval(ggx: &Ggx, eta: f32, wo: Vec3, wi: Vec3) -> (f32, f32, bool) {
    if wo.z == 0.0 || wi.z == 0.0 {
        return (0.0, 0.0, false);
    }
    let reflected = wo.z * wi.z > 0.0;
    let eta_rel = if wo.z > 0.0 { eta } else { 1.0 / eta };
    let Some(m) = (wo + wi * if reflected { 1.0 } else { eta_rel }).try_normalize() else {
        return (0.0, 0.0, !reflected);
    };
    let m = if m.z < 0.0 { -m } else { m };
    if wo.dot(m) * wo.z <= 0.0 || wi.dot(m) * wi.z <= 0.0 {
        return (0.0, 0.0, !reflected);
    }
    let d = ggx.d(m);
    let f = fresnel::dielectric(wo.dot(m), eta).r;
    let g = ggx.g(wo, wi, m);
    let up = if wo.z > 0.0 { wo } else { -wo };
    let pdf_m = ggx.pdf_visible(up, m);
    let (value, pdf) = if reflected {
        (
            f * d * g / (4.0 * wo.z.abs()),
            pdf_m * f / (4.0 * wi.dot(m).abs()),
        )
    } else {
        let denom = wo.dot(m) + eta_rel * wi.dot(m);
        let denom2 = denom * denom;
        (
            ((1.0 - f) * d * g * wo.dot(m) * wi.dot(m) / (wo.z * denom2)).abs(),
            pdf_m * (1.0 - f) * (eta_rel * eta_rel * wi.dot(m) / denom2).abs(),
        )
    };
    if value.is_finite() && pdf.is_finite() {
        (value, pdf, !reflected)
    } else {
        (0.0, 0.0, !reflected)
    }
}
