//! Adaptive sampling for the tile integrators: each pixel stops taking
//! samples once its estimate has converged (`sampler: {adaptive: {…}}`).
//!
//! The rule is seed 002's (CS 184): every `batch` samples, a pixel whose
//! luminance estimate satisfies z·σ/√n ≤ threshold·μ stops, where z is the
//! normal quantile of `confidence` (1.96 for 0.95), σ the standard
//! deviation of one sample's luminance, n the pixel's image samples and μ
//! its mean. Two changes make it usable:
//!
//! * **Unbiased.** Stopping on the statistics of the very samples the
//!   image averages biases it: a pixel whose estimate happens to be high
//!   looks converged (σ/μ small) and stops, keeping the high value, while
//!   a low one goes on and is pulled back up. So the decision is made on
//!   *separate* samples: every round of image samples (sample indices
//!   0, 1, 2, … of the pixel; `min_spp` in the first, `batch` after) also
//!   renders a quarter as many decision samples (at least 2), drawn with sample indices from [`DECISION_BASE`] on
//!   (independent of the image's: samplers draw sample i from the seed,
//!   the pixel and i alone) and never added to the image. Given the
//!   decisions, the image's samples are independent draws, so the image
//!   is the fixed-spp estimator with a random but independent count (pbrt
//!   and Cycles decide on the image's own samples, or on half of them,
//!   and accept the bias). The decision samples cost a quarter more
//!   samples per round; `tests/adaptive.rs` checks that deciding on the
//!   image's own samples instead is caught by its bias test.
//! * **Robust.** μ is floored at [`MEAN_FLOOR`] (in luminance): without
//!   it, a pixel that is nearly black (where a relative error is invisible)
//!   would sample to `max_spp`. Nothing else is looked at: even "the image
//!   samples saw light the decision samples did not" would make the count
//!   depend on the image's values again. So a pixel lit by rare bright
//!   paths (a caustic) whose decision samples all missed them stops at
//!   `min_spp`, unbiased but noisy: raise `min_spp` for such scenes.
//!
//! * **Reconstruction, with splatting too.** The decisions never look at
//!   the image's samples, so a tile makes them first ([`decide`]: rounds
//!   of decision samples alone, each pixel's count of image samples
//!   following from them) and renders the image samples afterwards
//!   ([`render_image`]), each pixel's count known. A splatting filter
//!   mixes neighbours' samples into a pixel; with unequal counts a
//!   converged pixel's few samples would be outweighed by its neighbours'
//!   many (the edges of the Cornell box's light came out 10 % dark). So a
//!   pixel's samples are weighted by 1 / its count, value and filter
//!   weight both: every pixel then adds its filter-weighted mean to its
//!   neighbours, as at a fixed spp, and the film's ratio Σw·L / Σw has
//!   the fixed-spp expectation. Filter importance sampling keeps each
//!   pixel's samples in the pixel, where the weight cancels.
//!
//! * **In passes** (`--time`, `--checkpoint`, `--resume`, `--partition`):
//!   a render's first pass makes every tile's decisions and keeps the
//!   counts in the film ([`Film::adaptive_counts`](crate::film::Film));
//!   each pass of sample indices a..b of a render of `spp` then renders
//!   the same fraction of every pixel's samples ([`pass_share`]), so the
//!   passes together render each pixel's `0..count`, the samples of one
//!   whole render, and a film stopped after a pass holds about the same
//!   fraction of every pixel's samples (to within a block of 4), so that
//!   splatting weighs pixels alike in it too. The counts are not saved: a
//!   resumed render, or each partition, decides again (the decision
//!   samples depend on the scene and seed alone), the same counts at the
//!   cost of the decision samples once more.
//!
//! Pixels are independent, so a tile runs its rounds alone: its pixels'
//! counts and the decision statistics live in the tile. A round renders
//! the runs of still-active pixels of each tile row as one batch each; the
//! image samples are rendered by runs of pixels of equal count.

use super::module::{Batch, batches};
use radiant_core::{Rgb, luminance};
use serde::Deserialize;

/// First sample index of the decision samples: far above any image
/// sample index (`spp` is below 2^30 in practice), so the two never share
/// a sampler value.
pub const DECISION_BASE: u32 = 1 << 30;

