//! Image comparison metrics, for `radiant compare` and the tests.

use crate::film::Image;

/// How two images differ.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Comparison {
    /// Root-mean-square error over all pixels and channels.
    pub rmse: f64,
    /// Mean of (a − b)² / (b² + 0.01) (relative MSE as in the denoising literature).
    pub relative_mse: f64,
    /// mean(a) / mean(b).
    pub mean_ratio: f64,
}

/// Compares `a` against the reference `b`; `None` if their sizes differ.
pub fn compare(a: &Image, b: &Image) -> Option<Comparison> {
    if (a.width, a.height) != (b.width, b.height) {
        return None;
    }
    let n = (a.pixels.len() * 3).max(1) as f64;
    let (mut se, mut rel) = (0.0f64, 0.0f64);
    for (pa, pb) in a.pixels.iter().zip(&b.pixels) {
        for c in 0..3 {
            let (x, y) = (pa[c] as f64, pb[c] as f64);
            se += (x - y).powi(2);
            rel += (x - y).powi(2) / (y * y + 0.01);
        }
    }
    Some(Comparison {
        rmse: (se / n).sqrt(),
        relative_mse: rel / n,
        mean_ratio: a.mean() / b.mean(),
    })
}

/// Means of `block`×`block` pixel blocks (channel-averaged), row-major.
pub fn block_means(image: &Image, block: u32) -> Vec<f64> {
    let (bw, bh) = (image.width.div_ceil(block), image.height.div_ceil(block));
    let mut sums = vec![(0.0f64, 0u32); (bw * bh) as usize];
    for y in 0..image.height {
        for x in 0..image.width {
            let p = image.pixels[(y * image.width + x) as usize];
            let s = &mut sums[((y / block) * bw + x / block) as usize];
            s.0 += (p.x + p.y + p.z) as f64 / 3.0;
            s.1 += 1;
        }
    }
    sums.into_iter().map(|(s, c)| s / c as f64).collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use radiant_core::Rgb;

    #[test]
    fn metrics_match_hand_computed_values() {
        let a = Image {
            width: 2,
            height: 1,
            pixels: vec![Rgb::splat(1.0), Rgb::splat(3.0)],
        };
        let b = Image {
            width: 2,
            height: 1,
            pixels: vec![Rgb::splat(1.0), Rgb::splat(1.0)],
        };
        let c = compare(&a, &b).unwrap();
        assert!((c.rmse - 2.0f64.sqrt()).abs() < 1e-12);
        assert!((c.mean_ratio - 2.0).abs() < 1e-12);
        assert!((c.relative_mse - 0.5 * 4.0 / 1.01).abs() < 1e-12);
        assert_eq!(block_means(&a, 1), vec![1.0, 3.0]);
        assert_eq!(block_means(&a, 2), vec![2.0]);
        let small = Image {
            width: 1,
            height: 1,
            pixels: vec![Rgb::ONE],
        };
        assert!(compare(&a, &small).is_none());
    }
}
