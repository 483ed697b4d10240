//! Error metrics of one render against the reference, and the split of its
//! error into bias and variance.
//!
//! Every setting is rendered as two independent halves (two sampler seeds),
//! and so is a reference made by `radiant accuracy`. The halves give the
//! variance of the combined image at every pixel without a model of the
//! noise: for independent halves A and B of equal variance, the image
//! I = (A + B)/2 has Var(I) = E[(A − B)²]/4. What the mean squared error
//! has beyond the variances of the image and of the reference is bias.
//!
//! The bias test works on block means, where noise averages out and bias
//! does not. Per block, D = mean(I − R) and H = mean((A − B)/2 +
//! (R_A − R_B)/2) have the same variance when the halves are independent
//! and alike — whatever the sampler (independent or quasi-random), the
//! pixel filter's correlation of neighbours or the shape of the noise — so
//! E[D²] = Var + bias² while E[H²] = Var. The test statistic z² is
//! Σ w·D² / Σ w·H², each block weighted by the inverse of its pixels' noise
//! (w = 1/Σ h², h the per-pixel half differences), so that a few noisy
//! blocks (fireflies) do not outweigh the rest; the threshold comes from the
//! effective number of blocks of the weighted ΣH². The share
//! of bias it reports, 1 − threshold/z², is the part of the block-mean
//! differences that noise cannot explain at the test's confidence: above
//! zero exactly when the setting is called biased.
//!
//! A setting may render without noise where the halves agree bit for bit
//! (a constant sky seen directly, or the whole image: a path length that
//! stops every path before it samples anything). Such a block's D is then
//! exact and H is zero, so each block's noise has a floor,
//! [`PRECISION`] of the block's level: the precision of a reference read
//! from a file (a half-float EXR rounds to 5·10⁻⁴). Without it a
//! noise-free image had no block to test and was never called biased
//! however far it was from the reference.

use crate::compare::compare;
use crate::film::Image;
use crate::film::output::to_srgb8;

/// Smallest block edge of the bias test: enough pixels per block for the
/// block means to average noise.
const MIN_BLOCK: u32 = 8;

/// One-sided normal quantile of the bias test: a false "biased" about once
/// in 4000 unbiased measurements (for Gaussian block means).
const BIAS_TEST_Z: f64 = 3.5;

/// Smallest threshold of the bias test's ratio, for images with so many
/// blocks that a bias far below the noise would be flagged.
const MIN_BIAS_THRESHOLD: f64 = 1.25;

/// Relative precision of a block mean: differences from the reference
/// below this fraction of the block's level (mean |value| of the image and
/// the reference) are taken as rounding, not bias. Above a half-float EXR's
/// rounding (2⁻¹¹ ≈ 4.9·10⁻⁴ of the value).
pub const PRECISION: f64 = 1e-3;

/// How far an image is from the reference.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Metrics {
    /// Root-mean-square error over pixels and channels.
    pub rmse: f64,
    /// Mean of (a − r)² / (r² + 0.01).
    pub rel_mse: f64,
    /// Mean absolute error over pixels and channels.
    pub mae: f64,
    /// Mean LDR-FLIP error (NVIDIA's perceptual metric, 0 = identical, 1 =
    /// most different) of the images tone-mapped as PNG output is: clamped,
    /// sRGB, 8 bit; at 67 pixels per degree (a 0.7 m distance from a 24"
    /// 4K screen, FLIP's default).
    pub flip: f64,
}

/// Measures `image` against `reference`; `None` if their sizes differ.
pub fn metrics(image: &Image, reference: &Image) -> Option<Metrics> {
    let c = compare(image, reference)?;
    let n = (image.pixels.len() * 3).max(1) as f64;
    let mae = image
        .pixels
        .iter()
        .zip(&reference.pixels)
        .map(|(a, r)| {
            (*a - *r)
                .abs()
                .to_array()
                .iter()
                .map(|&d| d as f64)
                .sum::<f64>()
        })
        .sum::<f64>()
        / n;
    Some(Metrics {
        rmse: c.rmse,
        rel_mse: c.relative_mse,
        mae,
        flip: flip(image, reference),
    })
}

fn flip_image(image: &Image) -> nv_flip::FlipImageRgb8 {
    nv_flip::FlipImageRgb8::with_data(image.width, image.height, &to_srgb8(image))
}

