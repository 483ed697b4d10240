//! One Metropolis step of a batch of chains, with expected-value deposits.
//!
//! Every step deposits one unit of weight per chain, split between the
//! proposal (its acceptance probability a) and the current state (1 − a),
//! each as radiance / target value at its raster position (Veach's
//! expected-value technique, as pbrt-v4 and Cline's ERPT deposit). A
//! current state's shares are gathered while the chain stays on it and
//! splatted once when it leaves (the GPU ERPT trick of seed 001), so a step
//! costs about one splat rather than two; a rejected proposal's share is
//! splatted at once. The caller scales the film by the energy of a unit.

use super::pss::{Chains, acceptance};
use super::trace::Tracer;
use crate::integrators::splat::SplatFilm;
use glam::Vec2;
use radiant_core::Rgb;

/// Each slot's current path (besides its primary samples).
#[derive(Debug, Default)]
pub struct Current {
    value: Vec<Rgb>,
    target: Vec<f32>,
    raster: Vec<Vec2>,
    /// Weight gathered since the state became current, not yet splatted.
    pending: Vec<f32>,
    /// Factor of every deposit of the slot's chain (1 but for the chains
    /// of a seed too bright to be split into chains of the usual energy).
    weight: Vec<f32>,
}

impl Current {
    /// Makes room for `n` slots.
    pub fn resize(&mut self, n: usize) {
        self.value.resize(n, Rgb::ZERO);
        self.target.resize(n, 0.0);
        self.raster.resize(n, Vec2::ZERO);
        self.pending.resize(n, 0.0);
        self.weight.resize(n, 1.0);
    }

    /// Makes slot `slot`'s last traced proposal (in `tracer`) its current
    /// state, with nothing gathered (a chain's start).
    pub fn start(&mut self, slot: usize, tracer: &Tracer) {
        self.value[slot] = tracer.value[slot];
        self.target[slot] = tracer.target[slot];
        self.raster[slot] = tracer.raster(slot);
        self.pending[slot] = 0.0;
        self.weight[slot] = 1.0;
    }

    /// Starts slot `slot` on slot `from` of `other` (its current state).
    pub fn start_from(&mut self, slot: usize, other: &Current, from: usize) {
        self.value[slot] = other.value[from];
        self.target[slot] = other.target[from];
        self.raster[slot] = other.raster[from];
        self.pending[slot] = 0.0;
        self.weight[slot] = 1.0;
    }

    /// Multiplies every deposit of slot `slot`'s chain by `weight`.
    pub fn set_weight(&mut self, slot: usize, weight: f32) {
        self.weight[slot] = weight;
    }

    /// The target value of slot `slot`'s current state.
    pub fn target(&self, slot: usize) -> f32 {
        self.target[slot]
    }

    /// One step of slots `0..chains.len()` after `tracer` traced their
    /// proposals: deposits, then acceptance or rejection. Returns the
    /// number of accepted proposals.
    pub fn step(&mut self, chains: &mut Chains, tracer: &Tracer, splats: &SplatFilm) -> usize {
        let mut accepted = 0;
        for slot in 0..chains.len() {
            let proposed = tracer.target[slot];
            let a = acceptance(self.target[slot], proposed);
            self.pending[slot] += 1.0 - a;
            if chains.acceptance_draw(slot) < a {
                self.flush_slot(slot, splats);
                chains.accept(slot);
                self.value[slot] = tracer.value[slot];
                self.target[slot] = proposed;
                self.raster[slot] = tracer.raster(slot);
                self.pending[slot] = a;
                accepted += 1;
            } else if a > 0.0 && proposed > 0.0 {
                let w = self.weight[slot] * a / proposed;
                splats.splat(tracer.raster(slot), tracer.value[slot] * w);
            }
        }
        accepted
    }

    /// Splats what every slot's current state has gathered.
    pub fn flush(&mut self, n: usize, splats: &SplatFilm) {
        for slot in 0..n {
            self.flush_slot(slot, splats);
        }
    }

    fn flush_slot(&mut self, slot: usize, splats: &SplatFilm) {
        let (w, t) = (self.pending[slot], self.target[slot]);
        if w > 0.0 && t > 0.0 {
            let w = self.weight[slot] * w / t;
            splats.splat(self.raster[slot], self.value[slot] * w);
        }
        self.pending[slot] = 0.0;
    }
}