/// Decision samples per round are `batch / DECISION_SHARE` (at least 2).
pub const DECISION_SHARE: u32 = 4;

/// Floor of the mean luminance in the relative test.
pub const MEAN_FLOOR: f64 = 1e-3;

/// Which error adaptive sampling lowers (`adaptive: {error: …}`).
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum ErrorGoal {
    /// Every pixel to `threshold` relative error, checked every `batch`
    /// samples (seed 002's rule; `spp` is the most a pixel takes).
    #[default]
    Relative,
    /// The least mean squared error for `spp` samples per pixel on
    /// average: one pilot round, then each pixel's samples in proportion
    /// to its σ ([`super::budget`]).
    Mse,
}

/// `sampler: {adaptive: {error, threshold, confidence, batch, min_spp,
/// max_spp}}`.
#[derive(Debug, Clone, Copy, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Adaptive {
    /// The error to lower: `relative` (the default) or `mse`.
    #[serde(default)]
    pub error: ErrorGoal,
    /// Relative error at which a pixel stops: the confidence interval's
    /// half-width over the mean.
    #[serde(default = "default_threshold")]
    pub threshold: f64,
    /// Confidence of that interval (0.5–0.9999).
    #[serde(default = "default_confidence")]
    pub confidence: f64,
    /// Image samples between two checks of a pixel (a multiple of 4).
    #[serde(default = "default_batch")]
    pub batch: u32,
    /// Samples every pixel takes before the first check (default: `batch`;
    /// rounded up to a multiple of `batch`); under `error: mse` the least
    /// a pixel takes (default `spp` / 4).
    #[serde(default)]
    pub min_spp: Option<u32>,
    /// Samples a pixel takes at most (default: the sampler's `spp`; under
    /// `error: mse` 16 · `spp`).
    #[serde(default)]
    pub max_spp: Option<u32>,
}

// The loader checks that the numbers are finite (no NaN), so equality is
// an equivalence.
impl Eq for Adaptive {}

fn default_threshold() -> f64 {
    0.05
}

fn default_confidence() -> f64 {
    0.95
}

fn default_batch() -> u32 {
    64
}

impl Default for Adaptive {
    fn default() -> Self {
        Self {
            error: ErrorGoal::Relative,
            threshold: default_threshold(),
            confidence: default_confidence(),
            batch: default_batch(),
            min_spp: None,
            max_spp: None,
        }
    }
}

impl Adaptive {
    /// What is wrong with these values, naming the key, if anything.
    pub fn check(&self) -> Result<(), (&'static str, String)> {
        if !(self.threshold > 0.0 && self.threshold.is_finite()) {
            return Err((
                "threshold",
                format!(
                    "adaptive threshold must be a positive relative error (0.05 = 5 %), found {}",
                    self.threshold
                ),
            ));
        }
        if !(0.5..=0.9999).contains(&self.confidence) {
            return Err((
                "confidence",
                format!(
                    "adaptive confidence must be between 0.5 and 0.9999, found {}",
                    self.confidence
                ),
            ));
        }
        if self.batch < 4 || !self.batch.is_multiple_of(4) || self.batch > 1 << 16 {
            return Err((
                "batch",
                format!(
                    "adaptive batch must be a multiple of 4 from 4 to 65536 samples, found {}",
                    self.batch
                ),
            ));
        }
        for (key, v) in [("min_spp", self.min_spp), ("max_spp", self.max_spp)] {
            if v == Some(0) {
                return Err((key, format!("adaptive {key} must be at least 1, found 0")));
            }
        }
        if let (Some(lo), Some(hi)) = (self.min_spp, self.max_spp)
            && lo > hi
        {
            return Err((
                "min_spp",
                format!("adaptive min_spp ({lo}) must not exceed max_spp ({hi})"),
            ));
        }
        Ok(())
    }

    /// z, the standard normal quantile of the two-sided `confidence`.
    pub fn z(&self) -> f64 {
        normal_quantile(0.5 + self.confidence / 2.0)
    }

