//! The `stratified` sampler: jittered stratification of each pixel's
//! samples, per dimension and per pair of dimensions.
//!
//! With N = spp samples per pixel, a 1D dimension puts exactly one sample
//! in each of the N strata [k/N, (k+1)/N), jittered within it; a 2D pair
//! uses a multi-jittered pattern (Chiu et al. 1994, with Kensler's 2013
//! hashed permutations): an m × n grid (m ≈ √N) with one sample per cell
//! *and* one per fine stratum of either axis. Which sample gets which stratum is a hashed
//! permutation keyed by (seed, pixel, dimension), so the sampler stays
//! stateless and dimensions are independent of each other. Sample indices
//! beyond N start a fresh, independently shuffled pattern.

use crate::pointwise::{Pointwise, pointwise_sampler};
use crate::scramble::{SCRAMBLE_WGSL, permute};
use crate::seed::fold;
use radiant_core::glam::Vec2;
use radiant_core::hash::{hash_u32, hash4, unit_float};
use radiant_core::{GpuModule, GpuParams, ONE_MINUS_EPSILON, Registry, SampleId};

/// Jittered stratified sampling over `spp` samples per pixel.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Stratified {
    seed: u32,
    spp: u32,
    /// Columns and rows of the 2D grid, `cols × rows ≥ spp`.
    cols: u32,
    rows: u32,
}

impl Stratified {
    /// A stratified sampler for `spp` samples per pixel (at least 1).
    pub fn new(seed: u64, spp: u32) -> Self {
        let spp = spp.max(1);
        let cols = ((spp as f64).sqrt().round() as u32).max(1);
        let rows = spp.div_ceil(cols);
        Self {
            seed: fold(seed),
            spp,
            cols,
            rows,
        }
    }

    /// The pattern key and the sample's position within its pattern.
    #[inline]
    fn key(&self, id: SampleId, dim: u32) -> (u32, u32) {
        let round = id.index / self.spp;
        let key = hash4(self.seed, id.pixel, dim, round);
        (key, permute(id.index % self.spp, self.spp, key))
    }
}

impl Pointwise for Stratified {
    #[inline]
    fn value_1d(&self, id: SampleId, dim: u32) -> f32 {
        let (key, s) = self.key(id, dim);
        let jitter = unit_float(hash_u32(key ^ id.index.wrapping_mul(0x2c1b_3c6d)));
        ((s as f32 + jitter) / self.spp as f32).min(ONE_MINUS_EPSILON)
    }

    #[inline]
    fn value_2d(&self, id: SampleId, dim: u32) -> Vec2 {
        let (key, s) = self.key(id, dim | 0x8000_0000);
        let (m, n) = (self.cols, self.rows);
        let (col, row) = (s % m, s / m);
        // Fine strata: within column `col` the rows take distinct x
        // sub-strata, within row `row` the columns distinct y sub-strata.
        // The permutations differ per column and per row (Kensler's
        // "correlated" variant shares them, which slows convergence on
        // smooth integrands to N^-0.75).
        let sx = permute(row, n, hash_u32(key ^ col.wrapping_mul(0xa511_e9b3)));
        let sy = permute(
            col,
            m,
            hash_u32(key ^ row.wrapping_mul(0x63d8_3595) ^ 0x68e3_1da4),
        );
        let jx = unit_float(hash_u32(key ^ s.wrapping_mul(0xa399_d265)));
        let jy = unit_float(hash_u32(key ^ s.wrapping_mul(0x711a_d6a5) ^ 0x5bd1_e995));
        let x = (col as f32 + (sx as f32 + jx) / n as f32) / m as f32;
        let y = (row as f32 + (sy as f32 + jy) / m as f32) / n as f32;
        Vec2::new(x.min(ONE_MINUS_EPSILON), y.min(ONE_MINUS_EPSILON))
    }

    fn gpu(&self) -> Option<GpuModule> {
        Some(
            GpuModule::new(
                "stratified",
                include_str!("stratified.wgsl"),
                GpuParams::new()
                    .u32(self.seed)
                    .u32(self.spp)
                    .u32(self.cols)
                    .u32(self.rows),
            )
            .with_libraries(&[SCRAMBLE_WGSL]),
        )
    }
}

pointwise_sampler!(Stratified);

pub(crate) fn register(registry: &mut Registry) {
    crate::register_sampler(
        registry,
        "stratified",
        "Jittered stratified samples over the pixel's spp (multi-jittered in 2D).",
        |ctx| Stratified::new(ctx.seed, ctx.spp),
    );
}

#[cfg(test)]
mod tests {
    use super::*;
    use radiant_core::Sampler;

    fn ids(pixel: u32, n: u32) -> Vec<SampleId> {
        (0..n).map(|index| SampleId { pixel, index }).collect()
    }

    #[test]
    fn one_sample_per_stratum_in_1d_and_per_cell_and_fine_stratum_in_2d() {
        for spp in [1u32, 7, 16, 30] {
            let s = Stratified::new(5, spp);
            let ids = ids(11, spp);
            let mut v = vec![0.0; spp as usize];
            s.fill_1d(&ids, 3, &mut v);
            let mut strata: Vec<u32> = v.iter().map(|x| (x * spp as f32) as u32).collect();
            strata.sort_unstable();
            assert_eq!(strata, (0..spp).collect::<Vec<_>>(), "spp {spp}");

            let mut p = vec![Vec2::ZERO; spp as usize];
            s.fill_2d(&ids, 5, &mut p);
            let (m, n) = (s.cols, s.rows);
            let mut cells: Vec<u32> = p
                .iter()
                .map(|q| (q.y * n as f32) as u32 * m + (q.x * m as f32) as u32)
                .collect();
            cells.sort_unstable();
            cells.dedup();
            assert_eq!(cells.len(), spp as usize, "one per cell, spp {spp}");
            for axis in 0..2 {
                let mut fine: Vec<u32> = p
                    .iter()
                    .map(|q| (q[axis] * (m * n) as f32) as u32)
                    .collect();
                fine.sort_unstable();
                fine.dedup();
                assert_eq!(
                    fine.len(),
                    spp as usize,
                    "fine strata on axis {axis}, spp {spp}"
                );
            }
        }
    }
}
