//! Tracing chain proposals, and the bootstrap that normalises the chains.
//!
//! A [`Tracer`] is one thread's scratch: it reads the raster position of
//! every slot's proposal from the chains' first two primary samples (the
//! image is [0, 1)² of primary sample space), traces all proposals as one
//! wavefront batch through [`Wavefront::trace_raster`] with the chains as
//! the sampler, and keeps each proposal's radiance, its target value (the
//! luminance, the scalar the chains are distributed by) and its raster
//! position. [`bootstrap`] traces independent fresh vectors on every
//! thread: their mean target value is the normalisation b = ∫ I(u) du.

use super::pss::Chains;
use crate::extract::RenderScene;
use crate::integrators::path::Wavefront;
use glam::Vec2;
use radiant_core::hash::{hash_u32, hash4};
use radiant_core::{Rgb, SampleId, Sampler, luminance};
use rayon::prelude::*;

/// Fresh proposals traced per batch of the bootstrap.
const BOOTSTRAP_BATCH: usize = 1024;

/// One thread's state for tracing chain proposals (reused: nothing is
/// allocated per path once the buffers have grown).
#[derive(Default)]
pub struct Tracer {
    wavefront: Wavefront,
    ids: Vec<SampleId>,
    raster: Vec<Vec2>,
    /// Radiance of each slot's proposal (zero where it was not finite).
    pub value: Vec<Rgb>,
    /// Target value of each slot's proposal: the luminance of `value`.
    pub target: Vec<f32>,
    /// Proposals whose radiance was NaN or infinite (recorded as zero).
    pub invalid: u64,
}

impl Tracer {
    /// Traces the proposal of every slot of `chains`.
    pub fn trace(&mut self, scene: &RenderScene, chains: &Chains) {
        let n = chains.len();
        self.ids.clear();
        // The index keeps the scene sampler's numbers (drawn where a
        // medium samples distances) fresh for every proposal.
        self.ids.extend((0..n as u32).map(|slot| SampleId {
            pixel: slot,
            index: hash4(
                chains.chain(slot as usize),
                chains.step(slot as usize),
                0,
                0,
            ),
        }));
        self.raster.resize(n, Vec2::ZERO);
        chains.fill_2d(&self.ids, 0, &mut self.raster);
        let size = Vec2::new(scene.settings.width as f32, scene.settings.height as f32);
        for r in &mut self.raster {
            *r *= size;
        }
        let radiance = self
            .wavefront
            .trace_raster(scene, chains, &self.ids, &self.raster);
        self.value.clear();
        self.target.clear();
        for &l in radiance {
            let y = luminance(l);
            if l.is_finite() && y > 0.0 {
                self.value.push(l);
                self.target.push(y);
            } else {
                self.invalid += u64::from(!l.is_finite());
                self.value.push(Rgb::ZERO);
                self.target.push(0.0);
            }
        }
    }

    /// The raster position of slot `slot`'s last traced proposal.
    pub fn raster(&self, slot: usize) -> Vec2 {
        self.raster[slot]
    }

    /// Rays traced so far.
    pub fn rays(&self) -> u64 {
        self.wavefront.rays
    }
}

/// The render's streams of chain randomness, kept apart by purpose.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Stream {
    /// Bootstrap samples (chain number = sample number).
    Bootstrap,
    /// ERPT seed paths (chain number = seed number).
    Seeds,
    /// ERPT chains of seed batch `n`.
    Redistribution(u32),
    /// Uniform numbers that pick chain starts and counts.
    Choices,
}

/// The seed of `stream` for a render with seed `seed`.
pub fn stream_seed(seed: u64, stream: Stream) -> u32 {
    let (a, b) = match stream {
        Stream::Bootstrap => (1, 0),
        Stream::Seeds => (2, 0),
        Stream::Redistribution(n) => (3, n),
        Stream::Choices => (4, 0),
    };
    hash4(
        hash_u32(seed as u32),
        (seed >> 32) as u32 ^ a,
        b,
        0x6572_7074,
    )
}

/// What the bootstrap found.
#[derive(Debug, Clone, PartialEq)]
pub struct Bootstrap {
    /// The target value of each bootstrap sample, in sample order.
    pub target: Vec<f32>,
    /// Their mean: the estimate of b = ∫ I(u) du.
    pub mean: f64,
    /// Rays traced.
    pub rays: u64,
    /// Samples whose radiance was NaN or infinite.
    pub invalid: u64,
}

/// Traces `count` independent fresh primary-sample vectors (stream
/// [`Stream::Bootstrap`], chain number = sample number) on the rayon pool.
pub fn bootstrap(scene: &RenderScene, count: usize) -> Bootstrap {
    let seed = stream_seed(scene.settings.seed, Stream::Bootstrap);
    let batches: Vec<(Vec<f32>, u64, u64)> = (0..count.div_ceil(BOOTSTRAP_BATCH))
        .into_par_iter()
        .map_init(
            || (Tracer::default(), Chains::new(seed)),
            |(tracer, chains), batch| {
                let first = batch * BOOTSTRAP_BATCH;
                let n = BOOTSTRAP_BATCH.min(count - first);
                chains.resize(n);
                for slot in 0..n {
                    chains.start(slot, (first + slot) as u32);
                    chains.propose_fresh(slot);
                }
                let (rays, invalid) = (tracer.rays(), tracer.invalid);
                tracer.trace(scene, chains);
                (
                    tracer.target.clone(),
                    tracer.rays() - rays,
                    tracer.invalid - invalid,
                )
            },
        )
        .collect();
    let mut out = Bootstrap {
        target: Vec::with_capacity(count),
        mean: 0.0,
        rays: 0,
        invalid: 0,
    };
    for (target, rays, invalid) in batches {
        out.target.extend(target);
        out.rays += rays;
        out.invalid += invalid;
    }
    let sum: f64 = out.target.iter().map(|&t| f64::from(t)).sum();
    out.mean = sum / count.max(1) as f64;
    out
}

/// Picks bootstrap samples in proportion to their target values.
pub struct Resampler {
    cdf: Vec<f64>,
}

impl Resampler {
    /// The distribution over `target`, or `None` where every value is 0.
    pub fn new(target: &[f32]) -> Option<Self> {
        let mut sum = 0.0f64;
        let cdf: Vec<f64> = target
            .iter()
            .map(|&t| {
                sum += f64::from(t);
                sum
            })
            .collect();
        (sum > 0.0).then_some(Self { cdf })
    }

    /// The sample whose share of the cumulative sum holds `u` ∈ [0, 1).
    pub fn pick(&self, u: f32) -> usize {
        let total = self.cdf.last().copied().unwrap_or(0.0);
        let x = f64::from(u) * total;
        self.cdf
            .partition_point(|&c| c <= x)
            .min(self.cdf.len() - 1)
    }
}