    /// (first check, most samples) for a render of `spp` samples: the
    /// first check after `min_spp` rounded up to whole batches (and no
    /// more than the most), the most `max_spp` or `spp`.
    pub fn limits(&self, spp: u32) -> (u32, u32) {
        let most = self.max_spp.unwrap_or(spp).max(1);
        let first = self.min_spp.unwrap_or(self.batch).div_ceil(self.batch) * self.batch;
        (first.min(most), most)
    }
}

/// Decision samples for a round of `image` image samples: a
/// [`DECISION_SHARE`]th of them, at least 2 (the variance needs two).
pub fn decision_samples(image: u32) -> u32 {
    (image / DECISION_SHARE).max(2)
}

/// The standard normal quantile Φ⁻¹(p) for p in (0, 1) (Acklam's rational
/// approximation, relative error below 1.2e-9).
pub fn normal_quantile(p: f64) -> f64 {
    const A: [f64; 6] = [
        -3.969683028665376e1,
        2.209460984245205e2,
        -2.759285104469687e2,
        1.383_577_518_672_69e2,
        -3.066479806614716e1,
        2.506628277459239,
    ];
    const B: [f64; 5] = [
        -5.447609879822406e1,
        1.615858368580409e2,
        -1.556989798598866e2,
        6.680131188771972e1,
        -1.328068155288572e1,
    ];
    const C: [f64; 6] = [
        -7.784894002430293e-3,
        -3.223964580411365e-1,
        -2.400758277161838,
        -2.549732539343734,
        4.374664141464968,
        2.938163982698783,
    ];
    const D: [f64; 4] = [
        7.784695709041462e-3,
        3.224671290700398e-1,
        2.445134137142996,
        3.754408661907416,
    ];
    let low = 0.02425;
    if p < low {
        let q = (-2.0 * p.ln()).sqrt();
        (((((C[0] * q + C[1]) * q + C[2]) * q + C[3]) * q + C[4]) * q + C[5])
            / ((((D[0] * q + D[1]) * q + D[2]) * q + D[3]) * q + 1.0)
    } else if p > 1.0 - low {
        -normal_quantile(1.0 - p)
    } else {
        let q = p - 0.5;
        let r = q * q;
        (((((A[0] * r + A[1]) * r + A[2]) * r + A[3]) * r + A[4]) * r + A[5]) * q
            / (((((B[0] * r + B[1]) * r + B[2]) * r + B[3]) * r + B[4]) * r + 1.0)
    }
}

/// One pixel's running sums of sample luminance.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct Moments {
    /// Samples.
    pub n: u32,
    /// Σ x.
    pub sum: f64,
    /// Σ x².
    pub sum_sq: f64,
}

impl Moments {
    /// Adds a sample of luminance `x`.
    #[inline]
    pub fn add(&mut self, x: f64) {
        self.n += 1;
        self.sum += x;
        self.sum_sq += x * x;
    }

    /// The mean.
    pub fn mean(&self) -> f64 {
        self.sum / f64::from(self.n.max(1))
    }

    /// The unbiased sample variance (0 below two samples).
    pub fn variance(&self) -> f64 {
        if self.n < 2 {
            return 0.0;
        }
        let n = f64::from(self.n);
        ((self.sum_sq - self.sum * self.sum / n) / (n - 1.0)).max(0.0)
    }
}

/// Whether a pixel has converged: the decision samples' statistics
/// `decision` say that the mean of `image_samples` image samples is within
/// `threshold` (relative, μ floored at [`MEAN_FLOOR`]) at quantile `z`.
pub fn converged(decision: &Moments, image_samples: u32, z: f64, threshold: f64) -> bool {
    let mean = decision.mean();
    let half_width = z * decision.variance().sqrt() / f64::from(image_samples.max(1)).sqrt();
    half_width <= threshold * mean.max(MEAN_FLOOR)
}

/// A tile's rectangle [x0, x1) × [y0, y1) in a frame `width` pixels wide.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct TileRect {
    /// See [`Batch`].
    pub x0: u32,
    /// See [`Batch`].
    pub y0: u32,
    /// See [`Batch`].
    pub x1: u32,
    /// See [`Batch`].
    pub y1: u32,
    /// The frame's width.
    pub width: u32,
}

