//! Exact accumulation of a frame's weighted sums.
//!
//! Floating-point addition is not associative, so sums kept in `f32` depend
//! on the order samples arrive in: a frame rendered as sample partitions
//! and merged, or rendered in passes and resumed, would differ from one
//! uninterrupted render in the last bits. [`Sums`] holds a pixel's
//! Σ w·r, Σ w·g, Σ w·b and Σ w in 128-bit fixed point (63 fraction bits),
//! where addition is exact, associative and commutative. Tiles still
//! splat in `f32` (the hot loop stays one multiply-add per tap), but only
//! the splats of one [`BLOCK`] of sample indices (`4k..4k + 4`) of one
//! tile, in a fixed order (by sample index, then pixel); that `f32`
//! partial sum is converted exactly ([`fixed`]) when the block ends, so the
//! frame's sums are the same whatever sample ranges, passes or partitions
//! its samples were rendered in, as long as those start and end on block
//! boundaries (or at the frame's last sample): partitions and passes do.
//! Converting per block rather than per sample costs a quarter as much
//! (measured on the Cornell box: per sample, the conversion took about 3 %
//! of the render; per block of 4 it is within the noise).
//!
//! Range: every value an `f32` partial sum can hold from 2^-40 (about
//! 9.1e-13) up is converted without rounding (smaller ones are truncated
//! toward zero at 2^-63, about 1.1e-19); one addend is clamped to
//! ±2^41 (2.2e12), so a pixel's sums may gather 2^23 (8 million) such
//! extreme addends, and ordinary ones (radiance up to 1e6 with weights
//! about 1) by the billion, before they wrap (addition is modulo 2^128 and
//! stays order-independent even then).

use glam::Vec4;
use radiant_core::Rgb;

/// Sample indices per block: a tile's `f32` sums are converted into exact
/// ones at the end of each block (`BLOCK·k .. BLOCK·(k + 1)`), so ranges of
/// samples rendered apart add up exactly where they start and end on
/// multiples of it.
pub const BLOCK: u32 = 4;

/// Fraction bits of the fixed-point sums.
pub const FRACTION_BITS: i32 = 63;

/// Largest magnitude of one addend, 2^41.
const LIMIT: f64 = (1u64 << 41) as f64;

/// 2^[`FRACTION_BITS`].
const SCALE: f64 = (1u64 << FRACTION_BITS) as f64;

/// A pixel's weighted sums, Σ w·r, Σ w·g, Σ w·b and Σ w, in fixed point
/// with [`FRACTION_BITS`] fraction bits.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Hash)]
pub struct Sums(pub [i128; 4]);

impl Sums {
    /// No samples.
    pub const ZERO: Self = Self([0; 4]);

    /// Adds the `f32` sums `v` (r, g, b, weight), each converted exactly.
    #[inline]
    pub fn add_f32(&mut self, v: Vec4) {
        for (sum, x) in self.0.iter_mut().zip(v.to_array()) {
            *sum = sum.wrapping_add(fixed(x));
        }
    }

    /// [`Sums::add_f32`] with AVX-512 (F, DQ and VL): the four channels
    /// converted side by side and the four 128-bit sums added in one
    /// 512-bit register, to the same integers.
    ///
    /// # Safety
    ///
    /// The CPU must have AVX-512 F, DQ and VL.
    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx512f,avx512dq,avx512vl")]
    #[inline]
    pub fn add_f32_avx512(&mut self, v: Vec4) {
        use std::arch::x86_64::*;
        let x = _mm256_cvtps_pd(v.into());
        // `clamp`'s bounds (NaN passes through both, as it does `clamp`),
        // then `fixed`'s two truncations; NaN lanes give 0, as `as` does.
        let ordered = _mm256_cmp_pd_mask::<_CMP_ORD_Q>(x, x);
        let v = _mm256_min_pd(
            _mm256_set1_pd(LIMIT),
            _mm256_max_pd(_mm256_set1_pd(-LIMIT), x),
        );
        let whole = _mm256_maskz_cvttpd_epi64(ordered, v);
        let fraction = _mm256_sub_pd(v, _mm256_cvtepi64_pd(whole));
        let low =
            _mm256_maskz_cvttpd_epi64(ordered, _mm256_mul_pd(fraction, _mm256_set1_pd(SCALE)));
        // (whole << 63) + low in 128 bits: the low and high words.
        let lo_whole = _mm256_slli_epi64::<63>(whole);
        let lo = _mm256_add_epi64(lo_whole, low);
        let carry = _mm256_cmplt_epu64_mask(lo, lo_whole);
        let hi = _mm256_add_epi64(_mm256_srai_epi64::<1>(whole), _mm256_srai_epi64::<63>(low));
        let hi = _mm256_mask_sub_epi64(hi, carry, hi, _mm256_set1_epi64x(-1));
        // Interleaved as the sums lie in memory (little-endian i128: low
        // word first), added, and the low words' carries into the high.
        let addend = _mm512_permutex2var_epi64(
            _mm512_castsi256_si512(lo),
            _mm512_setr_epi64(0, 8, 1, 9, 2, 10, 3, 11),
            _mm512_castsi256_si512(hi),
        );
        let at = self.0.as_mut_ptr().cast::<__m512i>();
        // SAFETY: the four i128 are 64 contiguous bytes.
        let old = unsafe { _mm512_loadu_si512(at) };
        let new = _mm512_add_epi64(old, addend);
        let carries = _mm512_cmplt_epu64_mask(new, old) & 0b0101_0101;
        let new = _mm512_mask_sub_epi64(new, carries << 1, new, _mm512_set1_epi64(-1));
        // SAFETY: as above.
        unsafe { _mm512_storeu_si512(at, new) };
    }

