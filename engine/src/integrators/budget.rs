//! Adaptive sampling toward the least mean squared error for a fixed
//! budget (`sampler: {adaptive: {error: mse}}`).
//!
//! Seed 002's rule ([`super::adaptive`]) stops each pixel at a relative
//! error. That spends samples where the *relative* error is large (dim,
//! noisy pixels), which is not where the image's mean squared error is: on
//! the Cornell box 1 % of the pixels (the edges of the light) hold 88 % of
//! the variance, and an allocation by relative error can lower the MSE by
//! at most a factor 1.38 there (`engine/benches/ADAPTIVE.md`). For a
//! budget of N = spp · pixels image samples, the MSE Σ σᵢ²/nᵢ is least
//! when each pixel takes nᵢ ∝ σᵢ, the standard deviation of one of its
//! samples (Lagrange: σᵢ²/nᵢ² is the same everywhere); against a fixed
//! spp that lowers the MSE by E[σ²]/E[σ]², 8.7 on the Cornell box.
//!
//! So a frame is decided in one pilot round: every pixel renders
//! [`pilot_samples`] decision samples (sample indices from
//! [`DECISION_BASE`], never added to the image, so the image stays
//! unbiased as under the relative rule), its σ is estimated from their
//! luminance, and [`allocate`] splits the budget nᵢ = clamp(c·σᵢ, min,
//! max) with c chosen so that the counts add up to the budget. Unlike the
//! relative rule this needs every pixel's σ before any count is known, so
//! the whole frame is decided before its image samples are rendered
//! (`backend/cpu.rs`); the image samples are then rendered and weighted
//! exactly as under the relative rule (1 / count where a filter splats).
//!
//! The floor `min_spp` (default a quarter of `spp`) keeps pixels whose
//! pilot samples all missed a rare bright path (σ estimated as 0) from
//! starving; the ceiling `max_spp` (default 16 · `spp`) bounds a pixel's
//! cost.

use super::adaptive::{
    Adaptive, DECISION_BASE, DECISION_SHARE, Moments, TileRect, sample_luminance,
};
use super::module::{Batch, batches};
use crate::film::Reconstruction;
use radiant_core::Rgb;

/// Bytes a frame pixel's decisions take at their peak: its pilot (mean
/// and σ) in its tile's results and in the frame, its effective σ before
/// and after pooling, and its count.
pub const DECISION_BYTES: u64 = 2 * 16 + 2 * 8 + 4;

/// Pilot decision samples per pixel for a budget of `spp`: a
/// [`DECISION_SHARE`]th of it, from 4 (a variance needs a few) to 64
/// (enough for σ; more would only cost).
pub fn pilot_samples(spp: u32) -> u32 {
    (spp / DECISION_SHARE).clamp(4, 64)
}

/// (least, most) image samples of a pixel under a budget of `spp` per
/// pixel: `min_spp` (default `spp` / 4, at least 1) and `max_spp`
/// (default 16 · `spp`).
pub fn limits(a: &Adaptive, spp: u32) -> (u32, u32) {
    let most = a.max_spp.unwrap_or(spp.saturating_mul(16)).max(1);
    let least = a.min_spp.unwrap_or(spp / 4).clamp(1, most);
    (least, most)
}

/// Renders the pilot round of tile `t` (`render(batch, on_sample)` renders
/// a batch of decision samples and reports each sample's value by pixel)
/// and returns each pixel's mean and σ of one sample's luminance,
/// row-major in the tile.
pub fn pilot(
    spp: u32,
    t: TileRect,
    mut render: impl FnMut(Batch, &mut dyn FnMut(u32, Rgb)),
) -> Vec<Pilot> {
    let mut moments = vec![Moments::default(); t.len()];
    let samples = DECISION_BASE..DECISION_BASE + pilot_samples(spp);
    for batch in batches((t.x0, t.y0, t.x1, t.y1), samples) {
        render(batch, &mut |p, v| {
            moments[t.index(p)].add(sample_luminance(v))
        });
    }
    moments
        .iter()
        .map(|m| Pilot {
            mean: m.mean(),
            sigma: m.variance().sqrt(),
        })
        .collect()
}

/// What a pixel's pilot samples say: the mean and the standard deviation
/// of one sample's luminance.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct Pilot {
    /// Mean luminance.
    pub mean: f64,
    /// Standard deviation of one sample's luminance.
    pub sigma: f64,
}

/// How much one sample of a pixel weighs in the squared error of each
/// pixel around it: K(d) = E[w(x − c − d)²] over x uniform in the pixel,
/// for the neighbour at offset d (up to the filter's radius). Under
/// filter importance sampling, or a filter that reaches no neighbour,
/// K is 1 at d = 0 alone.
#[derive(Debug, Clone, PartialEq)]
pub struct Footprint {
    reach: i32,
    /// K, row-major over (2·reach + 1)² offsets.
    weights: Vec<f64>,
}

