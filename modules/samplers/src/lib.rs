//! # radiant-samplers: built-in sampler modules
//!
//! Samplers feed every random decision of the wavefront (pixel jitter, lens,
//! light choice, BSDF lobes, Russian roulette) with values that are a pure
//! function of (seed, pixel, sample index, dimension), so batches can run
//! in any order. The integrator asks for 1D values and 2D pairs at fixed
//! dimensions per bounce; each sampler keeps its pairs stratified and its
//! dimensions independent of each other.
//!
//! * `independent`: hashed uniform random numbers.
//! * `stratified`: jittered strata over the pixel's spp (needs the spp from
//!   the build context).
//! * `halton`: Owen-scrambled Halton.
//! * `sobol`: Owen-scrambled, shuffled Sobol (Burley 2020).
//!
//! `scramble` holds the hashed permutations they share.

mod halton;
mod independent;
mod scramble;
mod seed;
mod sobol;
mod stratified;

pub use halton::Halton;
pub use independent::Independent;
pub use scramble::{nested_uniform_scramble, permute};
pub use sobol::Sobol;
pub use stratified::Stratified;

use radiant_core::Registry;

/// Registers every built-in sampler type.
pub fn register(registry: &mut Registry) {
    independent::register(registry);
    stratified::register(registry);
    halton::register(registry);
    sobol::register(registry);
}

#[cfg(test)]
mod tests;
