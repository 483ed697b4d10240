//! Chi-square goodness-of-fit tests of sampling routines against their own
//! densities, over a grid of directions (the method of Mitsuba 3's test
//! suite).
//!
//! The sphere of directions is cut into cells of equal solid angle
//! (uniform in cos θ and φ). The expected count of a cell is N × the
//! integral of the density over it (midpoint rule on a finer grid); cells
//! with an expected count below 5 are pooled. The test fails if the
//! p-value is below `significance`, if a sample lands where the density is
//! zero, or if the density does not integrate to the fraction of samples
//! that succeeded.

use glam::{Vec2, Vec3};
use statrs::distribution::{ChiSquared, ContinuousCDF};

/// The rejection threshold of every chi-square test in the suite: 1 %
/// shared over the ≈180 tests it runs (Bonferroni, as Mitsuba 3's suite
/// divides its significance by the number of tests). At 1e-3 each, a change
/// in how any sampler uses its random numbers had a ~16 % chance of failing
/// some correct routine by luck; the smallest p-value of a correct routine
/// in the suite was 1.1e-3. Wrong densities give p far below this (the
/// power tests see p = 0).
pub const SIGNIFICANCE: f64 = 0.01 / 200.0;

/// Grid and sample-count settings.
#[derive(Debug, Clone, Copy)]
pub struct Chi2 {
    /// Cells along cos θ.
    pub theta_cells: usize,
    /// Cells along φ.
    pub phi_cells: usize,
    /// Sub-cells per cell edge for integrating the density.
    pub refine: usize,
    /// Number of samples drawn.
    pub samples: usize,
    /// Rejection threshold of the p-value.
    pub significance: f64,
}

impl Default for Chi2 {
    fn default() -> Self {
        Self {
            theta_cells: 20,
            phi_cells: 40,
            refine: 8,
            samples: 200_000,
            significance: SIGNIFICANCE,
        }
    }
}

/// A small deterministic generator of uniform numbers for the tests.
pub struct Rng(u64);

impl Rng {
    /// A generator from a seed.
    pub fn new(seed: u64) -> Self {
        Self(seed.wrapping_mul(0x9e37_79b9_7f4a_7c15) | 1)
    }

    /// A uniform number in [0, 1).
    pub fn uniform(&mut self) -> f32 {
        self.0 ^= self.0 << 13;
        self.0 ^= self.0 >> 7;
        self.0 ^= self.0 << 17;
        (self.0 >> 40) as f32 / (1u64 << 24) as f32
    }

    /// A uniform point in [0, 1)².
    pub fn next_2d(&mut self) -> Vec2 {
        Vec2::new(self.uniform(), self.uniform())
    }
}

fn cell_of(cfg: &Chi2, d: Vec3) -> usize {
    let z = d.z.clamp(-1.0, 1.0);
    let t = (((z + 1.0) * 0.5 * cfg.theta_cells as f32) as usize).min(cfg.theta_cells - 1);
    let phi = d.y.atan2(d.x) + std::f32::consts::PI;
    let p = ((phi / std::f32::consts::TAU * cfg.phi_cells as f32) as usize).min(cfg.phi_cells - 1);
    t * cfg.phi_cells + p
}

impl Chi2 {
    /// Runs the test on `samples` (unit directions, or `None` for a failed
    /// sample) drawn by the routine whose solid-angle density is `pdf`.
    pub fn run(
        &self,
        samples: impl IntoIterator<Item = Option<Vec3>>,
        pdf: impl Fn(Vec3) -> f64,
    ) -> Result<f64, String> {
        let cells = self.theta_cells * self.phi_cells;
        let mut observed = vec![0.0f64; cells];
        let mut succeeded = 0usize;
        let mut drawn = 0usize;
        for s in samples {
            drawn += 1;
            let Some(d) = s else { continue };
            if !d.is_finite() || (d.length() - 1.0).abs() > 1e-3 {
                return Err(format!("sample {d} is not a unit direction"));
            }
            if pdf(d) <= 0.0 {
                return Err(format!("sample {d} has zero density"));
            }
            observed[cell_of(self, d)] += 1.0;
            succeeded += 1;
        }
        let n = drawn as f64;
        let dz = 2.0 / (self.theta_cells * self.refine) as f64;
        let dphi = std::f64::consts::TAU / (self.phi_cells * self.refine) as f64;
        let mut expected = vec![0.0f64; cells];
        for i in 0..self.theta_cells * self.refine {
            let z = -1.0 + (i as f64 + 0.5) * dz;
            let r = (1.0 - z * z).max(0.0).sqrt();
            for j in 0..self.phi_cells * self.refine {
                let phi = -std::f64::consts::PI + (j as f64 + 0.5) * dphi;
                let d = Vec3::new((r * phi.cos()) as f32, (r * phi.sin()) as f32, z as f32);
                let c = (i / self.refine) * self.phi_cells + j / self.refine;
                expected[c] += pdf(d) * dz * dphi * n;
            }
        }
        self.test(&observed, &expected, succeeded, drawn)
    }