/// Mean LDR-FLIP error of `image` against `reference` (same size).
pub fn flip(image: &Image, reference: &Image) -> f64 {
    mean_flip(&flip_map(image, reference))
}

/// Per-pixel LDR-FLIP error of `image` against `reference` (same size),
/// both shown as clamped 8-bit sRGB.
pub fn flip_map(image: &Image, reference: &Image) -> nv_flip::FlipImageFloat {
    nv_flip::flip(
        flip_image(reference),
        flip_image(image),
        nv_flip::DEFAULT_PIXELS_PER_DEGREE,
    )
}

/// The mean of a FLIP error map.
pub fn mean_flip(map: &nv_flip::FlipImageFloat) -> f64 {
    nv_flip::FlipPool::from_image(map).mean() as f64
}

/// Two independent renders of the same setting with the same samples per
/// pixel each.
#[derive(Debug, Clone, Copy)]
pub struct Halves<'a> {
    /// The first half (one sampler seed).
    pub a: &'a Image,
    /// The second half (another seed).
    pub b: &'a Image,
}

impl Halves<'_> {
    /// The combined image (A + B)/2.
    pub fn combined(&self) -> Image {
        Image {
            width: self.a.width,
            height: self.a.height,
            pixels: self
                .a
                .pixels
                .iter()
                .zip(&self.b.pixels)
                .map(|(a, b)| (*a + *b) * 0.5)
                .collect(),
        }
    }

    /// Variance of the combined image, averaged over pixels and channels:
    /// mean((A − B)²)/4.
    pub fn variance(&self) -> f64 {
        let n = (self.a.pixels.len() * 3).max(1) as f64;
        self.a
            .pixels
            .iter()
            .zip(&self.b.pixels)
            .map(|(a, b)| (*a - *b).length_squared() as f64)
            .sum::<f64>()
            / (4.0 * n)
    }
}

/// The bias/variance split of one measurement.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct BiasSplit {
    /// Variance of the image (mean over pixels and channels).
    pub variance: f64,
    /// Mean squared error less the variances of image and reference: the
    /// squared bias per pixel and channel (may come out slightly negative
    /// for an unbiased setting).
    pub bias2: f64,
    /// Σ D² / Σ H² over pixel blocks: the squared block-mean differences
    /// from the reference over what the halves say noise alone gives
    /// (see the module's documentation): about 1 without bias.
    pub block_z2: f64,
    /// The value of [`block_z2`](Self::block_z2) above which the setting is
    /// called biased, for the effective number of blocks of ΣH².
    pub threshold: f64,
}

impl BiasSplit {
    /// The share of bias in the block-mean differences from the reference
    /// that noise cannot explain at the test's confidence,
    /// 1 − threshold/z² (0 within the noise): above 0 exactly when
    /// [`is_biased`](Self::is_biased).
    pub fn bias_share(&self) -> f64 {
        if self.block_z2 > self.threshold {
            1.0 - self.threshold / self.block_z2
        } else {
            0.0
        }
    }

    /// Whether the block means differ from the reference beyond their
    /// noise.
    pub fn is_biased(&self) -> bool {
        self.block_z2 > self.threshold
    }
}

/// The threshold of the ratio test over `blocks` effective blocks: ln of a
/// ratio of two χ²ₙ/n has variance about 4/n, so exp(z·2/√n), at least
/// [`MIN_BIAS_THRESHOLD`].
pub fn bias_threshold(blocks: f64) -> f64 {
    (BIAS_TEST_Z * 2.0 / blocks.max(1.0).sqrt())
        .exp()
        .max(MIN_BIAS_THRESHOLD)
}

/// Kish's effective number of terms of a sum of non-negative `terms`:
/// (Σ t)² / Σ t², the count of equal terms that would spread as much.
fn effective_count(terms: impl Iterator<Item = f64> + Clone) -> f64 {
    let sum: f64 = terms.clone().sum();
    let squares: f64 = terms.map(|t| t * t).sum();
    if squares > 0.0 {
        sum * sum / squares
    } else {
        1.0
    }
}

