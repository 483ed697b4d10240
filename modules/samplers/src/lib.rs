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
//! `scramble` holds the hashed permutations they share, `pointwise` the
//! batch fill loops.

mod halton;
mod independent;
mod pointwise;
mod scramble;
mod seed;
mod sobol;
mod stratified;

pub use halton::Halton;
pub use independent::Independent;
pub use scramble::{nested_uniform_scramble, permute};
pub use sobol::Sobol;
pub use stratified::Stratified;

use radiant_core::{BuildContext, ModuleInfo, Params, Registry, Sampler};
use serde::Deserialize;

/// Registers every built-in sampler type.
pub fn register(registry: &mut Registry) {
    independent::register(registry);
    stratified::register(registry);
    halton::register(registry);
    sobol::register(registry);
}

/// The parameters of every built-in sampler: none (unknown keys are errors).
#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct NoParams {}

/// Registers the parameterless sampler type `type_name`, built by `make`
/// from the build context (seed, spp).
fn register_sampler<S: Sampler + 'static>(
    registry: &mut Registry,
    type_name: &'static str,
    summary: &'static str,
    make: fn(&BuildContext<'_>) -> S,
) {
    registry.register::<dyn Sampler>(
        ModuleInfo {
            type_name,
            summary,
            params: &[],
        },
        move |params: &Params, ctx| {
            let _: NoParams = params.parse()?;
            Ok(Box::new(make(ctx)) as Box<dyn Sampler>)
        },
    );
}

#[cfg(test)]
mod tests;
