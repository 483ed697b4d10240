//! The GGX (Trowbridge–Reitz) microfacet distribution with anisotropic
//! roughness, Smith's separable shadowing–masking and sampling of the
//! visible normals (Heitz 2018), shared by the rough shaders.
//!
//! Conventions are Mitsuba 3's: `alpha_u`/`alpha_v` are the roughnesses
//! along the local x and y axes, directions are in the local shading frame
//! and the sampled normals lie in the upper hemisphere.

use radiant_core::glam::{Vec2, Vec3};
use std::f32::consts::PI;

/// Smallest roughness used: below it GGX evaluations lose precision in
/// `f32`, and the lobe is numerically a mirror anyway.
pub const MIN_ALPHA: f32 = 1e-4;

/// An anisotropic GGX distribution of microfacet normals.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Ggx {
    /// Roughness along local x.
    pub alpha_u: f32,
    /// Roughness along local y.
    pub alpha_v: f32,
}

impl Ggx {
    /// A distribution with the given roughnesses (clamped to [`MIN_ALPHA`]).
    #[inline]
    pub fn new(alpha_u: f32, alpha_v: f32) -> Self {
        Self {
            alpha_u: alpha_u.max(MIN_ALPHA),
            alpha_v: alpha_v.max(MIN_ALPHA),
        }
    }

    /// Density of normals `m` per unit projected area, D(m).
    #[inline]
    pub fn d(&self, m: Vec3) -> f32 {
        if m.z <= 0.0 {
            return 0.0;
        }
        let (x, y) = (m.x / self.alpha_u, m.y / self.alpha_v);
        let s = x * x + y * y + m.z * m.z;
        let d = 1.0 / (PI * self.alpha_u * self.alpha_v * s * s);
        if d.is_finite() { d } else { 0.0 }
    }

    /// Smith's masking of direction `v` by microfacets of normal `m`.
    #[inline]
    pub fn g1(&self, v: Vec3, m: Vec3) -> f32 {
        if v.dot(m) * v.z <= 0.0 {
            return 0.0;
        }
        let xy = (self.alpha_u * v.x).powi(2) + (self.alpha_v * v.y).powi(2);
        if xy == 0.0 {
            return 1.0;
        }
        let tan2 = xy / (v.z * v.z);
        2.0 / (1.0 + (1.0 + tan2).sqrt())
    }

    /// Separable shadowing–masking G(wo, wi, m) = G1(wo, m) G1(wi, m).
    #[inline]
    pub fn g(&self, wo: Vec3, wi: Vec3, m: Vec3) -> f32 {
        self.g1(wo, m) * self.g1(wi, m)
    }

    /// Samples a normal visible from `wo` (which must have `wo.z > 0`) with
    /// density [`pdf_visible`](Self::pdf_visible).
    #[inline]
    pub fn sample_visible(&self, wo: Vec3, u: Vec2) -> Vec3 {
        // Stretch to the configuration of roughness 1.
        let vh = Vec3::new(self.alpha_u * wo.x, self.alpha_v * wo.y, wo.z).normalize();
        let lensq = vh.x * vh.x + vh.y * vh.y;
        let t1 = if lensq > 0.0 {
            Vec3::new(-vh.y, vh.x, 0.0) / lensq.sqrt()
        } else {
            Vec3::X
        };
        let t2 = vh.cross(t1);
        // A uniform point on the disk, warped to the projected hemisphere.
        let r = u.x.sqrt();
        let (s, c) = (2.0 * PI * u.y).sin_cos();
        let p1 = r * c;
        let h = 0.5 * (1.0 + vh.z);
        let p2 = (1.0 - h) * (1.0 - p1 * p1).max(0.0).sqrt() + h * r * s;
        let nh = t1 * p1 + t2 * p2 + vh * (1.0 - p1 * p1 - p2 * p2).max(0.0).sqrt();
        // Unstretch.
        Vec3::new(self.alpha_u * nh.x, self.alpha_v * nh.y, nh.z.max(1e-7)).normalize()
    }

    /// Density of [`sample_visible`](Self::sample_visible) producing `m`,
    /// per unit solid angle of normals: G1(wo, m) max(0, wo·m) D(m) / wo.z.
    #[inline]
    pub fn pdf_visible(&self, wo: Vec3, m: Vec3) -> f32 {
        if wo.z <= 0.0 {
            return 0.0;
        }
        self.g1(wo, m) * wo.dot(m).max(0.0) * self.d(m) / wo.z
    }
}

/// Mirror reflection of `v` about the unit normal `m`.
#[inline]
pub fn reflect(v: Vec3, m: Vec3) -> Vec3 {
    2.0 * v.dot(m) * m - v
}

/// Refraction of `v` about the normal `m` given the cosine of the
/// transmitted direction (from the crate's `fresnel::dielectric`) and the
/// relative index `eta_ti` (η of the side of `v` over the other side).
#[inline]
pub fn refract(v: Vec3, m: Vec3, cos_t: f32, eta_ti: f32) -> Vec3 {
    m * (v.dot(m) * eta_ti + cos_t) - v * eta_ti
}

#[cfg(test)]
mod tests {
    use super::*;

    fn grid(n: usize) -> impl Iterator<Item = Vec2> {
        (0..n * n).map(move |i| {
            Vec2::new(
                ((i % n) as f32 + 0.5) / n as f32,
                ((i / n) as f32 + 0.5) / n as f32,
            )
        })
    }

    #[test]
    fn projected_normals_integrate_to_one() {
        // ∫ D(m) cos θm dωm = 1, by Monte Carlo with uniform directions on
        // the hemisphere, for isotropic and anisotropic roughness.
        for (au, av) in [(0.3f32, 0.3f32), (0.5, 0.05), (1.0, 1.0)] {
            let ggx = Ggx::new(au, av);
            let n = 512;
            let mut sum = 0.0f64;
            for u in grid(n) {
                let z = u.x;
                let r = (1.0 - z * z).sqrt();
                let (s, c) = (2.0 * PI * u.y).sin_cos();
                let m = Vec3::new(r * c, r * s, z);
                sum += (ggx.d(m) * m.z) as f64 * 2.0 * std::f64::consts::PI;
            }
            let est = sum / (n * n) as f64;
            assert!((est - 1.0).abs() < 0.02, "{au} {av}: {est}");
        }
    }

    #[test]
    fn visible_normals_are_normalised() {
        // The density integrates to 1 (quadrature), and the mean of m.z
        // over sampled normals matches its quadrature under the density.
        let ggx = Ggx::new(0.4, 0.15);
        let wo = Vec3::new(0.5, 0.3, 0.2).normalize();
        let n = 256;
        let mut sampled = 0.0f64;
        for u in grid(n) {
            sampled += ggx.sample_visible(wo, u).z as f64;
        }
        sampled /= (n * n) as f64;
        let (mut quad, mut total) = (0.0f64, 0.0f64);
        let k = 1024;
        for u in grid(k) {
            let z = u.x;
            let r = (1.0 - z * z).sqrt();
            let (s, c) = (2.0 * PI * u.y).sin_cos();
            let m = Vec3::new(r * c, r * s, z);
            let p = ggx.pdf_visible(wo, m) as f64 * 2.0 * std::f64::consts::PI;
            quad += p * m.z as f64;
            total += p;
        }
        quad /= (k * k) as f64;
        total /= (k * k) as f64;
        assert!((total - 1.0).abs() < 0.01, "VNDF integrates to {total}");
        assert!((quad - sampled).abs() < 0.005, "{quad} vs {sampled}");
    }
}
