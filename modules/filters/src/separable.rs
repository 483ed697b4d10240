//! Separable filters: f(x, y) = k(x) · k(y) for a 1D kernel k.
//!
//! Every built-in filter is separable (as in Mitsuba 3 and pbrt), so each
//! one only defines its 1D [`Kernel`].

use radiant_core::Filter;

/// A symmetric 1D filter kernel with compact support.
pub trait Kernel: Send + Sync {
    /// Radius of the support in pixels.
    fn radius(&self) -> f32;

    /// The kernel's value at `x` pixels from its centre, for |x| ≤ radius.
    fn eval_1d(&self, x: f32) -> f32;
}

/// The 2D filter k(x) · k(y), zero outside [−r, r]².
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Separable<K>(pub K);

impl<K: Kernel> Filter for Separable<K> {
    fn radius(&self) -> f32 {
        self.0.radius()
    }

    fn eval(&self, x: f32, y: f32) -> f32 {
        let r = self.0.radius();
        if x.abs() > r || y.abs() > r {
            0.0
        } else {
            self.0.eval_1d(x) * self.0.eval_1d(y)
        }
    }
}
