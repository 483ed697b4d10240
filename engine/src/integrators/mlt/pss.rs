//! Primary sample space: the state of many Metropolis chains at once.
//!
//! A path is a pure function of its primary samples, the numbers in [0, 1)
//! that the integrator asks the sampler for, dimension by dimension
//! (Kelemen et al. 2002). A chain's state is such a vector. [`Chains`]
//! holds one current vector and one proposal per chain slot, builds the
//! proposals of all slots at once (a Kelemen small mutation of every stored
//! coordinate, or a large step that forgets them all), and serves the
//! proposals to the path tracer as a [`Sampler`] whose `SampleId::pixel` is
//! the slot. Vectors grow lazily: a dimension a vector does not hold yet is
//! a fresh uniform number, hashed from the seed, the chain and its step, so
//! a coordinate first read by a proposal is drawn as Kelemen draws it; the
//! coordinates a proposal read are stored when it is accepted (the
//! sampler counts how far each slot read). Rejection keeps the current
//! vector: the proposal buffer is rebuilt from it at the next step, and
//! acceptance swaps the two buffers, so nothing is copied back and, once
//! the vectors have reached the length the paths need, nothing allocates.
//!
//! All randomness of a step (large or small, each perturbation, the
//! acceptance test) is hashed from (seed, chain, step), so a chain's run
//! does not depend on how chains were grouped into batches or threads.

use radiant_core::hash::{hash4, unit_float};
use radiant_core::{SampleId, Sampler};
use std::sync::atomic::{AtomicU32, Ordering};

/// Salts that keep the hash streams of one (chain, step) apart.
const FRESH: u32 = 0x6d6c_7431;
const PERTURB: u32 = 0x6d6c_7432;
const DECIDE: u32 = 0x6d6c_7433;

/// How proposals are made.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Mutation {
    /// Probability that a proposal is a large step: a vector of fresh
    /// uniform numbers, independent of the current one.
    pub large_step: f32,
    /// Largest perturbation of a small mutation. Each coordinate moves by
    /// ±s with s log-uniform in [sigma/16, sigma] (Kelemen's s2 = 1/64,
    /// s1 = 1/1024 for the default) and wraps around [0, 1).
    pub sigma: f32,
}

impl Default for Mutation {
    fn default() -> Self {
        Self {
            large_step: 0.3,
            sigma: 1.0 / 64.0,
        }
    }
}

/// The Kelemen perturbation of `x` by the 32 random bits `bits` (sign from
/// the low bit, log-uniform size from the high ones), wrapped into [0, 1).
/// The kernel is symmetric: moving from `y` back to `x` is as likely.
#[inline]
pub fn perturb(x: f32, bits: u32, sigma: f32) -> f32 {
    // ln 16: the ratio of the largest to the smallest step.
    const LOG_RATIO: f32 = 2.772_588_8;
    let size = sigma * (-LOG_RATIO * unit_float(bits)).exp();
    let mut y = if bits & 1 == 0 { x + size } else { x - size };
    if y >= 1.0 {
        y -= 1.0;
    }
    if y < 0.0 {
        y += 1.0;
    }
    // x − size may round to exactly 1 after the wrap.
    if y >= 1.0 { 0.0 } else { y }
}

/// Metropolis–Hastings acceptance probability of moving from a state with
/// target value `current` to one with `proposed` (symmetric proposals; a
/// chain that sits on a zero accepts anything).
#[inline]
pub fn acceptance(current: f32, proposed: f32) -> f32 {
    if current > 0.0 {
        (proposed / current).min(1.0)
    } else {
        1.0
    }
}

/// The primary-sample vectors of a batch of chains (see the module docs).
#[derive(Debug, Default)]
pub struct Chains {
    seed: u32,
    /// Slots in use; the buffers beyond stay allocated for reuse.
    active: usize,
    /// Each slot's chain number (hash input; unique over a render).
    chain: Vec<u32>,
    /// Each slot's step count (hash input; the proposal being built).
    step: Vec<u32>,
    current: Vec<Vec<f32>>,
    proposal: Vec<Vec<f32>>,
    /// Whether the slot's proposal is a large step.
    large: Vec<bool>,
    /// One past the highest dimension the slot's proposal was asked for.
    read: Vec<AtomicU32>,
}

impl Chains {
    /// An empty batch for the render with seed `seed`.
    pub fn new(seed: u32) -> Self {
        Self {
            seed: hash4(seed, FRESH, PERTURB, DECIDE),
            ..Self::default()
        }
    }

    /// Keeps the buffers but draws from the render seed `seed` from now on
    /// (a new stream of chains).
    pub fn reseed(&mut self, seed: u32) {
        self.seed = Self::new(seed).seed;
    }

    /// Number of slots.
    pub fn len(&self) -> usize {
        self.active
    }

    /// Whether there are no slots.
    pub fn is_empty(&self) -> bool {
        self.active == 0
    }

    /// Makes the batch `n` slots long (slots keep their buffers when the
    /// batch shrinks, for the next time it grows); a slot must be started
    /// before it is used.
    pub fn resize(&mut self, n: usize) {
        if n > self.chain.len() {
            self.chain.resize(n, 0);
            self.step.resize(n, 0);
            self.current.resize_with(n, Vec::new);
            self.proposal.resize_with(n, Vec::new);
            self.large.resize(n, false);
            self.read.resize_with(n, || AtomicU32::new(0));
        }
        self.active = n;
    }

