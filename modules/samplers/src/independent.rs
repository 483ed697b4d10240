//! The `independent` sampler: uniform random numbers from a counter-based
//! hash of (seed, pixel, sample index, dimension).

use crate::seed::fold;
use radiant_core::glam::Vec2;
use radiant_core::hash::{hash4, unit_float};
use radiant_core::{ModuleInfo, Params, Registry, SampleId, Sampler};
use serde::Deserialize;

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

    #[inline]
    fn value(&self, id: SampleId, dim: u32) -> f32 {
        unit_float(hash4(self.seed, id.pixel, id.index, dim))
    }
}

impl Sampler for Independent {
    fn fill_2d(&self, ids: &[SampleId], dim: u32, out: &mut [Vec2]) {
        for (id, o) in ids.iter().zip(out.iter_mut()) {
            *o = Vec2::new(self.value(*id, dim), self.value(*id, dim + 1));
        }
    }

    fn fill_1d(&self, ids: &[SampleId], dim: u32, out: &mut [f32]) {
        for (id, o) in ids.iter().zip(out.iter_mut()) {
            *o = self.value(*id, dim);
        }
    }
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct IndependentParams {}

pub(crate) fn register(registry: &mut Registry) {
    registry.register::<dyn Sampler>(
        ModuleInfo {
            type_name: "independent",
            summary: "Independent uniform random numbers (seeded by the render's --seed).",
            params: &[],
        },
        |params: &Params, ctx| {
            let _: IndependentParams = params.parse()?;
            Ok(Box::new(Independent::new(ctx.seed)) as Box<dyn Sampler>)
        },
    );
}