    /// Adds `other`'s sums.
    #[inline]
    pub fn add(&mut self, other: &Self) {
        for (sum, x) in self.0.iter_mut().zip(other.0) {
            *sum = sum.wrapping_add(x);
        }
    }

    /// The pixel's value, Σ w·L / Σ w, black where no weight reached it.
    #[inline]
    pub fn develop(&self) -> Rgb {
        let w = self.0[3];
        if w > 0 {
            let w = w as f64;
            Rgb::new(
                (self.0[0] as f64 / w) as f32,
                (self.0[1] as f64 / w) as f32,
                (self.0[2] as f64 / w) as f32,
            )
        } else {
            Rgb::ZERO
        }
    }

    /// The sums as `f32` (r, g, b, weight), rounded: for previews and
    /// tests, not for adding up.
    pub fn to_f32(&self) -> Vec4 {
        let scale = (-FRACTION_BITS as f64).exp2();
        Vec4::from_array(self.0.map(|s| (s as f64 * scale) as f32))
    }

    /// The sums as 16 little-endian 32-bit words, channel by channel (how
    /// partial EXR files store them).
    pub fn to_words(&self) -> [u32; 16] {
        let mut words = [0; 16];
        for (chunk, sum) in words.chunks_exact_mut(4).zip(self.0) {
            let bits = sum as u128;
            for (k, word) in chunk.iter_mut().enumerate() {
                *word = (bits >> (32 * k)) as u32;
            }
        }
        words
    }

    /// The sums [`Sums::to_words`] gave `words`.
    pub fn from_words(words: &[u32; 16]) -> Self {
        let mut sums = [0i128; 4];
        for (sum, chunk) in sums.iter_mut().zip(words.chunks_exact(4)) {
            let bits = chunk
                .iter()
                .enumerate()
                .fold(0u128, |acc, (k, &w)| acc | (u128::from(w) << (32 * k)));
            *sum = bits as i128;
        }
        Self(sums)
    }
}