/// Splits the error of `image` (given as halves) against `reference` (with
/// its halves if it was rendered here, or `None` for an outside reference
/// assumed noise-free) into variance and bias, and tests for bias over
/// blocks of 1/16 of the image's smaller side (at least 8 pixels).
pub fn bias_split(
    image: Halves<'_>,
    reference: &Image,
    ref_halves: Option<Halves<'_>>,
) -> BiasSplit {
    let combined = image.combined();
    let n = (combined.pixels.len() * 3).max(1) as f64;
    let mse = combined
        .pixels
        .iter()
        .zip(&reference.pixels)
        .map(|(a, r)| (*a - *r).length_squared() as f64)
        .sum::<f64>()
        / n;
    let variance = image.variance();
    let ref_variance = ref_halves.map_or(0.0, |h| h.variance());
    let (w, h) = (combined.width, combined.height);
    let block = (w.min(h) / 16).max(MIN_BLOCK);
    let (bw, bh) = (w.div_ceil(block), h.div_ceil(block));
    let nb = (bw * bh) as usize;
    // Per block and channel: Σ (I − R), Σ half differences, and the count.
    let mut d = vec![[0.0f64; 3]; nb];
    let mut half = vec![[0.0f64; 3]; nb];
    let mut count = vec![0u32; nb];
    let mut pixel_var = vec![0.0f64; nb];
    let mut level = vec![0.0f64; nb];
    for y in 0..h {
        for x in 0..w {
            let i = (y * w + x) as usize;
            let b = ((y / block) * bw + x / block) as usize;
            let di = combined.pixels[i] - reference.pixels[i];
            let hi = (image.a.pixels[i] - image.b.pixels[i]) * 0.5;
            let hr = ref_halves.map_or(radiant_core::Rgb::ZERO, |r| {
                (r.a.pixels[i] - r.b.pixels[i]) * 0.5
            });
            for c in 0..3 {
                d[b][c] += di[c] as f64;
                half[b][c] += (hi[c] + hr[c]) as f64;
                pixel_var[b] += (hi[c] as f64).powi(2) + (hr[c] as f64).powi(2);
                level[b] +=
                    0.5 * f64::from(combined.pixels[i][c].abs() + reference.pixels[i][c].abs());
            }
            count[b] += 1;
        }
    }
    // Per block, the squared block means summed over the channels plus
    // (for H) the precision floor's variance, each weighted by the inverse
    // of its pixels' summed squared half differences with the floor added
    // in the same units (count² times the block mean's); blocks with
    // neither noise nor light are left out: their D is zero.
    let floor: Vec<f64> = level
        .iter()
        .zip(&count)
        .map(|(l, &c)| 3.0 * (PRECISION * l / f64::from(3 * c.max(1))).powi(2))
        .collect();
    let weighted = |sums: &[[f64; 3]], with_floor: bool| -> Vec<f64> {
        sums.iter()
            .zip(&count)
            .zip(pixel_var.iter().zip(&floor))
            .map(|((s, &c), (v, f))| {
                let c = f64::from(c.max(1));
                let v = v + c * c * f;
                let m2: f64 = s.iter().map(|x| (x / c).powi(2)).sum();
                (m2 + if with_floor { *f } else { 0.0 }, v)
            })
            .filter(|(_, v)| *v > 0.0)
            .map(|(m2, v)| m2 / v)
            .collect()
    };
    let (d2, h2) = (weighted(&d, false), weighted(&half, true));
    let (sd, sh): (f64, f64) = (d2.iter().sum(), h2.iter().sum());
    let block_z2 = if sh > 0.0 {
        sd / sh
    } else if sd > 0.0 {
        f64::INFINITY
    } else {
        1.0
    };
    BiasSplit {
        variance,
        bias2: mse - variance - ref_variance,
        block_z2,
        threshold: bias_threshold(effective_count(h2.iter().copied())),
    }
}

#[cfg(test)]
mod tests {
    // `unwrap` in this test code is the assertion: the inputs are the test's
    // own, so a failure is a bug, and the panic reports it with the error.
    use super::*;
    use radiant_core::Rgb;

    fn image(w: u32, h: u32, f: impl Fn(u32, u32) -> Rgb) -> Image {
        Image {
            width: w,
            height: h,
            pixels: (0..h)
                .flat_map(|y| (0..w).map(move |x| (x, y)))
                .map(|(x, y)| f(x, y))
                .collect(),
        }
    }

