//! The trigonometry between the map's (u, v) and directions: sine and
//! cosine of an angle in [0, 2π], and the angle of a point of the plane.
//!
//! Written out (a Cody–Waite reduction to radiant_core's
//! [`sin_cos_quarter`], Cephes' minimax polynomial for atan, within 2 ulp
//! of the exact values) rather than called in the C library:
//! every environment sample takes two sines and cosines and every escaped
//! ray two angles, and a call to libm is a chain of branches and a jump
//! the CPU cannot overlap with the neighbouring samples' work in the
//! light's staged loops, where these inline into a few multiplies and
//! adds. Only x86 `f32` arithmetic without fused multiply–adds is used,
//! so the values do not depend on the instruction set.

use radiant_core::warp::sin_cos_quarter;
use std::f32::consts::{FRAC_PI_2, FRAC_PI_4, PI};

/// tan(π/8): above it, [`atan_unit`] works on (a − 1)/(a + 1) instead.
const TAN_PI_8: f32 = 0.414_213_57;

/// (sin x, cos x) for x in [0, 2π] (within about 2·10⁻⁷ of the exact
/// values; larger |x| lose accuracy as the reduction's error grows).
#[inline(always)]
pub(super) fn sin_cos(x: f32) -> (f32, f32) {
    // x = q·π/2 + r with |r| ≤ π/4; π/2 in three parts, each product with
    // q exact for the q of this domain.
    const PI_2_HI: f32 = 1.570_312_5;
    const PI_2_MID: f32 = 4.837_513e-4;
    const PI_2_LO: f32 = 7.549_79e-8;
    let q = (x * (1.0 / FRAC_PI_2) + 0.5).floor();
    let r = ((x - q * PI_2_HI) - q * PI_2_MID) - q * PI_2_LO;
    let (sin_r, cos_r) = sin_cos_quarter(r);
    // sin and cos of q·π/2 + r by the quadrant q mod 4: (sin r, cos r),
    // (cos r, −sin r), (−sin r, −cos r) or (−cos r, sin r). Chosen with
    // bit masks, not branches: random angles would mispredict them.
    let q = q as u32;
    let swap = 0u32.wrapping_sub(q & 1);
    let (sin_bits, cos_bits) = (sin_r.to_bits(), cos_r.to_bits());
    let s = (sin_bits & !swap) | (cos_bits & swap);
    let c = (cos_bits & !swap) | (sin_bits & swap);
    (
        f32::from_bits(s ^ ((q & 2) << 30)),
        f32::from_bits(c ^ (((q + 1) & 2) << 30)),
    )
}

/// atan(a) for a in [0, 1].
#[inline(always)]
fn atan_unit(a: f32) -> f32 {
    let (t, base) = if a > TAN_PI_8 {
        ((a - 1.0) / (a + 1.0), FRAC_PI_4)
    } else {
        (a, 0.0)
    };
    let z = t * t;
    let p =
        (((8.053_744_5e-2 * z - 1.387_768_5e-1) * z + 1.997_771_1e-1) * z - 3.333_295e-1) * z * t
            + t;
    base + p
}

/// The angle of the point (`x`, `y`) in (−π, π] (within about 3·10⁻⁷
/// of the exact value), as `y.atan2(x)` except that the origin and
/// points on the negative x axis with y = −0 give 0 and π (C gives ±0
/// and ±π by the zeros' signs).
#[inline(always)]
pub(super) fn atan2(y: f32, x: f32) -> f32 {
    let (ax, ay) = (x.abs(), y.abs());
    let (lo, hi) = if ay > ax { (ax, ay) } else { (ay, ax) };
    let a = if hi > 0.0 { atan_unit(lo / hi) } else { 0.0 };
    let a = if ay > ax { FRAC_PI_2 - a } else { a };
    let a = if x < 0.0 { PI - a } else { a };
    if y < 0.0 { -a } else { a }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn sine_and_cosine_are_within_two_ulp_of_one() {
        let n = 1 << 20;
        let mut worst = 0.0f64;
        for i in 0..=n {
            let x = std::f32::consts::TAU * i as f32 / n as f32;
            let (s, c) = sin_cos(x);
            let (es, ec) = (x as f64).sin_cos();
            worst = worst.max((s as f64 - es).abs()).max((c as f64 - ec).abs());
        }
        assert!(worst < 2.0 * f32::EPSILON as f64, "worst error {worst:e}");
        // The quadrants' ends land on the right signs.
        assert_eq!(sin_cos(0.0), (0.0, 1.0));
        let (s, c) = sin_cos(PI);
        assert!(s.abs() < 1e-6 && (c + 1.0).abs() < 1e-7);
    }

    #[test]
    fn angles_are_those_of_atan2_within_three_ulp_of_pi() {
        let n = 2000;
        let mut worst = 0.0f64;
        for i in 0..n {
            let phi = std::f64::consts::TAU * (i as f64 + 0.37) / n as f64;
            for r in [1e-30, 1e-3, 1.0, 7.5, 1e30] {
                let (y, x) = ((r * phi.sin()) as f32, (r * phi.cos()) as f32);
                let exact = (y as f64).atan2(x as f64);
                worst = worst.max((atan2(y, x) as f64 - exact).abs());
            }
        }
        assert!(
            worst < 3.0 * PI as f64 * f32::EPSILON as f64 / 2.0,
            "worst error {worst:e}"
        );
        // Axes and the origin.
        assert_eq!(atan2(0.0, 1.0), 0.0);
        assert_eq!(atan2(1.0, 0.0), FRAC_PI_2);
        assert_eq!(atan2(0.0, -1.0), PI);
        assert_eq!(atan2(-1.0, 0.0), -FRAC_PI_2);
        assert_eq!(atan2(0.0, 0.0), 0.0);
    }
}
