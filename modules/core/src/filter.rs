//! Pixel reconstruction filters.
//!
//! The film splats every sample into the pixels within the filter's radius,
//! weighting it by the filter (Mitsuba 3 and pbrt semantics: a pixel's value
//! is Σ w·L / Σ w). The engine tabulates [`Filter::eval`] once, so filters
//! cost nothing per sample beyond a table lookup.

/// A reconstruction filter module.
pub trait Filter: Send + Sync {
    /// Radius of the filter's support in pixels (same on both axes).
    fn radius(&self) -> f32;

    /// The filter's value at offset (`x`, `y`) pixels from its centre.
    fn eval(&self, x: f32, y: f32) -> f32;
}
