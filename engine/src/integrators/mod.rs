//! Integrators: the light-transport algorithms.
//!
//! [`path`] is a wavefront unidirectional path tracer: a batch of camera
//! paths advances one bounce at a time through the stages generate → trace
//! → emission → sort by material → shade → next-event estimation → shadow
//! rays → continue/compact, and finally splats into the film.
//!
//! [`module`] makes integrators a module kind (`integrator: {type: …}`,
//! registered in the [`Registry`](radiant_core::Registry)) with a driver
//! per family — image tiles, Markov chains — and [`splat`] is the
//! whole-image film that light paths and chains splat into ([`strategies`]:
//! one such film per sampling strategy, for per-strategy images); [`adaptive`]
//! stops sampling converged pixels in the tile driver, and [`budget`]
//! spreads a fixed budget of samples where they lower the mean squared
//! error most.

pub mod adaptive;
pub mod bdpt;
pub mod budget;
mod buffer;
mod medium;
pub mod mlt;
pub mod module;
pub mod path;
mod shading_order;
mod sort;
pub mod splat;
pub mod strategies;
pub mod surface;

pub use module::{
    Batch, ChainContext, ChainIntegrator, ChainPass, Family, Integrator, TileContext,
    TileIntegrator, TileOutput, TileWorker,
};
pub use splat::SplatFilm;