/// `x` × 2^[`FRACTION_BITS`] as an integer: exact for |x| ≥ 2^-40,
/// truncated toward zero below, clamped to ±2^41 above; NaN (which the
/// film never holds) gives 0. The whole and fraction parts are converted
/// apart, each with one hardware conversion to `i64` (a direct conversion
/// to `i128` is a slow runtime call), and no branch.
#[inline]
pub fn fixed(x: f32) -> i128 {
    let v = f64::from(x).clamp(-LIMIT, LIMIT);
    // Both exact: |v| ≤ 2^41, and v has at most 24 significant bits.
    let whole = v as i64;
    let fraction = v - whole as f64;
    // |fraction| < 1, so the product is below 2^63; truncated toward zero,
    // as `whole` is, and with the same sign.
    let low = (fraction * SCALE) as i64;
    (i128::from(whole) << FRACTION_BITS) + i128::from(low)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn conversion_is_exact_in_range_and_matches_scaling() {
        let scale = (FRACTION_BITS as f64).exp2();
        let mut values = vec![
            0.0f32, -0.0, 1.0, -1.0, 0.5, 1e-6, -1e-6, 1e6, 3.25e9, 1e-12, 1e-30, 1e12, -2e12,
        ];
        values.extend((1..2000).map(|i| (i as f32 * 0.7731).sin() * 10f32.powi(i % 19 - 9)));
        for x in values {
            let expected = (f64::from(x) * scale).trunc();
            assert_eq!(fixed(x) as f64, expected, "{x}");
            if x.abs() >= 2f32.powi(-40) {
                // Exact: back to the same f32.
                assert_eq!((fixed(x) as f64 / scale) as f32, x, "{x}");
            }
        }
        // Clamped at 2^41, and ordered.
        assert_eq!(fixed(f32::MAX), 1 << (41 + FRACTION_BITS));
        assert_eq!(fixed(-1e30), -(1 << (41 + FRACTION_BITS)));
        assert!(fixed(1e30) > fixed(2e12));
        assert_eq!(fixed(f32::NAN), 0);
        // Subnormals truncate to zero.
        assert_eq!(fixed(f32::MIN_POSITIVE / 4.0), 0);
    }

    #[test]
    fn avx512_conversion_adds_the_same_integers() {
        #[cfg(target_arch = "x86_64")]
        {
            if !(is_x86_feature_detected!("avx512f")
                && is_x86_feature_detected!("avx512dq")
                && is_x86_feature_detected!("avx512vl"))
            {
                eprintln!("no AVX-512 DQ: the scalar conversion is the only one");
                return;
            }
            let mut values = vec![
                0.0f32,
                -0.0,
                1.0,
                -1.0,
                0.5,
                -1e-6,
                3.25e9,
                1e-12,
                -1e-30,
                2e12,
                -2e12,
                f32::MAX,
                -f32::MAX,
                f32::INFINITY,
                f32::NEG_INFINITY,
                f32::NAN,
                f32::MIN_POSITIVE / 4.0,
            ];
            values.extend((1..4000).map(|i| (i as f32 * 0.7731).sin() * 10f32.powi(i % 27 - 13)));
            // Starting sums near every carry: low words about to wrap,
            // high words of both signs.
            let starts = [
                Sums::ZERO,
                Sums([i128::MAX, i128::MIN, -1, 1]),
                Sums([(1 << 64) - 1, -(1 << 64), (1 << 63) - 1, -(1 << 63)]),
                Sums([u64::MAX as i128, -(u64::MAX as i128), 12345, -67890]),
            ];
            for (k, chunk) in values.chunks(4).enumerate() {
                let v = Vec4::from_array(std::array::from_fn(|j| chunk[j % chunk.len()]));
                let start = starts[k % starts.len()];
                let (mut scalar, mut wide) = (start, start);
                scalar.add_f32(v);
                // SAFETY: the CPU has AVX-512 F, DQ and VL (checked above).
                unsafe { wide.add_f32_avx512(v) };
                assert_eq!(wide, scalar, "{v} onto {start:?}");
            }
        }
    }

    #[test]
    fn sums_are_order_independent_where_f32_is_not() {
        // Values over 12 orders of magnitude: f32 sums in two orders differ.
        let values: Vec<Vec4> = (0..1000)
            .map(|i| {
                let x = (i as f32 * 1.618).fract() * 10f32.powi(i % 13 - 6);
                Vec4::new(x, 2.0 * x, -x, 0.25 + x)
            })
            .collect();
        let f32_sum = |v: &mut dyn Iterator<Item = &Vec4>| v.fold(Vec4::ZERO, |a, &b| a + b);
        assert_ne!(
            f32_sum(&mut values.iter()),
            f32_sum(&mut values.iter().rev()),
            "the test needs values whose f32 sum depends on the order"
        );
        let exact = |v: &mut dyn Iterator<Item = &Vec4>| {
            v.fold(Sums::ZERO, |mut a, &b| {
                a.add_f32(b);
                a
            })
        };
        let forward = exact(&mut values.iter());
        assert_eq!(forward, exact(&mut values.iter().rev()));
        // Split in two halves added separately, then together (a merge).
        let (mut a, b) = (
            exact(&mut values[..437].iter()),
            exact(&mut values[437..].iter()),
        );
        a.add(&b);
        assert_eq!(a, forward);
        // And the value is the f64 sum's, to f64 precision.
        let f64_sum: f64 = values.iter().map(|v| f64::from(v.x)).sum();
        assert!((f64::from(forward.to_f32().x) - f64_sum).abs() <= 1e-6 * f64_sum.abs());
    }

    #[test]
    fn words_round_trip_and_develop_divides() {
        let mut s = Sums::ZERO;
        s.add_f32(Vec4::new(-3.5, 1e-9, 7e8, 2.0));
        assert_eq!(Sums::from_words(&s.to_words()), s);
        assert_eq!(s.develop(), Rgb::new(-1.75, 5e-10, 3.5e8));
        assert_eq!(Sums::ZERO.develop(), Rgb::ZERO);
    }
}
