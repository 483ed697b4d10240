//! `pssmlt`: primary-sample-space Metropolis light transport (Kelemen et
//! al. 2002, as pbrt-v4 structures it).
//!
//! 1. Bootstrap: `bootstrap` independent paths; their mean luminance is
//!    the normalisation b = ∫ I(u) du over primary sample space.
//! 2. `chains` chains start at bootstrap samples picked in proportion to
//!    their luminance (so they start close to the stationary
//!    distribution) and each makes an equal share of the budget, the
//!    scene's samples per pixel read as mutations per pixel: small
//!    mutations of every coordinate (Kelemen's, size up to `sigma`) and,
//!    with probability `large_step`, large steps (fresh vectors).
//! 3. Every step deposits both the proposal and the current state with
//!    their expected weights ([`chain`](super::chain)); the image is the
//!    deposits × b × pixels / mutations.
//!
//! Chains run in batches of up to 1024 on each rayon thread: all the
//! batch's proposals of one step are traced as one wavefront. A chain's
//! randomness is hashed from its number and step, and the splat film's
//! sums are exact, so the image does not depend on the batching or the
//! number of threads.

use super::chain::Current;
use super::pss::{Chains, Mutation};
use super::trace::{Resampler, Stream, Tracer, bootstrap, stream_seed};
use crate::integrators::{ChainContext, ChainIntegrator, ChainPass, Family, Integrator};
use radiant_core::hash::{hash4, unit_float};
use radiant_core::{ParamDoc, ParamError, Params};
use rayon::prelude::*;
use serde::Deserialize;
use std::sync::atomic::{AtomicU64, Ordering};

/// Most chains one wavefront batch advances.
const MAX_BATCH: usize = 1024;

/// The `pssmlt` integrator.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Pssmlt {
    /// Number of chains.
    pub chains: u32,
    /// Bootstrap samples.
    pub bootstrap: u32,
    /// How proposals are made.
    pub mutation: Mutation,
}

/// `pssmlt`'s keys (beyond `max_depth`, `rr_depth`, `light_selection`).
#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct PssmltParams {
    #[serde(default = "default_chains")]
    chains: u32,
    #[serde(default = "default_bootstrap")]
    bootstrap: u32,
    #[serde(default = "default_large_step")]
    large_step: f32,
    #[serde(default = "default_sigma")]
    sigma: f32,
}

fn default_chains() -> u32 {
    1024
}
pub(super) fn default_bootstrap() -> u32 {
    100_000
}
fn default_large_step() -> f32 {
    0.3
}
pub(super) fn default_sigma() -> f32 {
    1.0 / 64.0
}

/// `radiant modules`' documentation of the keys.
pub(super) const DOCS: &[ParamDoc] = &[
    ParamDoc {
        name: "chains",
        ty: "positive integer",
        default: "1024",
        doc: "Markov chains; the budget (spp = mutations per pixel) is shared among them. Fewer, \
              longer chains explore each feature further and keep less of the bootstrap's \
              clumping (on scenes/veach-gap-room.yaml 256 chains reach an error 4× lower than 4096 \
              in the same time); more chains use more threads (up to 512 per thread are traced \
              as one wavefront) and let noise average out across the image sooner.",
    },
    ParamDoc {
        name: "bootstrap",
        ty: "positive integer",
        default: "100000",
        doc: "Independent paths that estimate the image's brightness b and from which chains \
              start. More: a more accurate b (its relative error scales the whole image) and \
              better starts, at the cost of that many paths.",
    },
    ParamDoc {
        name: "large_step",
        ty: "number in [0, 1]",
        default: "0.3",
        doc: "Probability that a mutation is a large step (an independent new path). Higher: \
              chains find features they have not seen (lights through gaps, caustics) and \
              noise stays uncorrelated, but bright regions are explored less locally.",
    },
    ParamDoc {
        name: "sigma",
        ty: "number in (0, 1]",
        default: "0.015625",
        doc: "Largest perturbation of a primary sample by a small mutation (sizes are \
              log-uniform down to sigma/16). Smaller: more proposals accepted but slower \
              exploration and blotchier noise; larger: the reverse.",
    },
];

/// Checks a key that must satisfy `ok`.
fn check_range(
    params: &Params,
    key: &str,
    value: f32,
    ok: bool,
    allowed: &str,
) -> Result<(), ParamError> {
    if ok && value.is_finite() {
        Ok(())
    } else {
        Err(ParamError {
            message: format!("`{key}` must be {allowed}, found {value}"),
            location: params.location_of(key),
        })
    }
}