impl TileRect {
    /// Pixels in the tile.
    pub fn len(&self) -> usize {
        ((self.x1 - self.x0) * (self.y1 - self.y0)) as usize
    }

    /// Whether the tile has no pixels.
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// The row-major index in the tile of frame pixel `pixel` (its
    /// row-major index in the frame), which must lie in the tile.
    #[inline]
    pub fn index(&self, pixel: u32) -> usize {
        let (x, y) = (pixel % self.width, pixel / self.width);
        ((y - self.y0) * (self.x1 - self.x0) + x - self.x0) as usize
    }
}

/// Decides how many image samples each pixel of tile `t` takes in a
/// render of `spp` samples per pixel, by rounds of decision samples alone:
/// `render(batch, on_sample)` renders a batch of decision samples (which
/// must not reach the image) and reports each sample's value by pixel.
/// The image samples never enter the decision, so they can be rendered
/// afterwards, each pixel's count known ([`render_image`]). Returns the
/// counts, row-major in the tile.
pub fn decide(
    a: &Adaptive,
    spp: u32,
    t: TileRect,
    mut render: impl FnMut(Batch, &mut dyn FnMut(u32, Rgb)),
) -> Vec<u32> {
    let len = t.len();
    let mut decision = vec![Moments::default(); len];
    let mut counts = vec![0u32; len];
    let mut active = vec![true; len];
    let (first, most) = a.limits(spp);
    let z = a.z();
    let (mut n, mut decided) = (0, 0);
    loop {
        let target = if n == 0 {
            first
        } else {
            (n + a.batch).min(most)
        };
        let per_round = decision_samples(target - n);
        let samples = DECISION_BASE + decided..DECISION_BASE + decided + per_round;
        for_runs(&active, t, samples, &mut |b| {
            render(b, &mut |p, v| decision[t.index(p)].add(sample_luminance(v)))
        });
        decided += per_round;
        for (c, _) in counts.iter_mut().zip(&active).filter(|(_, a)| **a) {
            *c = target;
        }
        n = target;
        if n >= most {
            break;
        }
        let mut any = false;
        for (on, d) in active.iter_mut().zip(&decision) {
            *on = *on && !converged(d, n, z, a.threshold);
            any |= *on;
        }
        if !any {
            break;
        }
    }
    counts
}

/// Renders the image samples of tile `t` whose pixels take `counts`
/// samples (from [`decide`]): of a pixel taking `c`, the sample indices
/// `samples(c)`. `render(batch, c)` renders a batch whose pixels all take
/// `c` (a splatting film weights their samples by 1/`c`, see
/// `backend/cpu.rs`). Rendering each count's pixels on their own keeps the
/// film's blocks of sample indices the same in passes as in one render
/// (see [`pass_share`]).
pub fn render_image(
    counts: &[u32],
    t: TileRect,
    samples: impl Fn(u32) -> std::ops::Range<u32>,
    mut render: impl FnMut(Batch, u32),
) {
    let mut classes = counts.to_vec();
    classes.sort_unstable();
    classes.dedup();
    let mut members = vec![false; counts.len()];
    for c in classes {
        let range = samples(c);
        if range.is_empty() {
            continue;
        }
        for (m, &n) in members.iter_mut().zip(counts) {
            *m = n == c;
        }
        for_runs(&members, t, range, &mut |b| render(b, c));
    }
}

/// The part of a pixel's `count` image samples that the pass of sample
/// indices `pass` (of a render of `spp` per pixel) renders: the same
/// fraction of every pixel's samples, so that after each pass every pixel
/// holds about that fraction of its samples, its ends rounded down to
/// whole blocks of [`BLOCK`](crate::film::exact::BLOCK) samples (so the
/// film's exact sums do not depend on where passes start); the pass that
/// ends at `spp` ends at `count`. A whole render's one pass `0..spp`
/// renders `0..count`.
pub fn pass_share(pass: &std::ops::Range<u32>, spp: u32, count: u32) -> std::ops::Range<u32> {
    let block = crate::film::exact::BLOCK;
    let end = |x: u32| {
        if x >= spp {
            count
        } else {
            (u64::from(x) * u64::from(count) / u64::from(spp.max(1))) as u32 / block * block
        }
    };
    end(pass.start)..end(pass.end)
}

