//! Hash-based permutations and scrambles the samplers share.
//!
//! * [`permute`]: a random permutation of 0..n chosen by a key, evaluated
//!   one element at a time (Kensler 2013, "Correlated Multi-Jittered
//!   Sampling"), so strata can be shuffled without storing anything.
//! * [`nested_uniform_scramble`]: base-2 Owen scrambling of a 32-bit
//!   fixed-point value with the Laine–Karras hash (Burley 2020, "Practical
//!   Hash-based Owen Scrambling").

use radiant_core::GpuLibrary;

/// The WGSL of [`permute`] (`smp_permute`) and [`nested_uniform_scramble`]
/// (`smp_owen_scramble`), for the samplers' GPU sides.
pub(crate) const SCRAMBLE_WGSL: GpuLibrary = GpuLibrary {
    name: "samplers::scramble",
    wgsl: include_str!("scramble.wgsl"),
    requires: &[],
};

/// The element at position `i` of a random permutation of 0..`n` chosen by
/// `key`. Every key gives a bijection of 0..n.
#[inline]
pub fn permute(mut i: u32, n: u32, key: u32) -> u32 {
    debug_assert!(i < n);
    if n <= 1 {
        return 0;
    }
    let mut w = n - 1;
    w |= w >> 1;
    w |= w >> 2;
    w |= w >> 4;
    w |= w >> 8;
    w |= w >> 16;
    // Cycle-walk a bijection of 0..=w until the value falls inside 0..n.
    loop {
        i ^= key;
        i = i.wrapping_mul(0xe170_893d);
        i ^= key >> 16;
        i ^= (i & w) >> 4;
        i ^= key >> 8;
        i = i.wrapping_mul(0x0929_eb3f);
        i ^= key >> 23;
        i ^= (i & w) >> 1;
        i = i.wrapping_mul(1 | key >> 27);
        i = i.wrapping_mul(0x6935_fa69);
        i ^= (i & w) >> 11;
        i = i.wrapping_mul(0x74dc_b303);
        i ^= (i & w) >> 2;
        i = i.wrapping_mul(0x9e50_1cc3);
        i ^= (i & w) >> 2;
        i = i.wrapping_mul(0xc860_a3df);
        i &= w;
        i ^= i >> 5;
        if i < n {
            break;
        }
    }
    (i.wrapping_add(key)) % n
}

/// The Laine–Karras permutation with Burley's constants: bit k of the
/// result depends only on bits ≤ k of `x`.
#[inline]
fn laine_karras(mut x: u32, seed: u32) -> u32 {
    x = x.wrapping_add(seed);
    x ^= x.wrapping_mul(0x6c50_b47c);
    x ^= x.wrapping_mul(0xb82f_1e52);
    x ^= x.wrapping_mul(0xc7af_e638);
    x ^= x.wrapping_mul(0x8d22_f6e6);
    x
}

/// Owen-scrambles the 32-bit fixed-point fraction `x` (most significant
/// bit first) with the scramble chosen by `seed`: each bit is flipped
/// depending on the bits above it.
#[inline]
pub fn nested_uniform_scramble(x: u32, seed: u32) -> u32 {
    laine_karras(x.reverse_bits(), seed).reverse_bits()
}

/// [`nested_uniform_scramble`] of `x.reverse_bits()`, computed without the
/// two bit reversals that cancel: the Owen scramble of the fraction whose
/// bits, most significant first, are `x`'s bits from the least significant.
#[inline]
pub fn nested_uniform_scramble_reversed(x: u32, seed: u32) -> u32 {
    laine_karras(x, seed).reverse_bits()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn permute_is_a_bijection_for_every_size() {
        for n in [1u32, 2, 3, 5, 16, 17, 100, 1000] {
            for key in [0u32, 1, 0xdead_beef, 12345] {
                let mut seen = vec![false; n as usize];
                for i in 0..n {
                    let p = permute(i, n, key);
                    assert!(p < n && !seen[p as usize], "n {n} key {key}");
                    seen[p as usize] = true;
                }
            }
        }
    }

    #[test]
    fn the_reversed_scramble_is_the_scramble_of_the_reversal() {
        for seed in [0u32, 3, 0xdead_beef] {
            for x in [0u32, 1, 0x8000_0000, 0x1234_5678, u32::MAX] {
                assert_eq!(
                    nested_uniform_scramble_reversed(x, seed),
                    nested_uniform_scramble(x.reverse_bits(), seed)
                );
            }
        }
    }

    #[test]
    fn owen_scrambling_keeps_aligned_blocks_together() {
        // Values sharing their top k bits still share them after scrambling
        // (the property that keeps a scrambled (0, m, 2)-net a net).
        for seed in [3u32, 77, 0x1234_5678] {
            for x in [0u32, 0x8000_0000, 0xf0f0_f0f0] {
                let a = nested_uniform_scramble(x, seed) >> 24;
                let b = nested_uniform_scramble(x ^ 0x00ff_ffff, seed) >> 24;
                assert_eq!(a, b);
            }
            // And a block of 2^k consecutive fractions maps onto a block.
            let mut top: Vec<u32> = (0..16u32)
                .map(|i| nested_uniform_scramble(i << 28, seed) >> 28)
                .collect();
            top.sort_unstable();
            assert_eq!(top, (0..16).collect::<Vec<_>>());
        }
    }
}
