//! `erpt`: energy redistribution path tracing (Cline et al. 2005, seed
//! 001's chapter 9), with mutations in primary sample space.
//!
//! 1. Bootstrap: `bootstrap` independent paths estimate b = ∫ I(u) du,
//!    which sets the deposition energy e_d = seeds × b / spp (so that the
//!    chains make, in expectation, the scene's samples per pixel in
//!    mutations per pixel). The seed paths never see their own b, so e_d
//!    is independent of them and the estimate stays unbiased.
//! 2. Seed paths: `seeds` path-traced samples per pixel (fresh primary
//!    sample vectors). A seed path X starts ⌊ξ + I(X) / (N · e_d)⌋ chains
//!    (N = `chain_length`): every path's energy is redistributed in equal
//!    quanta, so bright rare paths (light through a gap, caustics) spawn
//!    many chains that spread their energy over their neighbourhood.
//! 3. Each chain makes N mutations (Kelemen small mutations up to `sigma`;
//!    large steps with probability `large_step`, none by default) and
//!    every mutation deposits e_d between proposal and current state by
//!    their expected weights ([`chain`](super::chain)). Chains start where
//!    their seed is, which is distributed like the target in
//!    expectation, so there is no start-up bias (Cline's argument).
//!
//! The image is the deposits × e_d × pixels / seed paths = deposits × b /
//! spp. Seed paths are traced 1024 at a time, their chains run in
//! lockstep batches of up to 1024 as one wavefront per step; batches are
//! fixed by the seed numbers, not the threads, so the image does not
//! depend on the thread count.

use super::chain::Current;
use super::pss::{Chains, Mutation};
use super::pssmlt::{check_count, default_bootstrap, default_sigma, mutation};
use super::trace::{Stream, Tracer, bootstrap, stream_seed};
use crate::integrators::{ChainContext, ChainIntegrator, ChainPass, Family, Integrator};
use radiant_core::hash::{hash4, unit_float};
use radiant_core::{ParamDoc, ParamError, Params};
use rayon::prelude::*;
use serde::Deserialize;
use std::sync::atomic::{AtomicU64, Ordering};

/// Seed paths traced per batch; also the most chains one wavefront
/// advances.
const BATCH: usize = 1024;
/// The largest share of the budget (in mutations) one seed path's chains
/// may take.
const MAX_SHARE: f64 = 1.0 / 16.0;

/// The `erpt` integrator.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Erpt {
    /// Mutations per chain (N).
    pub chain_length: u32,
    /// Seed paths per pixel.
    pub seeds: u32,
    /// Bootstrap samples.
    pub bootstrap: u32,
    /// How proposals are made.
    pub mutation: Mutation,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct ErptParams {
    #[serde(default = "default_chain_length")]
    chain_length: u32,
    #[serde(default = "default_seeds")]
    seeds: u32,
    #[serde(default = "default_bootstrap")]
    bootstrap: u32,
    #[serde(default)]
    large_step: f32,
    #[serde(default = "default_sigma")]
    sigma: f32,
}

fn default_chain_length() -> u32 {
    256
}
fn default_seeds() -> u32 {
    16
}

/// `radiant modules`' documentation of the keys.
pub(super) const DOCS: &[ParamDoc] = &[
    ParamDoc {
        name: "chain_length",
        ty: "positive integer",
        default: "256",
        doc: "Mutations per chain (N). Longer chains spread a bright path's energy further \
              (smoother light through gaps, caustics) but with more correlated, blotchy noise; \
              with the budget fixed, fewer seeds then start a chain (N·e_d per chain), and at \
              N = 1 ERPT is a quantised path tracer.",
    },
    ParamDoc {
        name: "seeds",
        ty: "positive integer",
        default: "16",
        doc: "Path-traced seed paths per pixel. Which features get energy is decided by the \
              seeds alone, so their sampling noise is a floor that more mutations (spp) do not \
              lower: raise seeds with spp (scenes/veach-gap-room.yaml, 256 mutations per pixel: 1 \
              seed per pixel stays 220× above path's 60-s error whatever the spp, 32 seeds with \
              1024-mutation chains fall below it). Each costs a path on top of the mutations.",
    },
    ParamDoc {
        name: "bootstrap",
        ty: "positive integer",
        default: "100000",
        doc: "Independent paths that estimate the image's brightness b, which sets the \
              deposition energy e_d = seeds·b/spp (how many chains a seed starts). Its error \
              changes the number of mutations, not the expectation of the image.",
    },
    ParamDoc {
        name: "large_step",
        ty: "number in [0, 1]",
        default: "0",
        doc: "Probability that a mutation is a large step (an independent new path). ERPT's \
              chains are meant to stay local; a few large steps decorrelate them at the cost \
              of leaving the feature they were seeded on.",
    },
    ParamDoc {
        name: "sigma",
        ty: "number in (0, 1]",
        default: "0.015625",
        doc: "Largest perturbation of a primary sample by a mutation (sizes log-uniform down \
              to sigma/16). Smaller: more acceptances, energy spread less far; larger: the reverse.",
    },
];

impl Erpt {
    /// Builds the integrator from its keys.
    pub fn from_params(params: &Params) -> Result<Self, ParamError> {
        let p: ErptParams = params.parse()?;
        check_count(params, "chain_length", p.chain_length)?;
        check_count(params, "seeds", p.seeds)?;
        check_count(params, "bootstrap", p.bootstrap)?;
        Ok(Self {
            chain_length: p.chain_length,
            seeds: p.seeds,
            bootstrap: p.bootstrap,
            mutation: mutation(params, p.large_step, p.sigma)?,
        })
    }
}

