//! The `independent` sampler: uniform random numbers from a counter-based
//! hash of (seed, pixel, sample index, dimension).

use crate::pointwise::{Pointwise, pointwise_sampler};
use crate::seed::fold;
use radiant_core::hash::{hash4, unit_float};
use radiant_core::{Registry, SampleId};

/// Independent uniform random numbers.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Independent {
    seed: u32,
}

impl Independent {
    /// An independent sampler for the render seed `seed`.
    pub fn new(seed: u64) -> Self {
        Self { seed: fold(seed) }
    }
}

impl Pointwise for Independent {
    #[inline]
    fn value_1d(&self, id: SampleId, dim: u32) -> f32 {
        unit_float(hash4(self.seed, id.pixel, id.index, dim))
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
