//! Piecewise-constant distributions for sampling tabulated functions.
//!
//! A module that samples a tabulated function (a pixel filter's footprint,
//! an environment map) builds one of these once, at build time, from
//! non-negative cell weights; sampling is then two short searches and no
//! allocation.
//!
//! Each 1D distribution keeps a guide table (the cutpoint method of Chen
//! and Asau 1974): for `g` equal steps of u, the first cell that u at the
//! step's start can fall in. A sample searches only the cells between two
//! neighbouring entries (usually one or two) instead of the whole CDF, and
//! finds the very cell the whole-CDF search finds.

use glam::{UVec2, Vec2};

/// A 1D piecewise-constant distribution over [0, 1) with `n` equal cells.
#[derive(Debug, Clone, PartialEq)]
pub struct Distribution1D {
    /// Cumulative probabilities, `n + 1` entries from 0 to 1.
    cdf: Vec<f32>,
    /// `g + 1` entries for a power of two `g`: entry k is where
    /// [`Distribution1D::search`] puts u = k / g (0 for k = 0, so that a
    /// negative or NaN u searches from the start), the last one is
    /// `n + 1`.
    guide: Vec<u32>,
    /// Sum of the weights.
    total: f64,
}

impl Distribution1D {
    /// A distribution proportional to `weights` (non-negative, finite; an
    /// all-zero input gives the uniform distribution).
    pub fn new(weights: &[f32]) -> Self {
        let n = weights.len().max(1);
        let total: f64 = weights.iter().map(|&w| w.max(0.0) as f64).sum();
        let mut cdf = Vec::with_capacity(n + 1);
        cdf.push(0.0);
        let mut acc = 0.0f64;
        for i in 0..n {
            acc += if total > 0.0 {
                weights.get(i).map_or(0.0, |&w| w.max(0.0) as f64) / total
            } else {
                1.0 / n as f64
            };
            cdf.push(acc as f32);
        }
        cdf[n] = 1.0;
        // At most 2^24 steps, so that every k / g is exact in f32.
        let g = n.next_power_of_two().min(1 << 24);
        let mut guide: Vec<u32> = (0..g)
            .map(|k| cdf.partition_point(|&c| c <= k as f32 / g as f32) as u32)
            .collect();
        guide[0] = 0;
        guide.push(cdf.len() as u32);
        Self { cdf, guide, total }
    }

    /// The number of CDF entries ≤ `u`, found between the guide table's
    /// entries around `u`: u ∈ [k/g, (k+1)/g) (exact, g is a power of two)
    /// puts it between entries k and k + 1, as the CDF is non-decreasing.
    #[inline(always)]
    fn search(&self, u: f32) -> usize {
        let g = self.guide.len() - 1;
        // The float-to-int cast saturates: negative and NaN u give 0.
        let k = ((u * g as f32) as usize).min(g - 1);
        let (lo, hi) = (self.guide[k] as usize, self.guide[k + 1] as usize);
        lo + self.cdf[lo..hi].partition_point(|&c| c <= u)
    }

    /// Number of cells.
    pub fn len(&self) -> usize {
        self.cdf.len() - 1
    }

    /// Whether the distribution has no cells (never: an empty input gives
    /// one uniform cell).
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// Sum of the weights it was built from.
    pub fn total(&self) -> f64 {
        self.total
    }

    /// The cumulative probabilities, `len() + 1` entries from 0 to 1 (what
    /// a GPU side samples from).
    pub fn cdf(&self) -> &[f32] {
        &self.cdf
    }

    /// Probability of cell `i`.
    #[inline]
    pub fn cell_probability(&self, i: usize) -> f32 {
        self.cdf[i + 1] - self.cdf[i]
    }

    /// Samples a cell with `u` in [0, 1); returns the cell and `u`
    /// re-scaled to [0, 1) within it.
    #[inline(always)]
    pub fn sample(&self, u: f32) -> (usize, f32) {
        let n = self.len();
        let i = self.search(u).clamp(1, n) - 1;
        let width = self.cdf[i + 1] - self.cdf[i];
        let rest = if width > 0.0 {
            ((u - self.cdf[i]) / width).clamp(0.0, crate::ONE_MINUS_EPSILON)
        } else {
            0.5
        };
        (i, rest)
    }
}

/// A 2D piecewise-constant distribution over [0, 1)² with `size.x × size.y`
/// equal cells: a marginal over rows and a conditional per row.
#[derive(Debug, Clone, PartialEq)]
pub struct Distribution2D {
    size: UVec2,
    rows: Vec<Distribution1D>,
    marginal: Distribution1D,
}