/// Cuts the sample indices `samples` of the active pixels of tile `t`
/// into [`batches`]: the whole tile where every
/// pixel is active, else each row's runs of active pixels.
fn for_runs(
    active: &[bool],
    t: TileRect,
    samples: std::ops::Range<u32>,
    render: &mut dyn FnMut(Batch),
) {
    let tw = (t.x1 - t.x0) as usize;
    let mut rect = |x0: u32, y0: u32, x1: u32, y1: u32| {
        for batch in batches((x0, y0, x1, y1), samples.clone()) {
            render(batch);
        }
    };
    if active.iter().all(|a| *a) {
        rect(t.x0, t.y0, t.x1, t.y1);
        return;
    }
    for (row, y) in active.chunks(tw.max(1)).zip(t.y0..) {
        let mut x = 0;
        while x < row.len() {
            if !row[x] {
                x += 1;
                continue;
            }
            let start = x;
            while x < row.len() && row[x] {
                x += 1;
            }
            rect(t.x0 + start as u32, y, t.x0 + x as u32, y + 1);
        }
    }
}

/// The luminance a sample's value is judged by (negative values, which
/// no built-in module produces, count as black).
#[inline]
pub fn sample_luminance(value: Rgb) -> f64 {
    if value.is_finite() {
        f64::from(luminance(value)).max(0.0)
    } else {
        0.0
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn quantiles_match_the_table() {
        for (p, z) in [(0.975, 1.959_963_985), (0.5, 0.0), (0.995, 2.575_829_304)] {
            assert!((normal_quantile(p) - z).abs() < 1e-8, "{p}");
        }
        assert!((normal_quantile(0.01) + 2.326_347_874).abs() < 1e-8);
        assert!((Adaptive::default().z() - 1.959_963_985).abs() < 1e-8);
    }

    #[test]
    fn the_rule_stops_flat_pixels_and_keeps_noisy_ones() {
        let z = 1.96;
        let mut flat = Moments::default();
        let mut noisy = Moments::default();
        for i in 0..16 {
            flat.add(0.5);
            noisy.add(if i % 4 == 0 { 2.0 } else { 0.0 });
        }
        assert!(converged(&flat, 64, z, 0.05));
        assert!(!converged(&noisy, 64, z, 0.05));
        // σ = √(16/15·0.75) ≈ 0.894, μ = 0.5: converged from n ≥ (z·σ/(0.05·μ))² ≈ 4913.
        assert!(!converged(&noisy, 4800, z, 0.05));
        assert!(converged(&noisy, 5000, z, 0.05));
        // Near-black pixels are judged against the floor, not their mean.
        let dim = Moments {
            n: 16,
            sum: 16e-6,
            sum_sq: 32e-12,
        };
        assert!(converged(&dim, 64, z, 0.05));
    }

    #[test]
    fn bad_values_name_their_key() {
        let bad = [
            (
                Adaptive {
                    threshold: 0.0,
                    ..Adaptive::default()
                },
                "threshold",
            ),
            (
                Adaptive {
                    threshold: f64::NAN,
                    ..Adaptive::default()
                },
                "threshold",
            ),
            (
                Adaptive {
                    confidence: 1.0,
                    ..Adaptive::default()
                },
                "confidence",
            ),
            (
                Adaptive {
                    batch: 6,
                    ..Adaptive::default()
                },
                "batch",
            ),
            (
                Adaptive {
                    max_spp: Some(0),
                    ..Adaptive::default()
                },
                "max_spp",
            ),
            (
                Adaptive {
                    min_spp: Some(128),
                    max_spp: Some(64),
                    ..Adaptive::default()
                },
                "min_spp",
            ),
        ];
        for (a, key) in bad {
            assert_eq!(a.check().map_err(|e| e.0), Err(key), "{a:?}");
        }
        assert_eq!(Adaptive::default().check(), Ok(()));
        let a = Adaptive {
            min_spp: Some(100),
            ..Adaptive::default()
        };
        assert_eq!(a.limits(1024), (128, 1024));
        assert_eq!(a.limits(32), (32, 32));
    }
}
