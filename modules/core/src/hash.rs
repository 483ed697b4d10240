//! Stateless hashing to uniform random numbers.
//!
//! Samplers in Radiant are stateless: a sample value is a pure function of
//! (seed, pixel, sample index, dimension). That makes every render
//! reproducible regardless of thread scheduling and lets the wavefront
//! integrator ask for any dimension of any path at any time.

/// A 32-bit integer hash with good avalanche (the "lowbias32" finaliser of
/// Chris Wellons' hash prospector).
#[inline]
pub fn hash_u32(mut x: u32) -> u32 {
    x ^= x >> 16;
    x = x.wrapping_mul(0x21f0_aaad);
    x ^= x >> 15;
    x = x.wrapping_mul(0xd35a_2d97);
    x ^= x >> 15;
    x
}

/// Hashes four words into one, order-sensitively.
#[inline]
pub fn hash4(a: u32, b: u32, c: u32, d: u32) -> u32 {
    hash4_last(hash4_middle(hash4_first(a), b, c), d)
}

/// The first stage of [`hash4`]: the state after word `a`. Callers that
/// hash many tuples with the same first word (a seed) compute it once.
#[inline]
pub fn hash4_first(a: u32) -> u32 {
    hash_u32(a ^ 0x9e37_79b9)
}

/// The middle stage of [`hash4`]: the state after words `b` and `c`,
/// from the state [`hash4_first`] returned.
#[inline]
pub fn hash4_middle(state: u32, b: u32, c: u32) -> u32 {
    let h = hash_u32(state ^ b);
    hash_u32(h ^ c.wrapping_mul(0x85eb_ca6b))
}

/// The last stage of [`hash4`]: the hash of the tuple ending in word `d`,
/// from the state [`hash4_middle`] returned. A sample's dimensions share
/// everything up to here.
#[inline]
pub fn hash4_last(state: u32, d: u32) -> u32 {
    hash_u32(state ^ d.wrapping_mul(0xc2b2_ae35))
}

/// Maps 32 random bits to a float uniformly distributed in [0, 1).
#[inline]
pub fn unit_float(bits: u32) -> f32 {
    (bits >> 8) as f32 * (1.0 / (1u32 << 24) as f32)
}

/// The next random state of a PCG-style LCG step, for generating a sequence
/// from one hashed seed.
#[inline]
pub fn lcg_next(state: u32) -> u32 {
    state.wrapping_mul(747_796_405).wrapping_add(2_891_336_453)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn unit_float_is_in_range() {
        assert_eq!(unit_float(0), 0.0);
        assert!(unit_float(u32::MAX) < 1.0);
    }

    #[test]
    fn staged_hash_is_hash4() {
        for (a, b, c, d) in [(0, 0, 0, 0), (7, 1, 2, 3), (u32::MAX, 9, 0, 12345)] {
            let staged = hash4_last(hash4_middle(hash4_first(a), b, c), d);
            assert_eq!(staged, hash4(a, b, c, d));
        }
        // Word order matters.
        assert_ne!(hash4(1, 2, 3, 4), hash4(2, 1, 3, 4));
        assert_ne!(hash4(1, 2, 3, 4), hash4(1, 2, 4, 3));
    }

    #[test]
    fn hashed_floats_are_uniform() {
        // Chi-square of 64 equal bins over 64k hashed values.
        let bins = 64;
        let n = 65_536u32;
        let mut counts = vec![0u32; bins];
        for i in 0..n {
            let u = unit_float(hash4(7, i, 3, 1));
            counts[(u * bins as f32) as usize] += 1;
        }
        let expected = n as f64 / bins as f64;
        let chi2: f64 = counts
            .iter()
            .map(|&c| (c as f64 - expected).powi(2) / expected)
            .sum();
        // 63 degrees of freedom: the 99.9% quantile is about 103.
        assert!(chi2 < 103.0, "chi2 = {chi2}");
    }
}