/// The mutation of the keys `large_step` and `sigma`, checked.
pub(super) fn mutation(
    params: &Params,
    large_step: f32,
    sigma: f32,
) -> Result<Mutation, ParamError> {
    check_range(
        params,
        "large_step",
        large_step,
        (0.0..=1.0).contains(&large_step),
        "in [0, 1]",
    )?;
    check_range(
        params,
        "sigma",
        sigma,
        sigma > 0.0 && sigma <= 1.0,
        "in (0, 1]",
    )?;
    Ok(Mutation { large_step, sigma })
}

/// Checks a count that must be at least 1.
pub(super) fn check_count(params: &Params, key: &str, value: u32) -> Result<(), ParamError> {
    if value >= 1 {
        Ok(())
    } else {
        Err(ParamError {
            message: format!("`{key}` must be at least 1, found 0"),
            location: params.location_of(key),
        })
    }
}

impl Pssmlt {
    /// Builds the integrator from its keys.
    pub fn from_params(params: &Params) -> Result<Self, ParamError> {
        let p: PssmltParams = params.parse()?;
        check_count(params, "chains", p.chains)?;
        check_count(params, "bootstrap", p.bootstrap)?;
        Ok(Self {
            chains: p.chains,
            bootstrap: p.bootstrap,
            mutation: mutation(params, p.large_step, p.sigma)?,
        })
    }
}

impl Integrator for Pssmlt {
    fn family(&self) -> Family<'_> {
        Family::Chains(self)
    }
}

impl ChainIntegrator for Pssmlt {
    fn render(&self, ctx: &ChainContext<'_>) -> ChainPass {
        let scene = ctx.scene;
        let (w, h) = (scene.settings.width, scene.settings.height);
        let budget = u64::from(ctx.spp) * u64::from(w) * u64::from(h);
        let boot = bootstrap(scene, self.bootstrap as usize);
        let mut pass = ChainPass {
            scale: 0.0,
            samples: u64::from(self.bootstrap),
            rays: boot.rays,
        };
        let Some(resampler) = Resampler::new(&boot.target) else {
            return pass;
        };
        let chains = u64::from(self.chains).min(budget.max(1)) as usize;
        let steps = (budget / chains as u64).max(1) as u32;
        let threads = rayon::current_num_threads().max(1);
        let batch = chains.div_ceil(2 * threads).clamp(1, MAX_BATCH);
        let seed = stream_seed(scene.settings.seed, Stream::Bootstrap);
        let choices = stream_seed(scene.settings.seed, Stream::Choices);
        let total = chains as u64 * u64::from(steps);
        let done = AtomicU64::new(0);
        let rays: u64 = (0..chains.div_ceil(batch))
            .into_par_iter()
            .map_init(
                || (Tracer::default(), Chains::new(seed), Current::default()),
                |(tracer, slots, current), b| {
                    let first = b * batch;
                    let n = batch.min(chains - first);
                    let rays = tracer.rays();
                    slots.resize(n);
                    current.resize(n);
                    // Re-trace the picked bootstrap samples (the same
                    // fresh vectors), then rename the chains so that two
                    // started at one sample part ways.
                    for slot in 0..n {
                        let chain = (first + slot) as u32;
                        let u = unit_float(hash4(choices, chain, 0, 0));
                        slots.start(slot, resampler.pick(u) as u32);
                        slots.propose_fresh(slot);
                    }
                    tracer.trace(scene, slots);
                    for slot in 0..n {
                        slots.accept(slot);
                        slots.set_chain(slot, self.bootstrap + (first + slot) as u32);
                        current.start(slot, tracer);
                    }
                    for _ in 0..steps {
                        slots.propose(&self.mutation);
                        tracer.trace(scene, slots);
                        current.step(slots, tracer, ctx.splats);
                        let d = done.fetch_add(n as u64, Ordering::Relaxed) + n as u64;
                        ctx.progress.report(d, total);
                    }
                    current.flush(n, ctx.splats);
                    tracer.rays() - rays
                },
            )
            .sum();
        pass.rays += rays;
        pass.samples += chains as u64 * (1 + u64::from(steps));
        pass.scale = boot.mean * f64::from(w) * f64::from(h) / total as f64;
        pass
    }
}
