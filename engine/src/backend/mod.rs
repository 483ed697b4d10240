//! Backends run the integrator over the frame. [`cpu`] uses every core
//! through rayon.

pub mod cpu;
