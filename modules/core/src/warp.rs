//! Sampling warps: maps from the unit square to shapes and directions, each
//! with the density it produces.

use glam::{Vec2, Vec3};
use std::f32::consts::{FRAC_1_PI, FRAC_PI_4, PI};

/// Maps the unit square to the unit disk with Shirley–Chiu's concentric map.
#[inline]
pub fn square_to_disk_concentric(u: Vec2) -> Vec2 {
    let o = 2.0 * u - Vec2::ONE;
    if o.x == 0.0 && o.y == 0.0 {
        return Vec2::ZERO;
    }
    // θ = φ or π/2 − φ with |φ| ≤ π/4, so only sin φ and cos φ are needed.
    if o.x.abs() > o.y.abs() {
        let (s, c) = sin_cos_quarter(FRAC_PI_4 * (o.y / o.x));
        Vec2::new(c, s) * o.x
    } else {
        let (s, c) = sin_cos_quarter(FRAC_PI_4 * (o.x / o.y));
        Vec2::new(s, c) * o.y
    }
}

/// sin φ and cos φ for |φ| ≤ π/4 by their Taylor series to the φ⁹ and φ¹⁰
/// terms: the truncation error is below 2e-9, under single-precision
/// rounding, and the hot sampling path needs no call into libm.
#[inline]
pub fn sin_cos_quarter(phi: f32) -> (f32, f32) {
    let x2 = phi * phi;
    let sin = phi
        * (1.0
            + x2 * (-1.0 / 6.0
                + x2 * (1.0 / 120.0 + x2 * (-1.0 / 5040.0 + x2 * (1.0 / 362_880.0)))));
    let cos = 1.0
        + x2 * (-0.5
            + x2 * (1.0 / 24.0
                + x2 * (-1.0 / 720.0 + x2 * (1.0 / 40_320.0 + x2 * (-1.0 / 3_628_800.0)))));
    (sin, cos)
}

/// Cosine-weighted direction on the +z hemisphere.
#[inline]
pub fn square_to_cosine_hemisphere(u: Vec2) -> Vec3 {
    let d = square_to_disk_concentric(u);
    let z = (1.0 - d.length_squared()).max(0.0).sqrt();
    Vec3::new(d.x, d.y, z)
}

/// Density of [`square_to_cosine_hemisphere`] in solid angle.
#[inline]
pub fn cosine_hemisphere_pdf(v: Vec3) -> f32 {
    v.z.max(0.0) * FRAC_1_PI
}

/// Uniform direction on the unit sphere.
#[inline]
pub fn square_to_uniform_sphere(u: Vec2) -> Vec3 {
    let z = 1.0 - 2.0 * u.y;
    let r = (1.0 - z * z).max(0.0).sqrt();
    let (s, c) = (2.0 * PI * u.x).sin_cos();
    Vec3::new(r * c, r * s, z)
}

/// Density of [`square_to_uniform_sphere`] in solid angle.
pub const UNIFORM_SPHERE_PDF: f32 = 1.0 / (4.0 * PI);

/// Barycentric coordinates (b1, b2) of a uniformly distributed point on a
/// triangle; b0 = 1 − b1 − b2.
#[inline]
pub fn square_to_uniform_triangle(u: Vec2) -> Vec2 {
    let su = u.x.sqrt();
    Vec2::new(1.0 - su, u.y * su)
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::f32::consts::FRAC_1_SQRT_2;

    #[test]
    fn quarter_sin_cos_matches_libm() {
        for i in 0..=10_000 {
            let phi = FRAC_PI_4 * (2.0 * i as f32 / 10_000.0 - 1.0);
            let (s, c) = sin_cos_quarter(phi);
            let (es, ec) = (phi as f64).sin_cos();
            assert!((s as f64 - es).abs() < 2e-7, "sin {phi}: {s} vs {es}");
            assert!((c as f64 - ec).abs() < 2e-7, "cos {phi}: {c} vs {ec}");
        }
    }

    #[test]
    fn concentric_disk_keeps_its_quadrants_and_radius() {
        for (u, x, y) in [
            (Vec2::new(1.0, 0.5), 1.0, 0.0),
            (Vec2::new(0.5, 1.0), 0.0, 1.0),
            (Vec2::new(0.0, 0.5), -1.0, 0.0),
            (Vec2::new(0.5, 0.0), 0.0, -1.0),
            (Vec2::new(1.0, 1.0), FRAC_1_SQRT_2, FRAC_1_SQRT_2),
        ] {
            let d = square_to_disk_concentric(u);
            assert!((d - Vec2::new(x, y)).length() < 1e-6, "{u} → {d}");
        }
    }

    fn grid(n: usize) -> impl Iterator<Item = Vec2> {
        (0..n * n).map(move |i| {
            Vec2::new(
                ((i % n) as f32 + 0.5) / n as f32,
                ((i / n) as f32 + 0.5) / n as f32,
            )
        })
    }

    #[test]
    fn disk_points_lie_in_the_disk() {
        for u in grid(64) {
            assert!(square_to_disk_concentric(u).length() <= 1.0 + 1e-6);
        }
    }

    #[test]
    fn cosine_hemisphere_is_normalised_and_matches_its_pdf() {
        // E[f/pdf] with f = cos²θ estimates ∫ cos²θ dω = 2π/3.
        let n = 256;
        let mut sum = 0.0f64;
        for u in grid(n) {
            let v = square_to_cosine_hemisphere(u);
            assert!((v.length() - 1.0).abs() < 1e-5 && v.z >= 0.0);
            let pdf = cosine_hemisphere_pdf(v);
            if pdf > 0.0 {
                sum += (v.z * v.z / pdf) as f64;
            }
        }
        let est = sum / (n * n) as f64;
        assert!(
            (est - 2.0 * std::f64::consts::PI / 3.0).abs() < 1e-3,
            "{est}"
        );
    }

    #[test]
    fn triangle_barycentrics_are_valid_and_uniform() {
        let n = 128;
        let mut lower = 0usize;
        for u in grid(n) {
            let b = square_to_uniform_triangle(u);
            assert!(b.x >= 0.0 && b.y >= 0.0 && b.x + b.y <= 1.0 + 1e-6);
            // The sub-triangle b1 + b2 < 1/2 holds a quarter of the area.
            if b.x + b.y < 0.5 {
                lower += 1;
            }
        }
        let frac = lower as f64 / (n * n) as f64;
        assert!((frac - 0.25).abs() < 0.01, "{frac}");
    }
}