    /// Runs the test on points of the rectangle [`lo`, `hi`] (or `None` for
    /// a failed sample) drawn by a routine whose density per unit area is
    /// `pdf`, over `phi_cells` × `theta_cells` cells along x × y.
    pub fn run_planar(
        &self,
        lo: Vec2,
        hi: Vec2,
        samples: impl IntoIterator<Item = Option<Vec2>>,
        pdf: impl Fn(Vec2) -> f64,
    ) -> Result<f64, String> {
        let (nx, ny) = (self.phi_cells, self.theta_cells);
        let size = hi - lo;
        let mut observed = vec![0.0f64; nx * ny];
        let (mut succeeded, mut drawn) = (0usize, 0usize);
        for s in samples {
            drawn += 1;
            let Some(p) = s else { continue };
            let q = (p - lo) / size;
            if !(q.x >= 0.0 && q.y >= 0.0 && q.x < 1.0 && q.y < 1.0) {
                return Err(format!("sample {p} lies outside [{lo}, {hi}]"));
            }
            if pdf(p) <= 0.0 {
                return Err(format!("sample {p} has zero density"));
            }
            let (i, j) = ((q.x * nx as f32) as usize, (q.y * ny as f32) as usize);
            observed[j.min(ny - 1) * nx + i.min(nx - 1)] += 1.0;
            succeeded += 1;
        }
        let n = drawn as f64;
        let (fx, fy) = (nx * self.refine, ny * self.refine);
        let (dx, dy) = (size.x as f64 / fx as f64, size.y as f64 / fy as f64);
        let mut expected = vec![0.0f64; nx * ny];
        for j in 0..fy {
            for i in 0..fx {
                let p = Vec2::new(
                    (lo.x as f64 + (i as f64 + 0.5) * dx) as f32,
                    (lo.y as f64 + (j as f64 + 0.5) * dy) as f32,
                );
                expected[(j / self.refine) * nx + i / self.refine] += pdf(p) * dx * dy * n;
            }
        }
        self.test(&observed, &expected, succeeded, drawn)
    }

    /// Runs the test on the counts `observed` of a discrete choice among
    /// `observed.len()` outcomes against their expected counts out of
    /// `drawn` draws (a draw counted in no outcome failed).
    pub fn run_discrete(
        &self,
        observed: &[f64],
        expected: &[f64],
        drawn: usize,
    ) -> Result<f64, String> {
        let succeeded = observed.iter().sum::<f64>() as usize;
        self.test(observed, expected, succeeded, drawn)
    }

    /// The normalisation check and the pooled chi-square test shared by
    /// [`run`](Self::run) and [`run_planar`](Self::run_planar).
    fn test(
        &self,
        observed: &[f64],
        expected: &[f64],
        succeeded: usize,
        drawn: usize,
    ) -> Result<f64, String> {
        let n = drawn as f64;
        let cells = observed.len();
        let integral: f64 = expected.iter().sum::<f64>() / n;
        let success = succeeded as f64 / n;
        if (integral - success).abs() > 0.01 + 3.0 / n.sqrt() {
            return Err(format!(
                "the density integrates to {integral:.4} but {success:.4} of the samples succeeded"
            ));
        }
        // Pool cells with small expected counts (in increasing order).
        let mut order: Vec<usize> = (0..cells).collect();
        order.sort_by(|&a, &b| expected[a].total_cmp(&expected[b]));
        let (mut chi2, mut dof) = (0.0f64, 0usize);
        let (mut pool_e, mut pool_o) = (0.0f64, 0.0f64);
        for &c in &order {
            if expected[c] == 0.0 {
                if observed[c] > 0.0 {
                    return Err(format!("{} samples in a cell of zero density", observed[c]));
                }
                continue;
            }
            if expected[c] < 5.0 || pool_e > 0.0 && pool_e < 5.0 {
                pool_e += expected[c];
                pool_o += observed[c];
                continue;
            }
            chi2 += (observed[c] - expected[c]).powi(2) / expected[c];
            dof += 1;
        }
        if pool_e > 0.0 {
            chi2 += (pool_o - pool_e).powi(2) / pool_e;
            dof += 1;
        }
        if dof < 2 {
            return Err(format!(
                "only {dof} cell(s) with enough expected samples: the test cannot judge \
                 the distribution (use more samples or fewer cells)"
            ));
        }
        let p = 1.0
            - ChiSquared::new((dof - 1) as f64)
                .map_err(|e| e.to_string())?
                .cdf(chi2);
        if p < self.significance {
            Err(format!(
                "chi² = {chi2:.1} with {} degrees of freedom: p = {p:.2e}",
                dof - 1
            ))
        } else {
            Ok(p)
        }
    }
}

/// Pearson's chi-square p-value of `observed` counts against equal
/// expected counts (for cells made equiprobable by construction, e.g. by
/// [`invert_cdf`]).
pub fn uniform_p_value(observed: &[f64]) -> f64 {
    let n: f64 = observed.iter().sum();
    let e = n / observed.len() as f64;
    let chi2: f64 = observed.iter().map(|o| (o - e) * (o - e) / e).sum();
    let dist = statrs::distribution::ChiSquared::new((observed.len() - 1) as f64).expect("dof > 0");
    1.0 - statrs::distribution::ContinuousCDF::cdf(&dist, chi2)
}

/// The inverse of an increasing CDF on [lo, hi] at `p`, by bisection (f64).
pub fn invert_cdf(cdf: impl Fn(f64) -> f64, p: f64, lo: f64, hi: f64) -> f64 {
    let (mut a, mut b) = (lo, hi);
    for _ in 0..200 {
        let m = 0.5 * (a + b);
        if cdf(m) < p { a = m } else { b = m }
    }
    0.5 * (a + b)
}
