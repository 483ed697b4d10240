//! The `independent` sampler: uniform random numbers from a counter-based
//! hash of (seed, pixel, sample index, dimension).

use crate::pointwise::{Pointwise, pointwise_sampler};
use crate::seed::fold;
use radiant_core::glam::Vec2;
use radiant_core::hash::{hash4_first, hash4_last, hash4_middle, unit_float};
use radiant_core::{GpuModule, GpuParams, Registry, SampleId};

/// Independent uniform random numbers: dimension `dim` of sample `id` is
/// `hash4(seed, id.pixel, id.index, dim)`, computed in stages so that the
/// seed is hashed once and a 2D pair shares its sample's hash.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Independent {
    /// The seed after [`hash4_first`].
    seed_state: u32,
}

impl Independent {
    /// An independent sampler for the render seed `seed`.
    pub fn new(seed: u64) -> Self {
        Self {
            seed_state: hash4_first(fold(seed)),
        }
    }

    /// The hash state of sample `id`, shared by its dimensions.
    #[inline]
    fn sample_state(&self, id: SampleId) -> u32 {
        hash4_middle(self.seed_state, id.pixel, id.index)
    }
}

impl Pointwise for Independent {
    #[inline]
    fn value_1d(&self, id: SampleId, dim: u32) -> f32 {
        unit_float(hash4_last(self.sample_state(id), dim))
    }

    #[inline]
    fn value_2d(&self, id: SampleId, dim: u32) -> Vec2 {
        let state = self.sample_state(id);
        Vec2::new(
            unit_float(hash4_last(state, dim)),
            unit_float(hash4_last(state, dim + 1)),
        )
    }

    fn gpu(&self) -> Option<GpuModule> {
        Some(GpuModule::new(
            "independent",
            include_str!("independent.wgsl"),
            GpuParams::new().u32(self.seed_state),
        ))
    }
}

pointwise_sampler!(Independent);

pub(crate) fn register(registry: &mut Registry) {
    crate::register_sampler(
        registry,
        "independent",
        "Independent uniform random numbers (seeded by the render's --seed).",
        |ctx| Independent::new(ctx.seed),
    );
}

#[cfg(test)]
mod tests {
    use super::*;
    use radiant_core::hash::hash4;

    #[test]
    fn values_are_the_documented_hash() {
        let sampler = Independent::new(0x1234_5678_9abc);
        let id = SampleId {
            pixel: 4097,
            index: 33,
        };
        let expected = |dim| unit_float(hash4(fold(0x1234_5678_9abc), 4097, 33, dim));
        assert_eq!(sampler.value_1d(id, 5), expected(5));
        assert_eq!(sampler.value_2d(id, 5), Vec2::new(expected(5), expected(6)));
    }
}