impl Distribution2D {
    /// A distribution proportional to `weights`, `size.x` per row, rows
    /// from y = 0 up.
    ///
    /// # Panics
    /// If `weights.len() != size.x * size.y`.
    pub fn new(weights: &[f32], size: UVec2) -> Self {
        assert_eq!(weights.len(), (size.x * size.y) as usize);
        let rows: Vec<Distribution1D> = weights
            .chunks_exact(size.x as usize)
            .map(Distribution1D::new)
            .collect();
        let row_totals: Vec<f32> = rows.iter().map(|r| r.total() as f32).collect();
        let marginal = Distribution1D::new(&row_totals);
        Self {
            size,
            rows,
            marginal,
        }
    }

    /// Sum of all weights.
    pub fn total(&self) -> f64 {
        self.marginal.total()
    }

    /// The distribution over rows.
    pub fn marginal(&self) -> &Distribution1D {
        &self.marginal
    }

    /// The distribution within each row, from y = 0 up.
    pub fn rows(&self) -> &[Distribution1D] {
        &self.rows
    }

    /// Samples a point of [0, 1)²; returns it and its cell.
    #[inline]
    pub fn sample(&self, u: Vec2) -> (Vec2, UVec2) {
        let (y, ry) = self.marginal.sample(u.y);
        let (x, rx) = self.rows[y].sample(u.x);
        let p = Vec2::new(
            (x as f32 + rx) / self.size.x as f32,
            (y as f32 + ry) / self.size.y as f32,
        );
        (p, UVec2::new(x as u32, y as u32))
    }

    /// Density (with respect to area on [0, 1)²) of cell `cell`.
    #[inline]
    pub fn pdf(&self, cell: UVec2) -> f32 {
        self.marginal.cell_probability(cell.y as usize)
            * self.rows[cell.y as usize].cell_probability(cell.x as usize)
            * (self.size.x * self.size.y) as f32
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn one_dimensional_cells_get_their_share() {
        let d = Distribution1D::new(&[1.0, 0.0, 3.0]);
        assert_eq!(d.total(), 4.0);
        assert_eq!(d.sample(0.0).0, 0);
        assert_eq!(d.sample(0.2).0, 0);
        // The empty middle cell is never chosen.
        assert_eq!(d.sample(0.25).0, 2);
        let (i, r) = d.sample(0.625);
        assert_eq!(i, 2);
        assert!((r - 0.5).abs() < 1e-6);
        assert!(d.sample(0.999_999).1 < 1.0);
    }

    #[test]
    fn the_guide_table_finds_the_cell_the_whole_cdf_search_finds() {
        // Uneven weights with empty cells and runs of tiny ones, so that
        // guide steps hold many cells or none, and u on the CDF's values.
        let weights: Vec<f32> = (0..37)
            .map(|i| match i % 7 {
                0 => 0.0,
                3 => 40.0,
                _ => 1e-3 * i as f32,
            })
            .collect();
        for d in [Distribution1D::new(&weights), Distribution1D::new(&[2.0])] {
            let mut us: Vec<f32> = (0..=4096).map(|i| i as f32 / 4096.0).collect();
            us.extend(
                d.cdf()
                    .iter()
                    .flat_map(|&c| [c, c.next_down(), c.next_up()]),
            );
            us.extend([-1.0, f32::NAN, 1.0, 2.0, f32::INFINITY, -0.0]);
            for u in us {
                let whole = d.cdf.partition_point(|&c| c <= u);
                assert_eq!(d.search(u), whole, "u = {u}");
            }
        }
    }

    #[test]
    fn all_zero_weights_give_the_uniform_distribution() {
        let d = Distribution1D::new(&[0.0; 4]);
        assert_eq!(d.sample(0.6).0, 2);
        assert!((d.cell_probability(1) - 0.25).abs() < 1e-7);
    }

    #[test]
    fn two_dimensional_pdf_matches_weights() {
        let w = [1.0, 2.0, 3.0, 0.0, 0.0, 2.0];
        let d = Distribution2D::new(&w, UVec2::new(3, 2));
        for (i, &wi) in w.iter().enumerate() {
            let cell = UVec2::new(i as u32 % 3, i as u32 / 3);
            let expected = wi / 8.0 * 6.0;
            assert!((d.pdf(cell) - expected).abs() < 1e-6, "{cell}");
        }
        let (p, cell) = d.sample(Vec2::new(0.99, 0.99));
        assert_eq!(cell, UVec2::new(2, 1));
        assert!(p.x < 1.0 && p.y < 1.0 && p.y >= 0.5);
    }
}