    #[test]
    fn metrics_match_hand_computed_values() {
        // Differences per channel: pixel 0 (0, 0, 0), pixel 1 (2, −1, 0.5).
        let r = image(2, 1, |_, _| Rgb::new(1.0, 2.0, 0.5));
        let a = image(2, 1, |x, _| {
            if x == 0 {
                Rgb::new(1.0, 2.0, 0.5)
            } else {
                Rgb::new(3.0, 1.0, 1.0)
            }
        });
        let m = metrics(&a, &r).unwrap();
        assert!((m.rmse - (5.25f64 / 6.0).sqrt()).abs() < 1e-12);
        assert!((m.mae - 3.5 / 6.0).abs() < 1e-12);
        let rel = 4.0 / 1.01 + 1.0 / 4.01 + 0.25 / 0.26;
        assert!((m.rel_mse - rel / 6.0).abs() < 1e-9);
        assert_eq!(m.flip, flip(&a, &r));
        assert!(metrics(&a, &image(1, 1, |_, _| Rgb::ONE)).is_none());
    }

    #[test]
    fn flip_is_zero_for_equal_images_and_grows_with_the_difference() {
        let r = image(32, 32, |x, y| Rgb::splat(((x + y) % 7) as f32 / 7.0));
        assert_eq!(flip(&r, &r), 0.0);
        let slightly = image(32, 32, |x, y| r.pixels[(y * 32 + x) as usize] * 0.95);
        let very = image(32, 32, |x, y| r.pixels[(y * 32 + x) as usize] * 0.3);
        let (s, v) = (flip(&slightly, &r), flip(&very, &r));
        assert!(0.0 < s && s < v && v <= 1.0, "{s} {v}");
    }

    #[test]
    fn variance_and_bias_of_hand_made_halves() {
        // Reference 1; half A = 1 + β + e everywhere, half B = 1 + β − e on
        // even and 1 + β + e on odd pixels (e = 0.5). Variance estimate:
        // mean((A − B)²)/4 = ((2e)²/4 + 0)/2 = 0.125. MSE of the combined
        // image: (β² + (β + e)²)/2, so bias² = β² + βe.
        let r = image(32, 32, |_, _| Rgb::ONE);
        let halves = |beta: f32| {
            let a = image(32, 32, |_, _| Rgb::splat(1.5 + beta));
            let b = image(32, 32, |x, y| {
                Rgb::splat(if (x + y) % 2 == 0 { 0.5 } else { 1.5 } + beta)
            });
            (a, b)
        };
        for (beta, bias2) in [(0.0, 0.0), (0.1, 0.06)] {
            let (a, b) = halves(beta);
            let s = bias_split(Halves { a: &a, b: &b }, &r, None);
            assert!((s.variance - 0.125).abs() < 1e-9);
            assert!((s.bias2 - bias2).abs() < 1e-6, "{beta}: {}", s.bias2);
        }
        // The reference's own variance is subtracted as well.
        let (a, b) = halves(0.0);
        let s = bias_split(Halves { a: &a, b: &b }, &r, Some(Halves { a: &a, b: &b }));
        assert!((s.bias2 + 0.125).abs() < 1e-9);
    }

    /// Independent noise in [−0.5, 0.5), blurred over `blur` neighbours in
    /// x the way a pixel filter correlates neighbours.
    fn noisy(reference: &Image, seed: u32, offset: f32, blur: u32) -> Image {
        let w = reference.width;
        let noise = |x: u32, y: u32, c: u32| {
            radiant_core::hash::unit_float(radiant_core::hash::hash4(seed, x, y, c)) - 0.5
        };
        image(w, reference.height, |x, y| {
            let mut n = Rgb::ZERO;
            for k in 0..blur {
                let xx = (x + k).min(w - 1);
                n += Rgb::new(noise(xx, y, 0), noise(xx, y, 1), noise(xx, y, 2));
            }
            reference.pixels[(y * w + x) as usize] + n / blur as f32 + Rgb::splat(offset)
        })
    }

