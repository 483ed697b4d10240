//! The batch fill every built-in sampler shares.
//!
//! Each built-in sampler computes a sample's value at a dimension on its own,
//! from (seed, pixel, index, dimension); [`Pointwise`] is that per-value
//! function and [`pointwise_sampler!`] writes the [`Sampler`] batch loops
//! over it once, monomorphised per sampler (no dynamic dispatch per value).
//!
//! [`Sampler`]: radiant_core::Sampler

use radiant_core::SampleId;
use radiant_core::glam::Vec2;

/// A sampler whose values are computed one sample at a time.
pub(crate) trait Pointwise {
    /// Dimension `dim` of sample `id`, in [0, 1).
    fn value_1d(&self, id: SampleId, dim: u32) -> f32;

    /// Dimensions `dim` and `dim + 1` of sample `id`, each in [0, 1); by
    /// default two independent 1D values.
    #[inline]
    fn value_2d(&self, id: SampleId, dim: u32) -> Vec2 {
        Vec2::new(self.value_1d(id, dim), self.value_1d(id, dim + 1))
    }

    /// The sampler's GPU side: `sample_1d_T` computing
    /// [`value_1d`](Self::value_1d), and `sample_2d_T` computing
    /// [`value_2d`](Self::value_2d) where that is not the default.
    fn gpu(&self) -> Option<radiant_core::GpuModule> {
        None
    }
}

/// Writes `value(ids[i])` into `out[i]`: with AVX2 where the CPU has it
/// (eight hashes per instruction, with native 32-bit multiplies), else
/// with the target's baseline.
#[inline]
pub(crate) fn fill<T>(ids: &[SampleId], out: &mut [T], value: impl Fn(SampleId) -> T) {
    #[cfg(target_arch = "x86_64")]
    if std::arch::is_x86_feature_detected!("avx2") {
        // SAFETY: the CPU supports AVX2.
        return unsafe { fill_avx2(ids, out, value) };
    }
    fill_loop(ids, out, value);
}

/// [`fill`] compiled for AVX2.
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2")]
fn fill_avx2<T>(ids: &[SampleId], out: &mut [T], value: impl Fn(SampleId) -> T) {
    fill_loop(ids, out, value);
}

/// The loop of [`fill`].
#[inline(always)]
fn fill_loop<T>(ids: &[SampleId], out: &mut [T], value: impl Fn(SampleId) -> T) {
    for (id, o) in ids.iter().zip(out.iter_mut()) {
        *o = value(*id);
    }
}

/// Implements [`radiant_core::Sampler`] for a [`Pointwise`] type.
macro_rules! pointwise_sampler {
    ($ty:ty) => {
        impl radiant_core::Sampler for $ty {
            fn fill_2d(
                &self,
                ids: &[radiant_core::SampleId],
                dim: u32,
                out: &mut [radiant_core::glam::Vec2],
            ) {
                $crate::pointwise::fill(ids, out, |id| {
                    $crate::pointwise::Pointwise::value_2d(self, id, dim)
                });
            }

            fn fill_1d(&self, ids: &[radiant_core::SampleId], dim: u32, out: &mut [f32]) {
                $crate::pointwise::fill(ids, out, |id| {
                    $crate::pointwise::Pointwise::value_1d(self, id, dim)
                });
            }

            fn gpu(&self) -> Option<radiant_core::GpuModule> {
                $crate::pointwise::Pointwise::gpu(self)
            }
        }
    };
}

pub(crate) use pointwise_sampler;

#[cfg(test)]
mod tests {
    use super::*;
    use crate::{Halton, Independent, Sobol, Stratified};

    /// The instruction set the fill runs with must not change the values:
    /// the dispatched fill (AVX2 where the CPU has it) against the plain
    /// loop, for every built-in sampler, 1D and 2D.
    #[test]
    fn dispatched_fill_matches_the_plain_loop() {
        let ids: Vec<SampleId> = (0..1000)
            .map(|i| SampleId {
                pixel: i * 7919 % 65536,
                index: i % 37,
            })
            .collect();
        let check = |s: &dyn Pointwise| {
            for dim in [0, 3, 17] {
                let mut a = vec![0.0f32; ids.len()];
                let mut b = vec![0.0f32; ids.len()];
                fill(&ids, &mut a, |id| s.value_1d(id, dim));
                fill_loop(&ids, &mut b, |id| s.value_1d(id, dim));
                assert_eq!(a, b);
                let mut a = vec![Vec2::ZERO; ids.len()];
                let mut b = vec![Vec2::ZERO; ids.len()];
                fill(&ids, &mut a, |id| s.value_2d(id, dim));
                fill_loop(&ids, &mut b, |id| s.value_2d(id, dim));
                assert_eq!(a, b);
            }
        };
        check(&Independent::new(5));
        check(&Stratified::new(5, 37));
        check(&Halton::new(5));
        check(&Sobol::new(5));
    }
}
