//! Sampling a bilinear patch: the density inside one cell of the
//! environment map's grid, proportional to the bilinear interpolation of
//! the sampling weights at its four corners (pbrt-v4's `SampleBilinear`
//! and `BilinearPDF`, with the linear step written so that no weight is
//! squared unscaled). `environment.wgsl` has the same three functions.
//!
//! Corner order: `w[0]` at (0, 0), `w[1]` at (1, 0), `w[2]` at (0, 1),
//! `w[3]` at (1, 1).

use radiant_core::ONE_MINUS_EPSILON;
use radiant_core::glam::Vec2;

/// A point of [0, 1) drawn with density ∝ (1 − x) a + x b from `u` in
/// [0, 1) (a, b ≥ 0; uniform where both are 0).
#[inline]
pub(super) fn sample_linear(u: f32, a: f32, b: f32) -> f32 {
    let sum = a + b;
    if sum <= 0.0 {
        return u;
    }
    // The inverse CDF u (a + b) / (a + √((1 − u) a² + u b²)) with a and b
    // divided by their sum, so that large weights cannot overflow.
    let (a, b) = (a / sum, b / sum);
    let den = a + ((1.0 - u) * a * a + u * b * b).sqrt();
    if den > 0.0 {
        (u / den).min(ONE_MINUS_EPSILON)
    } else {
        0.0
    }
}

/// A point of [0, 1)² drawn with density ∝ the bilinear interpolation of
/// `w` from `u`: v from the marginal, then u given v.
#[inline]
pub(super) fn sample_bilinear(u: Vec2, w: [f32; 4]) -> Vec2 {
    let y = sample_linear(u.y, w[0] + w[1], w[2] + w[3]);
    let x = sample_linear(u.x, w[0] + (w[2] - w[0]) * y, w[1] + (w[3] - w[1]) * y);
    Vec2::new(x, y)
}

/// The density of [`sample_bilinear`] at `t` in [0, 1]²: the bilinear
/// interpolation of `w` over its mean (1 where all corners are 0, as the
/// sampling is then uniform).
#[inline]
pub(super) fn bilinear_pdf(t: Vec2, w: [f32; 4]) -> f32 {
    let sum = w[0] + w[1] + w[2] + w[3];
    if sum <= 0.0 {
        return 1.0;
    }
    4.0 * bilerp(t, w) / sum
}

/// The bilinear interpolation of the corner values `w` at `t`.
#[inline]
fn bilerp(t: Vec2, w: [f32; 4]) -> f32 {
    let top = w[0] + (w[1] - w[0]) * t.x;
    let bottom = w[2] + (w[3] - w[2]) * t.x;
    top + (bottom - top) * t.y
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The fraction of the density ∝ bilinear `w` over [0, x] × [0, y],
    /// in closed form.
    fn cdf(x: f64, y: f64, w: [f32; 4]) -> f64 {
        let w = w.map(f64::from);
        let (x2, y2) = (x * x / 2.0, y * y / 2.0);
        let integral = w[0] * (x - x2) * (y - y2)
            + w[1] * x2 * (y - y2)
            + w[2] * (x - x2) * y2
            + w[3] * x2 * y2;
        integral * 4.0 / w.iter().sum::<f64>()
    }

    #[test]
    fn bilinear_samples_follow_their_density() {
        // Steep, flat, one-zero-corner and two-zero-corner patches.
        let patches = [
            [1.0, 9.0, 3.0, 0.5],
            [2.0, 2.0, 2.0, 2.0],
            [0.0, 1.0, 4.0, 2.0],
            [0.0, 0.0, 1.0, 3.0],
            [1e30, 3e30, 2e30, 0.0],
        ];
        let n = 256;
        for w in patches {
            // Each sample's inverse: the density's CDF at the sample, as
            // the conditional of x given y times the marginal of y, must
            // give back u.
            for i in 0..n {
                for j in 0..n {
                    let u = Vec2::new((i as f32 + 0.5) / n as f32, (j as f32 + 0.5) / n as f32);
                    let t = sample_bilinear(u, w);
                    assert!((0.0..1.0).contains(&t.x) && (0.0..1.0).contains(&t.y));
                    let marginal = cdf(1.0, t.y as f64, w);
                    let dy = 1e-4;
                    let conditional = (cdf(t.x as f64, t.y as f64 + dy, w)
                        - cdf(t.x as f64, t.y as f64, w))
                        / (cdf(1.0, t.y as f64 + dy, w) - cdf(1.0, t.y as f64, w));
                    assert!((marginal - u.y as f64).abs() < 1e-4, "{w:?} {u} {t}");
                    assert!((conditional - u.x as f64).abs() < 1e-3, "{w:?} {u} {t}");
                }
            }
            // The density integrates to 1 and is what the CDF differentiates to.
            let h = 1e-3;
            let (x, y) = (0.3, 0.6);
            let numeric = (cdf(x + h, y + h, w) - cdf(x, y + h, w) - cdf(x + h, y, w)
                + cdf(x, y, w))
                / (h * h);
            let pdf = bilinear_pdf(Vec2::new(x as f32, y as f32), w) as f64;
            assert!(
                (numeric / pdf - 1.0).abs() < 1e-2,
                "{w:?}: {numeric} vs {pdf}"
            );
            assert!((cdf(1.0, 1.0, w) - 1.0).abs() < 1e-9);
        }
    }
}