    #[test]
    fn block_test_tells_bias_from_correlated_noise() {
        let r = image(128, 128, |x, y| {
            Rgb::splat(1.0 + ((x / 9 + y / 5) % 3) as f32)
        });
        for blur in [1, 4] {
            let (a, b) = (noisy(&r, 1, 0.0, blur), noisy(&r, 2, 0.0, blur));
            let unbiased = bias_split(Halves { a: &a, b: &b }, &r, None);
            assert!(
                (0.75..1.3).contains(&unbiased.block_z2),
                "blur {blur}: {unbiased:?}"
            );
            assert!(!unbiased.is_biased() && unbiased.bias_share() == 0.0);
            // An offset of half the per-pixel noise is found.
            let sd = unbiased.variance.sqrt() as f32;
            let (a, b) = (noisy(&r, 1, 0.5 * sd, blur), noisy(&r, 2, 0.5 * sd, blur));
            let biased = bias_split(Halves { a: &a, b: &b }, &r, None);
            assert!(biased.block_z2 > 3.0, "blur {blur}: {biased:?}");
            // The verdict and the share agree: most of the block-mean
            // difference is the offset.
            assert!(
                biased.is_biased() && biased.bias_share() > 0.5,
                "{biased:?}"
            );
        }
    }

    #[test]
    fn a_noise_free_image_is_tested_against_the_reference_precision() {
        // Both halves alike bit for bit, as where a setting stops every path
        // before it samples anything: 10 % off the reference is biased
        // (before the precision floor no block had noise, z² fell back to
        // 1 and the threshold to e⁷, and it passed), a reference's
        // half-float rounding (±4.9·10⁻⁴ of the value) is not.
        let r = image(64, 64, |x, y| {
            Rgb::new(0.15, 0.2, 0.3) * (1.0 + ((x / 5 + y / 3) % 4) as f32)
        });
        let scaled = |f: &dyn Fn(u32, u32) -> f32| {
            image(64, 64, |x, y| r.pixels[(y * 64 + x) as usize] * f(x, y))
        };
        let dark = scaled(&|_, _| 0.9);
        let s = bias_split(Halves { a: &dark, b: &dark }, &r, None);
        assert!(s.is_biased() && s.bias_share() > 0.99, "{s:?}");
        let black = scaled(&|_, _| 0.0);
        let s = bias_split(
            Halves {
                a: &black,
                b: &black,
            },
            &r,
            None,
        );
        assert!(s.is_biased() && s.bias_share() > 0.99, "{s:?}");
        let rounded = scaled(&|x, y| 1.0 + 4.9e-4 * if (x + y) % 2 == 0 { 1.0 } else { -1.0 });
        let s = bias_split(
            Halves {
                a: &rounded,
                b: &rounded,
            },
            &r,
            None,
        );
        assert!(!s.is_biased(), "{s:?}");
        let same = bias_split(Halves { a: &r, b: &r }, &r, None);
        assert!(!same.is_biased() && same.block_z2 == 0.0, "{same:?}");
        // Noise-free where the image is a constant sky, noisy elsewhere:
        // unbiased, and an offset of the noisy part is still found.
        for (offset, biased) in [(0.0, false), (1.0, true)] {
            let half = |seed| {
                let n = noisy(&r, seed, offset, 1);
                image(64, 64, |x, y| {
                    let i = (y * 64 + x) as usize;
                    if x < 32 { r.pixels[i] } else { n.pixels[i] }
                })
            };
            let (a, b) = (half(1), half(2));
            let s = bias_split(Halves { a: &a, b: &b }, &r, None);
            assert_eq!(s.is_biased(), biased, "offset {offset}: {s:?}");
        }
    }

    #[test]
    fn the_threshold_falls_with_the_number_of_blocks_and_the_share_agrees() {
        assert!(bias_threshold(16.0) > bias_threshold(64.0));
        assert!(bias_threshold(64.0) > bias_threshold(10_000.0));
        assert_eq!(bias_threshold(1e6), MIN_BIAS_THRESHOLD);
        assert_eq!(effective_count([2.0, 2.0, 2.0, 2.0].into_iter()), 4.0);
        // One term carrying nearly everything counts about once.
        assert!(effective_count([100.0, 0.1, 0.1, 0.1].into_iter()) < 1.01);
        for z2 in [0.5, 1.0, 1.4, 1.5, 1.6, 3.0, 50.0] {
            let s = BiasSplit {
                variance: 1.0,
                bias2: 0.0,
                block_z2: z2,
                threshold: 1.5,
            };
            assert_eq!(s.is_biased(), s.bias_share() > 0.0, "{z2}");
        }
    }
}