    /// Renames the chain in `slot` (its stored state stays): chains started
    /// from the same bootstrap sample then mutate independently.
    pub fn set_chain(&mut self, slot: usize, chain: u32) {
        self.chain[slot] = chain;
    }

    /// Starts chain number `chain` in `slot` with no stored coordinates:
    /// its first proposal (whatever [`Chains::propose`] decides) reads
    /// fresh uniform numbers only, the independent sample a bootstrap or
    /// an ERPT seed path needs.
    pub fn start(&mut self, slot: usize, chain: u32) {
        self.chain[slot] = chain;
        self.step[slot] = 0;
        self.current[slot].clear();
        self.proposal[slot].clear();
        self.large[slot] = true;
        *self.read[slot].get_mut() = 0;
    }

    /// Starts `slot` on a copy of the current state of slot `from` (of
    /// `source`), as chain number `chain`.
    pub fn start_from(&mut self, slot: usize, chain: u32, source: &Chains, from: usize) {
        self.start(slot, chain);
        self.current[slot].extend_from_slice(&source.current[from]);
    }

    /// Builds the proposal of every slot: with probability
    /// `mutation.large_step` a large step (no stored coordinates, so every
    /// dimension reads fresh), otherwise every stored coordinate perturbed.
    pub fn propose(&mut self, mutation: &Mutation) {
        for slot in 0..self.len() {
            self.propose_slot(slot, mutation);
        }
    }

    /// Makes the proposal of `slot` a large step, whatever the mutation
    /// would choose (a bootstrap sample or an ERPT seed path).
    pub fn propose_fresh(&mut self, slot: usize) {
        self.step[slot] = self.step[slot].wrapping_add(1);
        self.proposal[slot].clear();
        self.large[slot] = true;
        *self.read[slot].get_mut() = 0;
    }

    fn propose_slot(&mut self, slot: usize, mutation: &Mutation) {
        let step = self.step[slot].wrapping_add(1);
        self.step[slot] = step;
        let chain = self.chain[slot];
        *self.read[slot].get_mut() = 0;
        let decide = unit_float(hash4(self.seed ^ DECIDE, chain, step, 0));
        let proposal = &mut self.proposal[slot];
        proposal.clear();
        self.large[slot] = decide < mutation.large_step;
        if self.large[slot] {
            return;
        }
        let salt = self.seed ^ PERTURB;
        proposal.extend(
            self.current[slot]
                .iter()
                .zip(0u32..)
                .map(|(&x, d)| perturb(x, hash4(salt, chain, step, d), mutation.sigma)),
        );
    }

    /// Whether the proposal of `slot` is a large step.
    pub fn is_large(&self, slot: usize) -> bool {
        self.large[slot]
    }

    /// The uniform number that decides the acceptance of `slot`'s
    /// proposal (accept where it is below the acceptance probability).
    pub fn acceptance_draw(&self, slot: usize) -> f32 {
        unit_float(hash4(
            self.seed ^ DECIDE,
            self.chain[slot],
            self.step[slot],
            1,
        ))
    }

    /// The proposal's value of dimension `dim` in `slot`.
    #[inline]
    fn value(&self, slot: usize, dim: u32) -> f32 {
        let stored = &self.proposal[slot];
        match stored.get(dim as usize) {
            Some(&v) => v,
            None => unit_float(hash4(
                self.seed ^ FRESH,
                self.chain[slot],
                self.step[slot],
                dim,
            )),
        }
    }

    /// Makes `slot`'s proposal its current state, storing every coordinate
    /// the proposal was asked for (those it read fresh included).
    pub fn accept(&mut self, slot: usize) {
        let read = *self.read[slot].get_mut();
        for dim in self.proposal[slot].len() as u32..read {
            let v = self.value(slot, dim);
            self.proposal[slot].push(v);
        }
        std::mem::swap(&mut self.current[slot], &mut self.proposal[slot]);
    }

    /// The current state of `slot`'s coordinates (those stored so far).
    pub fn current(&self, slot: usize) -> &[f32] {
        &self.current[slot]
    }

    /// The step counter of `slot` (distinct for each proposal of a chain).
    pub fn step(&self, slot: usize) -> u32 {
        self.step[slot]
    }

    /// The chain number in `slot`.
    pub fn chain(&self, slot: usize) -> u32 {
        self.chain[slot]
    }

    #[inline]
    fn note_read(&self, slot: usize, end: u32) {
        self.read[slot].fetch_max(end, Ordering::Relaxed);
    }
}

/// The proposals as a sampler: `SampleId::pixel` is the slot, the index is
/// ignored.
impl Sampler for Chains {
    fn fill_2d(&self, ids: &[SampleId], dim: u32, out: &mut [glam::Vec2]) {
        for (id, o) in ids.iter().zip(out) {
            let slot = id.pixel as usize;
            self.note_read(slot, dim + 2);
            *o = glam::Vec2::new(self.value(slot, dim), self.value(slot, dim + 1));
        }
    }

    fn fill_1d(&self, ids: &[SampleId], dim: u32, out: &mut [f32]) {
        for (id, o) in ids.iter().zip(out) {
            let slot = id.pixel as usize;
            self.note_read(slot, dim + 1);
            *o = self.value(slot, dim);
        }
    }
}
