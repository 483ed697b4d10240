//! The `halton` sampler: the Halton sequence over each pixel's sample
//! indices, randomised by Owen scrambling.
//!
//! Dimension d is the radical inverse of the sample index in the d-th prime
//! base (2, 3, 5, …; past the 128th prime the bases repeat with independent
//! scrambles). Each digit is permuted by a hashed permutation of 0..base
//! that depends on the seed, the pixel, the dimension and all the digits
//! before it — full Owen scrambling, which keeps the sequence's
//! stratification, makes every sample uniformly distributed (unbiased) and
//! decorrelates pixels and dimensions.

use crate::pointwise::{Pointwise, pointwise_sampler};
use crate::scramble::{SCRAMBLE_WGSL, permute};
use crate::seed::fold;
use radiant_core::hash::{hash_u32, hash4};
use radiant_core::{GpuModule, GpuParams, Registry, SampleId};

/// Number of distinct prime bases.
const BASES: usize = 128;

/// The first [`BASES`] primes.
const PRIMES: [u32; BASES] = primes();

const fn primes() -> [u32; BASES] {
    let mut out = [0u32; BASES];
    let (mut count, mut candidate) = (0, 2u32);
    while count < BASES {
        let mut d = 2;
        let mut prime = true;
        while d * d <= candidate {
            if candidate % d == 0 {
                prime = false;
                break;
            }
            d += 1;
        }
        if prime {
            out[count] = candidate;
            count += 1;
        }
        candidate += 1;
    }
    out
}

/// Owen-scrambled Halton sampling.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Halton {
    seed: u32,
}

impl Halton {
    /// A Halton sampler for the render seed `seed`.
    pub fn new(seed: u64) -> Self {
        Self { seed: fold(seed) }
    }
}

impl Pointwise for Halton {
    #[inline]
    fn value_1d(&self, id: SampleId, dim: u32) -> f32 {
        let base = PRIMES[dim as usize % BASES];
        let key = hash4(self.seed, id.pixel, dim, 0x6a09_e667);
        owen_radical_inverse(id.index, base, key)
    }

    fn gpu(&self) -> Option<GpuModule> {
        let params = PRIMES
            .iter()
            .fold(GpuParams::new().u32(self.seed), |p, &b| p.u32(b));
        Some(
            GpuModule::new("halton", include_str!("halton.wgsl"), params)
                .with_libraries(&[SCRAMBLE_WGSL]),
        )
    }
}

/// The radical inverse of `index` in `base` with every digit permuted
/// depending on `key` and the digits before it, to f32 precision.
fn owen_radical_inverse(mut index: u32, base: u32, key: u32) -> f32 {
    let inv_base = 1.0 / base as f64;
    let (mut scale, mut sum, mut state) = (inv_base, 0.0f64, key);
    // Digits below 2^-26 cannot change an f32 in [0, 1): scramble down to
    // there, so even the trailing zero digits of the index get random values.
    while scale > 1.0 / (1u64 << 26) as f64 {
        let digit = index % base;
        index /= base;
        sum += permute(digit, base, state) as f64 * scale;
        state = hash_u32(state ^ digit.wrapping_mul(0x9e37_79b9));
        scale *= inv_base;
    }
    (sum as f32).min(radiant_core::ONE_MINUS_EPSILON)
}

pointwise_sampler!(Halton);

pub(crate) fn register(registry: &mut Registry) {
    crate::register_sampler(
        registry,
        "halton",
        "Owen-scrambled Halton sequence over each pixel's samples (dimension d in the d-th prime base).",
        |ctx| Halton::new(ctx.seed),
    );
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn primes_are_primes() {
        assert_eq!(&PRIMES[..6], &[2, 3, 5, 7, 11, 13]);
        assert_eq!(PRIMES[BASES - 1], 719);
    }

    #[test]
    fn scrambled_digits_keep_the_strata_of_each_base() {
        // The first b^k indices of a scrambled radical inverse still put
        // one point in each interval [j/b^k, (j+1)/b^k).
        for (base, k) in [(2u32, 6u32), (3, 4), (5, 3), (719, 1)] {
            let n = base.pow(k);
            let mut strata: Vec<u32> = (0..n)
                .map(|i| (owen_radical_inverse(i, base, 0xabc) * n as f32) as u32)
                .collect();
            strata.sort_unstable();
            assert_eq!(strata, (0..n).collect::<Vec<_>>(), "base {base}");
        }
    }
}
