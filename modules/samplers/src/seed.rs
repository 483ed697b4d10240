//! Folding the render's 64-bit seed into the 32-bit keys the samplers hash.

/// A 32-bit key from a 64-bit seed.
#[inline]
pub(crate) fn fold(seed: u64) -> u32 {
    (seed as u32) ^ ((seed >> 32) as u32).wrapping_mul(0x9e37_79b9)
}
