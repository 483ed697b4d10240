//! Integrators: the light-transport algorithms.
//!
//! [`path`] is a wavefront unidirectional path tracer: a batch of camera
//! paths advances one bounce at a time through the stages generate → trace
//! → emission → sort by material → shade → next-event estimation → shadow
//! rays → continue/compact, and finally splats into the film.

mod medium;
pub mod path;
mod sort;
pub mod surface;