impl Integrator for Erpt {
    fn family(&self) -> Family<'_> {
        Family::Chains(self)
    }
}

/// One thread's scratch: seed paths and the chains they start.
#[derive(Default)]
struct Worker {
    tracer: Tracer,
    seeds: Chains,
    seed_state: Current,
    chains: Chains,
    current: Current,
    /// Seed slot of every chain to run, in order.
    queue: Vec<u32>,
    /// Deposit factor of each seed's chains (see `MAX_SHARE`).
    seed_weight: Vec<f32>,
}

impl ChainIntegrator for Erpt {
    fn render(&self, ctx: &ChainContext<'_>) -> ChainPass {
        let scene = ctx.scene;
        let (w, h) = (scene.settings.width, scene.settings.height);
        let boot = bootstrap(scene, self.bootstrap as usize);
        let mut pass = ChainPass {
            scale: 0.0,
            samples: u64::from(self.bootstrap),
            rays: boot.rays,
        };
        if boot.mean <= 0.0 {
            return pass;
        }
        let spp = f64::from(ctx.spp.max(1));
        let seeds = u64::from(self.seeds) * u64::from(w) * u64::from(h);
        // Energy of one deposit, in units of the target (luminance).
        let energy = f64::from(self.seeds) * boot.mean / spp;
        let per_chain = energy * f64::from(self.chain_length);
        let budget = f64::from(ctx.spp.max(1)) * f64::from(w) * f64::from(h);
        let max_chains = (budget * MAX_SHARE / f64::from(self.chain_length)).max(1.0);
        let settings_seed = scene.settings.seed;
        let seed_stream = stream_seed(settings_seed, Stream::Seeds);
        let choices = stream_seed(settings_seed, Stream::Choices);
        let batches = seeds.div_ceil(BATCH as u64);
        let done = AtomicU64::new(0);
        let total = u64::from(ctx.spp) * u64::from(w) * u64::from(h);
        let (rays, samples) = (0..batches)
            .into_par_iter()
            .map_init(
                || Worker {
                    seeds: Chains::new(seed_stream),
                    ..Worker::default()
                },
                |wk, b| {
                    let rays = wk.tracer.rays();
                    let first = b * BATCH as u64;
                    let n = (BATCH as u64).min(seeds - first) as usize;
                    wk.seeds.resize(n);
                    wk.seed_state.resize(n);
                    for slot in 0..n {
                        wk.seeds.start(slot, (first + slot as u64) as u32);
                        wk.seeds.propose_fresh(slot);
                    }
                    wk.tracer.trace(scene, &wk.seeds);
                    wk.queue.clear();
                    wk.seed_weight.clear();
                    for slot in 0..n {
                        wk.seeds.accept(slot);
                        wk.seed_state.start(slot, &wk.tracer);
                        let t = f64::from(wk.tracer.target[slot]);
                        let xi = unit_float(hash4(choices, (first + slot as u64) as u32, 1, 0));
                        let chains = t / per_chain;
                        // A seed worth more chains than a share of the
                        // budget (a firefly) gets that many, each
                        // depositing proportionally more: the same
                        // expectation without one path taking the render.
                        let (count, weight) = if chains > max_chains {
                            (max_chains as usize, (chains / max_chains) as f32)
                        } else {
                            ((f64::from(xi) + chains).floor() as usize, 1.0)
                        };
                        wk.queue.extend(std::iter::repeat_n(slot as u32, count));
                        wk.seed_weight.push(weight);
                    }
                    wk.chains
                        .reseed(stream_seed(settings_seed, Stream::Redistribution(b as u32)));
                    let mut samples = n as u64;
                    let mut next_chain = 0u32;
                    for group in wk.queue.chunks(BATCH) {
                        let m = group.len();
                        wk.chains.resize(m);
                        wk.current.resize(m);
                        for (k, &seed_slot) in group.iter().enumerate() {
                            wk.chains
                                .start_from(k, next_chain, &wk.seeds, seed_slot as usize);
                            wk.current.start_from(k, &wk.seed_state, seed_slot as usize);
                            wk.current.set_weight(k, wk.seed_weight[seed_slot as usize]);
                            next_chain += 1;
                        }
                        for _ in 0..self.chain_length {
                            wk.chains.propose(&self.mutation);
                            wk.tracer.trace(scene, &wk.chains);
                            wk.current.step(&mut wk.chains, &wk.tracer, ctx.splats);
                        }
                        wk.current.flush(m, ctx.splats);
                        let mutations = m as u64 * u64::from(self.chain_length);
                        samples += mutations;
                        let d = done.fetch_add(mutations, Ordering::Relaxed) + mutations;
                        ctx.progress.report(d.min(total), total);
                    }
                    (wk.tracer.rays() - rays, samples)
                },
            )
            .reduce(|| (0, 0), |a, b| (a.0 + b.0, a.1 + b.1));
        pass.rays += rays;
        pass.samples += samples;
        // deposits × e_d × pixels / seed paths = deposits × b / spp.
        pass.scale = energy * f64::from(w) * f64::from(h) / seeds as f64;
        pass
    }
}
