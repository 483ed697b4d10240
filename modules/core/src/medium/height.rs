//! Exponential height fog's density profile in closed form: the density
//! integral along a ray and its inverse, so that distance sampling and
//! transmittance are exact (no tracking, no noise in shadow rays).
//!
//! With density ρ(p) = ρ0·exp(−(u·p − h0)/H) (`u` the unit up axis), a ray
//! p(t) = o + t·d (d a unit vector) sees ρ(t) = a·exp(−t·k/H), a = ρ(o),
//! k = u·d, so D(t) = ∫0^t ρ = a·H/k·(1 − exp(−t·k/H)) (a·t where k = 0).
//! The medium's coefficients are ρ times its base coefficients, so a
//! homogeneous free flight in the coordinate D is exact in t
//! ([`crate::medium::free_flight`] on D, then [`HeightProfile::inverse`]).
//! Computed in f64; the exponent is clamped to ±[`MAX_EXPONENT`] so that a
//! ray far below the reference height gives a large finite density, never
//! an overflow.

use glam::Vec3;

/// The largest |exponent| of the density: ρ stays within ρ0·e^(±80).
pub const MAX_EXPONENT: f64 = 80.0;

/// An exponential density profile along an up axis, in render space.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct HeightProfile {
    /// The unit up axis.
    pub up: Vec3,
    /// The reference height h0 (u·p of the reference point, render space).
    pub h0: f64,
    /// The density at the reference height, ρ0 ≥ 0.
    pub rho0: f64,
    /// The scale height H > 0: the density falls by e every H upwards.
    pub scale_height: f64,
}

impl HeightProfile {
    /// ρ at the render-space point `p`.
    pub fn density(&self, p: Vec3) -> f64 {
        let h = self.up.as_dvec3().dot(p.as_dvec3());
        let x = (-(h - self.h0) / self.scale_height).clamp(-MAX_EXPONENT, MAX_EXPONENT);
        self.rho0 * x.exp()
    }

    /// D(t) = ∫0^t ρ(o + s·d) ds for the unit direction `d` (`t` may be
    /// infinite: D(∞) is finite for rays going up).
    pub fn integral(&self, o: Vec3, d: Vec3, t: f32) -> f64 {
        let a = self.density(o);
        if a == 0.0 || t <= 0.0 {
            return 0.0;
        }
        let k = f64::from(self.up.dot(d));
        let t = f64::from(t);
        let x = t * k / self.scale_height;
        if k == 0.0 {
            // Level: the density is constant along the ray.
            return a * t;
        }
        // a·H/k·(1 − e^(−x)), clamped like the density.
        a * self.scale_height / k * -(-x.min(MAX_EXPONENT)).exp_m1()
    }

    /// The distance t with D(t) = `depth` along the unit direction `d`, or
    /// infinity where the ray's whole integral stays below it.
    pub fn inverse(&self, o: Vec3, d: Vec3, depth: f64) -> f32 {
        let a = self.density(o);
        if a == 0.0 {
            return f32::INFINITY;
        }
        let k = f64::from(self.up.dot(d));
        let h = self.scale_height;
        let y = depth * k / (a * h);
        if k == 0.0 {
            return (depth / a) as f32;
        }
        if y >= 1.0 {
            return f32::INFINITY;
        }
        // 1 − e^(−t·k/H) = y  ⇒  t = −H/k · ln(1 − y).
        (-h / k * (-y).ln_1p()) as f32
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn fog() -> HeightProfile {
        HeightProfile {
            up: Vec3::Y,
            h0: 0.5,
            rho0: 2.0,
            scale_height: 0.7,
        }
    }

    #[test]
    fn integral_matches_quadrature_and_inverse_inverts_it() {
        let f = fog();
        let o = Vec3::new(0.1, -0.3, 0.2);
        for d in [
            Vec3::new(0.0, 1.0, 0.0),
            Vec3::new(0.6, -0.8, 0.0),
            Vec3::new(1.0, 0.0, 0.0),
            Vec3::new(0.0, 1e-10, 1.0).normalize(),
        ] {
            for t in [0.01f32, 0.5, 3.0] {
                let n = 100_000;
                let h = f64::from(t) / n as f64;
                let quad: f64 = (0..n)
                    .map(|i| f.density(o + d * ((i as f64 + 0.5) * h) as f32) * h)
                    .sum();
                let closed = f.integral(o, d, t);
                assert!(
                    (closed - quad).abs() < 1e-5 * quad.max(1.0),
                    "{d} {t}: {closed} vs {quad}"
                );
                let back = f.inverse(o, d, closed);
                assert!(
                    (back - t).abs() < 1e-4 * t.max(1.0),
                    "{d} {t}: inverse {back}"
                );
            }
        }
        // Upwards the integral to infinity is finite, and depths beyond it
        // are never reached.
        let total = f.integral(o, Vec3::Y, f32::INFINITY);
        assert!(total.is_finite() && total > 0.0);
        assert_eq!(f.inverse(o, Vec3::Y, total * 1.01), f32::INFINITY);
        assert_eq!(f.integral(o, -Vec3::Y, f32::INFINITY), f64::INFINITY);
    }
}