impl Footprint {
    /// The footprint of samples reconstructed by `reconstruction`.
    pub fn new(reconstruction: &Reconstruction) -> Self {
        let Reconstruction::Splat(table) = reconstruction else {
            return Self::own_pixel();
        };
        // Offsets whose filter support meets the pixel: |d| < radius + ½.
        let reach = (table.radius() + 0.5).floor() as i32;
        let side = 2 * reach + 1;
        // E[w²] by the midpoint rule on an 8×8 grid over the pixel.
        const GRID: i32 = 8;
        let mut weights = Vec::with_capacity((side * side) as usize);
        for dy in -reach..=reach {
            for dx in -reach..=reach {
                let mut sum = 0.0;
                for gy in 0..GRID {
                    for gx in 0..GRID {
                        let x = (gx as f32 + 0.5) / GRID as f32 - 0.5 - dx as f32;
                        let y = (gy as f32 + 0.5) / GRID as f32 - 0.5 - dy as f32;
                        sum += f64::from(table.weight(x, y)).powi(2);
                    }
                }
                weights.push(sum / f64::from(GRID * GRID));
            }
        }
        Self { reach, weights }
    }

    fn own_pixel() -> Self {
        Self {
            reach: 0,
            weights: vec![1.0],
        }
    }

    /// Each pixel's effective σ: with the filter's ratio estimator
    /// linearised, a sample of pixel j adds w·(L − Iᵢ) to the error of each
    /// neighbour i, so it counts σⱼ,eff² = Σᵢ K(i − j)·(σⱼ² + (μⱼ − μᵢ)²):
    /// a pixel inside a bright light with no noise of its own still makes
    /// its dark neighbours' estimates noisy through where its samples land.
    /// `pilot` is row-major over a `width`-wide frame.
    pub fn effective_sigma(&self, pilot: &[Pilot], width: usize) -> Vec<f64> {
        let height = pilot.len() / width.max(1);
        let (reach, side) = (self.reach as isize, (2 * self.reach + 1) as usize);
        let mut out = Vec::with_capacity(pilot.len());
        for y in 0..height {
            for x in 0..width {
                let p = pilot[y * width + x];
                let mut sum = 0.0;
                for dy in -reach..=reach {
                    for dx in -reach..=reach {
                        let (nx, ny) = (x as isize + dx, y as isize + dy);
                        if nx < 0 || ny < 0 || nx >= width as isize || ny >= height as isize {
                            continue;
                        }
                        let k = (dy + reach) as usize * side + (dx + reach) as usize;
                        let spread = p.mean - pilot[ny as usize * width + nx as usize].mean;
                        sum += self.weights[k] * (p.sigma * p.sigma + spread * spread);
                    }
                }
                out.push(sum);
            }
        }
        pool(&out, width).into_iter().map(f64::sqrt).collect()
    }
}

/// The mean of `variance` over each pixel's 3×3 neighbourhood (within the
/// frame, `width` wide): 16 pilot samples rarely catch a rare bright path
/// (light through glass), so one pixel's own estimate is 0 or huge at
/// random, while its neighbours see the same light; pooled, the estimate
/// follows the region.
fn pool(variance: &[f64], width: usize) -> Vec<f64> {
    let height = variance.len() / width.max(1);
    let mut out = Vec::with_capacity(variance.len());
    for y in 0..height {
        for x in 0..width {
            let (mut sum, mut n) = (0.0, 0.0);
            for ny in y.saturating_sub(1)..(y + 2).min(height) {
                for nx in x.saturating_sub(1)..(x + 2).min(width) {
                    sum += variance[ny * width + nx];
                    n += 1.0;
                }
            }
            out.push(sum / n);
        }
    }
    out
}

/// Splits a budget of `spp` image samples per pixel among pixels whose
/// one-sample standard deviations are `sigma`: nᵢ = clamp(c·σᵢ, `least`,
/// `most`), rounded to [`quantize`]'s grid, with c such that the counts add up to the budget
/// (as near as the rounded counts can) — or every pixel at `least` (`most`) where even that
/// exceeds (falls short of) it.
pub fn allocate(sigma: &[f64], spp: u32, (least, most): (u32, u32)) -> Vec<u32> {
    let budget = f64::from(spp) * sigma.len() as f64;
    let (lo, hi) = (f64::from(least), f64::from(most));
    let count = |c: f64, s: f64| f64::from(quantize((c * s).clamp(lo, hi))).clamp(lo, hi);
    let spent = |c: f64| -> f64 { sigma.iter().map(|&s| count(c, s)).sum() };
    let c = if spent(0.0) >= budget {
        0.0
    } else {
        // spent(c) grows with c; find where it reaches the budget.
        let mut high = 1.0;
        while spent(high) < budget && high < 1e30 {
            high *= 2.0;
        }
        let mut low = 0.0;
        for _ in 0..64 {
            let mid = 0.5 * (low + high);
            if spent(mid) < budget {
                low = mid;
            } else {
                high = mid;
            }
        }
        // The rounded counts jump: take the side nearer the budget.
        if budget - spent(low) < spent(high) - budget {
            low
        } else {
            high
        }
    };
    sigma.iter().map(|&s| count(c, s) as u32).collect()
}

