//! Pixel reconstruction filters.
//!
//! The film splats every sample into the pixels within the filter's radius,
//! weighting it by the filter (Mitsuba 3 and pbrt semantics: a pixel's value
//! is Σ w·L / Σ w). The engine tabulates [`Filter::eval`] once, so filters
//! cost nothing per sample beyond a table lookup.
//!
//! [`FilterSampler`] is the alternative for wide filters: instead of
//! splatting a uniformly placed sample into every pixel in reach, a film
//! can draw the sample's offset from the pixel centre in proportion to |f|
//! and give it the weight f/pdf (pbrt-v4's filter importance sampling).

use crate::distribution::Distribution2D;
use glam::{UVec2, Vec2};

/// A reconstruction filter module.
pub trait Filter: Send + Sync {
    /// Radius of the filter's support in pixels (same on both axes).
    fn radius(&self) -> f32;

    /// The filter's value at offset (`x`, `y`) pixels from its centre.
    fn eval(&self, x: f32, y: f32) -> f32;
}

/// Importance sampling of a filter's footprint: a piecewise-constant
/// distribution proportional to |f|, tabulated once from [`Filter::eval`]
/// at cell centres over [−r, r]².
#[derive(Debug, Clone, PartialEq)]
pub struct FilterSampler {
    radius: f32,
    res: u32,
    /// f at the cell centres, row-major from (−r, −r).
    values: Vec<f32>,
    distribution: Distribution2D,
    abs_integral: f32,
}

impl FilterSampler {
    /// Cells per axis over the filter's support [−r, r].
    pub const DEFAULT_RESOLUTION: u32 = 64;

    /// Tabulates `filter` on a `res × res` grid over its support.
    pub fn new(filter: &dyn Filter, res: u32) -> Self {
        let res = res.max(1);
        let radius = filter.radius();
        let cell = 2.0 * radius / res as f32;
        let values: Vec<f32> = (0..res * res)
            .map(|i| {
                let x = -radius + ((i % res) as f32 + 0.5) * cell;
                let y = -radius + ((i / res) as f32 + 0.5) * cell;
                filter.eval(x, y)
            })
            .collect();
        let abs: Vec<f32> = values.iter().map(|v| v.abs()).collect();
        let distribution = Distribution2D::new(&abs, UVec2::splat(res));
        let abs_integral = (distribution.total() * (cell * cell) as f64) as f32;
        Self {
            radius,
            res,
            values,
            distribution,
            abs_integral,
        }
    }

    /// The filter's radius in pixels.
    pub fn radius(&self) -> f32 {
        self.radius
    }

    /// f at the cell centres, row-major from (−r, −r).
    pub fn values(&self) -> &[f32] {
        &self.values
    }

    /// The distribution offsets are drawn from (proportional to |f|).
    pub fn distribution(&self) -> &Distribution2D {
        &self.distribution
    }

    /// ∫|f| over the support, as tabulated.
    pub fn abs_integral(&self) -> f32 {
        self.abs_integral
    }

    /// Draws an offset from the pixel centre (in pixels) with density
    /// |f|/∫|f| and returns it with its weight f/pdf (= ±∫|f|, the sign of
    /// f where the offset landed).
    #[inline]
    pub fn sample(&self, u: Vec2) -> (Vec2, f32) {
        let (p, cell) = self.distribution.sample(u);
        let offset = (2.0 * p - Vec2::ONE) * self.radius;
        let f = self.values[(cell.y * self.res + cell.x) as usize];
        (offset, self.abs_integral.copysign(f))
    }

    /// Density (per square pixel) with which [`sample`](Self::sample)
    /// produces `offset`.
    pub fn pdf(&self, offset: Vec2) -> f32 {
        let p = (offset / self.radius + Vec2::ONE) * 0.5 * self.res as f32;
        if p.x < 0.0 || p.y < 0.0 || p.x >= self.res as f32 || p.y >= self.res as f32 {
            return 0.0;
        }
        let area = (2.0 * self.radius).powi(2);
        self.distribution.pdf(p.as_uvec2()) / area
    }
}
