//! Metropolis light transport in primary sample space.
//!
//! [`pss`] holds the state of many Markov chains at once and serves their
//! proposals to the wavefront path tracer as a sampler, so that every
//! chain's proposal of one iteration is traced in one batch.

pub mod pss;
