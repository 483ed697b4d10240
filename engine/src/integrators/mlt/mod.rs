//! Metropolis light transport in primary sample space: the `pssmlt` and
//! `erpt` integrators of the Markov-chain family.
//!
//! The data flow of one step of a batch of chains: [`pss::Chains`] builds
//! every chain's proposal (a vector of primary samples: Kelemen small
//! mutation or large step) → [`trace::Tracer`] reads each proposal's raster
//! position from its first two coordinates and traces all proposals as one
//! wavefront through the path tracer, with the chains as its sampler →
//! [`chain::Current`] accepts or rejects each proposal and deposits the
//! expected values of proposal and current state into the frame's
//! [`SplatFilm`](super::SplatFilm). [`pssmlt`] and [`erpt`] differ in where
//! chains start and how long they run: from bootstrap samples over the
//! whole budget, or from path-traced seed paths in equal energy quanta.
//!
//! Both estimate the same image as `path`: a path's contribution is the
//! path tracer's own estimator (next-event estimation and MIS included)
//! seen as a function of its primary samples, and both Metropolis
//! estimators are unbiased for its integral up to the bootstrap (pssmlt:
//! b's error scales the image and chains start from a finite resampled
//! bootstrap; erpt: unbiased). Dimensions the chains do not hold — those a
//! medium draws from the scene's sampler — are fresh for every proposal,
//! which keeps the chains correct as a pseudo-marginal Metropolis method
//! (the kept estimate is the current state's).

pub mod chain;
pub mod erpt;
pub mod pss;
pub mod pssmlt;
pub mod trace;

use super::Integrator;
use radiant_core::{BuildContext, ModuleInfo, ParamError, Params, Registry};

/// Registers `pssmlt` and `erpt`.
pub fn register(registry: &mut Registry) {
    registry.register::<dyn Integrator>(
        ModuleInfo {
            type_name: "pssmlt",
            summary: "Primary-sample-space Metropolis light transport (Kelemen): chains of path-tracer \
                      samples with small mutations and large steps, bootstrapped normalisation; \
                      spp = mutations per pixel. Wins where light arrives through narrow paths.",
            params: pssmlt::DOCS,
        },
        |params: &Params, _: &mut BuildContext<'_>| -> Result<Box<dyn Integrator>, ParamError> {
            Ok(Box::new(pssmlt::Pssmlt::from_params(params)?))
        },
    );
    registry.register::<dyn Integrator>(
        ModuleInfo {
            type_name: "erpt",
            summary: "Energy redistribution path tracing (Cline): path-traced seed paths start \
                      chains of primary-sample-space mutations that deposit equal energy; \
                      spp = mutations per pixel.",
            params: erpt::DOCS,
        },
        |params: &Params, _: &mut BuildContext<'_>| -> Result<Box<dyn Integrator>, ParamError> {
            Ok(Box::new(erpt::Erpt::from_params(params)?))
        },
    );
}

#[cfg(test)]
mod tests {
    use radiant_core::params::check_param_docs;

    #[test]
    fn documented_keys_are_the_accepted_ones() {
        check_param_docs::<super::pssmlt::PssmltParams>(super::pssmlt::DOCS)
            .expect("pssmlt's documentation");
        check_param_docs::<super::erpt::ErptParams>(super::erpt::DOCS)
            .expect("erpt's documentation");
    }
}