/// `n` rounded to one of four counts per octave (…, 16, 20, 24, 28, 32,
/// 40, …; exact below 8): few distinct counts make few cuts in
/// [`render_image`](super::adaptive::render_image), so its batches stay
/// large, and a count off by at most an eighth from the best one costs
/// under 2 % of the MSE (the optimum is flat: σ²/n near n* changes by
/// (n − n*)²/n*² to second order).
fn quantize(n: f64) -> u32 {
    let n = n.round().max(1.0) as u32;
    if n < 8 {
        return n;
    }
    let step = 1u32 << (n.ilog2() - 2);
    (n + step / 2) / step * step
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn counts_follow_sigma_and_spend_the_budget() {
        let sigma = [0.0, 1.0, 2.0, 4.0, 1.0, 0.0, 0.0, 0.0];
        let counts = allocate(&sigma, 64, (2, 10_000));
        // The budget, and σ's proportions, within the rounding to four
        // counts per octave (an eighth at most).
        let spent: u32 = counts.iter().sum();
        assert!(spent.abs_diff(64 * 8) <= 64, "{counts:?}");
        assert_eq!(counts[0], 2, "zero-σ pixels take the floor");
        let c = f64::from(counts[1]);
        for (k, ratio) in [(2, 2.0), (3, 4.0), (4, 1.0)] {
            let r = f64::from(counts[k]) / c;
            assert!((r / ratio - 1.0).abs() < 0.26, "{counts:?}");
        }
    }

    #[test]
    fn counts_are_four_per_octave() {
        assert_eq!(quantize(5.0), 5);
        assert_eq!(quantize(17.0), 16);
        assert_eq!(quantize(19.0), 20);
        assert_eq!(quantize(100.0), 96);
        assert_eq!(quantize(1000.0), 1024);
    }

    #[test]
    fn a_bright_flat_pixel_next_to_a_dark_one_counts_through_the_filter() {
        // Under filter importance sampling each pixel keeps its own samples:
        // a flat pixel has no error to lower wherever it is.
        let pilot = [
            Pilot {
                mean: 10.0,
                sigma: 0.0,
            },
            Pilot {
                mean: 0.0,
                sigma: 0.0,
            },
        ];
        let own = Footprint::own_pixel();
        assert_eq!(own.effective_sigma(&pilot, 2), [0.0, 0.0]);
        // Splatted with a tent of radius 1.5, the bright pixel's samples
        // land in its dark neighbour with random weights: both count.
        struct Tent;
        impl radiant_core::Filter for Tent {
            fn radius(&self) -> f32 {
                1.5
            }
            fn eval(&self, x: f32, y: f32) -> f32 {
                (1.5 - x.abs()).max(0.0) * (1.5 - y.abs()).max(0.0)
            }
        }
        let table = crate::film::FilterTable::new(&Tent);
        let splat = Footprint::new(&Reconstruction::Splat(table));
        let sigma = splat.effective_sigma(&pilot, 2);
        assert!(sigma.iter().all(|&s| s > 1.0), "{sigma:?}");
    }

    #[test]
    fn the_limits_bind() {
        // A single noisy pixel is held at the ceiling; the rest of the
        // budget is not spent (nowhere useful to put it).
        let counts = allocate(&[0.0, 0.0, 0.0, 5.0], 8, (1, 20));
        assert_eq!(counts, [1, 1, 1, 20]);
        // A flat image: every pixel at the budget... or the floor, if higher.
        assert_eq!(allocate(&[0.0; 4], 8, (1, 20)), [1; 4]);
        assert_eq!(allocate(&[1.0; 4], 8, (10, 20)), [10; 4]);
        assert_eq!(allocate(&[1.0; 4], 8, (1, 20)), [8; 4]);
        assert_eq!(allocate(&[1.0; 4], 100, (1, 2000)), [96; 4]);
    }

    #[test]
    fn defaults() {
        let a = Adaptive::default();
        assert_eq!(limits(&a, 64), (16, 1024));
        assert_eq!(limits(&a, 2), (1, 32));
        assert_eq!(pilot_samples(64), 16);
        assert_eq!(pilot_samples(8), 4);
        assert_eq!(pilot_samples(4096), 64);
    }
}
