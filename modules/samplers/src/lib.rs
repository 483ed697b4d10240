//! # radiant-samplers: built-in sampler modules
//!
//! Samplers feed every random decision of the wavefront (pixel jitter, light
//! choice, BSDF lobes, Russian roulette) with values that are a pure
//! function of (seed, pixel, sample index, dimension).

use radiant_core::glam::Vec2;
use radiant_core::hash::{hash4, unit_float};
use radiant_core::{ModuleInfo, Params, Registry, SampleId, Sampler};
use serde::Deserialize;

/// Independent uniform random numbers from a counter-based hash.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Independent {
    seed: u32,
}

impl Independent {
    /// An independent sampler for the render seed `seed`.
    pub fn new(seed: u64) -> Self {
        Self {
            seed: (seed as u32) ^ ((seed >> 32) as u32).wrapping_mul(0x9e37_79b9),
        }
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

/// Registers every built-in sampler type.
pub fn register(registry: &mut Registry) {
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

#[cfg(test)]
mod tests {
    use super::*;

    fn chi2_uniform_2d(values: &[Vec2], bins: usize) -> f64 {
        let mut counts = vec![0u32; bins * bins];
        for v in values {
            let x = ((v.x * bins as f32) as usize).min(bins - 1);
            let y = ((v.y * bins as f32) as usize).min(bins - 1);
            counts[y * bins + x] += 1;
        }
        let expected = values.len() as f64 / (bins * bins) as f64;
        counts
            .iter()
            .map(|&c| (c as f64 - expected).powi(2) / expected)
            .sum()
    }

    #[test]
    fn values_are_uniform_across_samples_and_dimensions() {
        let s = Independent::new(42);
        // Across samples of one pixel, and across dimensions of one sample:
        // both must look uniform in 2D (16×16 bins, 255 dof; the 99.9%
        // quantile is about 330).
        let ids: Vec<SampleId> = (0..40_000)
            .map(|i| SampleId { pixel: 7, index: i })
            .collect();
        let mut out = vec![Vec2::ZERO; ids.len()];
        s.fill_2d(&ids, 4, &mut out);
        assert!(chi2_uniform_2d(&out, 16) < 330.0);
        let one = [SampleId { pixel: 3, index: 5 }];
        let across_dims: Vec<Vec2> = (0..40_000)
            .map(|d| {
                let mut o = [Vec2::ZERO];
                s.fill_2d(&one, 2 * d, &mut o);
                o[0]
            })
            .collect();
        assert!(chi2_uniform_2d(&across_dims, 16) < 330.0);
    }

    #[test]
    fn different_seeds_give_different_values() {
        let id = [SampleId { pixel: 1, index: 2 }];
        let (mut a, mut b) = ([0.0], [0.0]);
        Independent::new(1).fill_1d(&id, 0, &mut a);
        Independent::new(2).fill_1d(&id, 0, &mut b);
        assert_ne!(a, b);
    }
}
