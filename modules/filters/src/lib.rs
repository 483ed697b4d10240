//! # radiant-filters: built-in pixel reconstruction filters
//!
//! The film (the last stage of the wavefront) splats each sample into the
//! pixels within a filter's radius; these modules define the weights. All
//! of them are separable products of a 1D [`Kernel`] (`separable`), one
//! file per kernel.

mod blackman_harris;
mod box_filter;
mod gaussian;
mod lanczos;
mod mitchell;
mod separable;
mod tent;
mod validate;

pub use blackman_harris::{BLACKMAN_HARRIS, BlackmanHarrisFilter, BlackmanHarrisKernel};
pub use box_filter::{BoxFilter, BoxKernel};
pub use gaussian::{GaussianFilter, GaussianKernel};
pub use lanczos::{LanczosFilter, LanczosKernel};
pub use mitchell::{MitchellFilter, MitchellKernel};
pub use separable::{Kernel, Separable};
pub use tent::{TentFilter, TentKernel};

use radiant_core::Registry;

/// Registers every built-in filter type.
pub fn register(registry: &mut Registry) {
    box_filter::register(registry);
    gaussian::register(registry);
    tent::register(registry);
    mitchell::register(registry);
    lanczos::register(registry);
    blackman_harris::register(registry);
}

#[cfg(test)]
mod tests;
