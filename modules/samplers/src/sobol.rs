//! The `sobol` sampler: Owen-scrambled Sobol points with Burley's (2020)
//! shuffling ("Practical Hash-based Owen Scrambling").
//!
//! Every 2D request (dimensions d, d+1) takes the first two Sobol
//! dimensions — a (0, 2)-sequence in base 2, so any 2^k consecutive
//! aligned samples stratify every elementary interval of area 2^-k — at a
//! sample index that is itself Owen-scrambled (shuffled) with a key of
//! (seed, pixel, d), then Owen-scrambles each coordinate with its own key.
//! A 1D request uses the first dimension the same way. Shuffles are
//! independent between requests, so dimensions are decorrelated while each
//! pair keeps the full 2D stratification. Sample counts that are powers of
//! two are best.

use crate::pointwise::{Pointwise, pointwise_sampler};
use crate::scramble::{SCRAMBLE_WGSL, nested_uniform_scramble, nested_uniform_scramble_reversed};
use crate::seed::fold;
use radiant_core::glam::Vec2;
use radiant_core::hash::{hash_u32, hash4_first, hash4_last, hash4_middle, unit_float};
use radiant_core::{GpuModule, GpuParams, Registry, SampleId};

/// The second Sobol dimension of `index`, bit-reversed (lowest bit =
/// the fraction's first digit).
///
/// Its generator matrix is Pascal's triangle mod 2 (direction numbers
/// v₀ = 2³¹, vᵢ = vᵢ₋₁ ⊕ (vᵢ₋₁ ≫ 1)); by Lucas' theorem digit k of the
/// fraction is the XOR of the index bits i whose positions contain k's as
/// a bit subset. That superset XOR takes five shift-mask-XOR steps, one per
/// bit of a position, instead of a 32-step loop over the direction numbers
/// (and it vectorises across a batch). Returning it bit-reversed saves the
/// reversal that Owen scrambling would undo first.
#[inline]
fn sobol_1_reversed(index: u32) -> u32 {
    let mut w = index;
    w ^= (w >> 1) & 0x5555_5555;
    w ^= (w >> 2) & 0x3333_3333;
    w ^= (w >> 4) & 0x0f0f_0f0f;
    w ^= (w >> 8) & 0x00ff_00ff;
    w ^= w >> 16;
    w
}

/// Owen-scrambled, shuffled Sobol sampling.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Sobol {
    seed: u32,
    /// `hash4_first(seed)`: the keys' hash state after the seed.
    seed_state: u32,
}

impl Sobol {
    /// A Sobol sampler for the render seed `seed`.
    pub fn new(seed: u64) -> Self {
        let seed = fold(seed);
        Self {
            seed,
            seed_state: hash4_first(seed),
        }
    }
}

impl Pointwise for Sobol {
    #[inline]
    fn value_2d(&self, id: SampleId, dim: u32) -> Vec2 {
        let key = hash4_last(hash4_middle(self.seed_state, id.pixel, dim), 0x3c6e_f372);
        let i = nested_uniform_scramble(id.index, key);
        let x = nested_uniform_scramble_reversed(i, hash_u32(key ^ 0x1));
        let y = nested_uniform_scramble_reversed(sobol_1_reversed(i), hash_u32(key ^ 0x2));
        Vec2::new(unit_float(x), unit_float(y))
    }

    #[inline]
    fn value_1d(&self, id: SampleId, dim: u32) -> f32 {
        let key = hash4_last(hash4_middle(self.seed_state, id.pixel, dim), 0xa54f_f53a);
        let i = nested_uniform_scramble(id.index, key);
        unit_float(nested_uniform_scramble_reversed(i, hash_u32(key)))
    }

    fn gpu(&self) -> Option<GpuModule> {
        Some(
            GpuModule::new(
                "sobol",
                include_str!("sobol.wgsl"),
                GpuParams::new().u32(self.seed),
            )
            .with_libraries(&[SCRAMBLE_WGSL]),
        )
    }
}

pointwise_sampler!(Sobol);

pub(crate) fn register(registry: &mut Registry) {
    crate::register_sampler(
        registry,
        "sobol",
        "Owen-scrambled Sobol points, shuffled per dimension pair (Burley 2020); best with power-of-two spp.",
        |ctx| Sobol::new(ctx.seed),
    );
}

#[cfg(test)]
mod tests {
    use super::*;
    use radiant_core::Sampler;

    #[test]
    fn second_dimension_matches_the_sobol_sequence() {
        // XORs of the direction numbers 1/2, 3/4, 5/8 by the index's bits.
        let expected = [0.0, 0.5, 0.75, 0.25, 0.625, 0.125, 0.375, 0.875];
        for (i, e) in expected.iter().enumerate() {
            assert_eq!(
                unit_float(sobol_1_reversed(i as u32).reverse_bits()),
                *e,
                "index {i}"
            );
        }
    }

    /// The five-step superset XOR against the definition, the XOR of the
    /// direction numbers of the index's set bits, on indices with every
    /// bit count (shuffled indices have random high bits).
    #[test]
    fn superset_xor_is_the_sum_of_direction_numbers() {
        let by_directions = |index: u32| {
            let (mut x, mut v) = (0u32, 1u32 << 31);
            for bit in 0..32 {
                if index >> bit & 1 == 1 {
                    x ^= v;
                }
                v ^= v >> 1;
            }
            x
        };
        let mut index = 0x2545_f491u32;
        for i in 0..100_000u32 {
            let index_i = if i < 4096 { i } else { index };
            assert_eq!(
                sobol_1_reversed(index_i).reverse_bits(),
                by_directions(index_i),
                "index {index_i:#x}"
            );
            index = radiant_core::hash::hash_u32(index.wrapping_add(i));
        }
        assert_eq!(
            sobol_1_reversed(u32::MAX).reverse_bits(),
            by_directions(u32::MAX)
        );
    }

    #[test]
    fn every_power_of_two_prefix_is_a_net() {
        // 2^k samples of a pixel: one in each of the 2^k cells of every
        // elementary-interval shape 2^-a × 2^-(k-a).
        let s = Sobol::new(9);
        for k in [4u32, 6, 8] {
            let n = 1u32 << k;
            let ids: Vec<SampleId> = (0..n).map(|index| SampleId { pixel: 3, index }).collect();
            let mut p = vec![Vec2::ZERO; n as usize];
            s.fill_2d(&ids, 6, &mut p);
            for a in 0..=k {
                let (nx, ny) = (1u32 << a, 1u32 << (k - a));
                let mut cells: Vec<u32> = p
                    .iter()
                    .map(|q| (q.y * ny as f32) as u32 * nx + (q.x * nx as f32) as u32)
                    .collect();
                cells.sort_unstable();
                cells.dedup();
                assert_eq!(cells.len(), n as usize, "k {k}, {nx}×{ny}");
            }
        }
    }
}
