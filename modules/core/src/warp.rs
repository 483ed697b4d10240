//! Sampling warps: maps from the unit square to shapes and directions, each
//! with the density it produces.

use glam::{Vec2, Vec3};
use std::f32::consts::{FRAC_1_PI, FRAC_PI_2, FRAC_PI_4, PI};

/// Maps the unit square to the unit disk with Shirley–Chiu's concentric map.
#[inline]
pub fn square_to_disk_concentric(u: Vec2) -> Vec2 {
    let o = 2.0 * u - Vec2::ONE;
    if o.x == 0.0 && o.y == 0.0 {
        return Vec2::ZERO;
    }
    let (r, theta) = if o.x.abs() > o.y.abs() {
        (o.x, FRAC_PI_4 * (o.y / o.x))
    } else {
        (o.y, FRAC_PI_2 - FRAC_PI_4 * (o.x / o.y))
    };
    let (s, c) = theta.sin_cos();
    Vec2::new(c, s) * r
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
