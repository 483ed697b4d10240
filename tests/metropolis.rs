//! Metropolis chains in primary sample space (`integrators::mlt::pss`) on
//! toy integrands whose integrals are known.
//!
//! Stationarity is tested the way that keeps the chi-square test sound:
//! many independent chains start exactly in the target distribution (by
//! rejection sampling through the chains' own fresh proposals), run their
//! mutations, and only each chain's final state is counted. Successive
//! states of one chain are correlated, so counting them would shrink the
//! apparent variance; final states of independent chains are independent
//! draws, and an invariant kernel leaves them distributed as the target
//! whatever the number of steps. The targets read their coordinates
//! through the chains' `Sampler` interface at scattered dimensions and a
//! variable number of them, as a path does, so the lazy extension of the
//! vectors is under test too.

use radiant::integrators::mlt::pss::{Chains, Mutation, acceptance};
use radiant_core::{SampleId, Sampler};
use radiant_tests::SplitMix;
use radiant_tests::chi2::SIGNIFICANCE;
use statrs::distribution::{ChiSquared, ContinuousCDF};

/// A toy target: its value on a proposal (read through the sampler) and
/// the cell of a state (read from the stored coordinates).
trait Target {
    /// Evaluates every slot's proposal into `out`.
    fn eval(&self, chains: &Chains, out: &mut [f32]);
    /// Number of cells of the chi-square grid.
    fn cells(&self) -> usize;
    /// The cell of a stored state.
    fn cell(&self, state: &[f32]) -> usize;
    /// Each cell's share of the target's integral (quadrature).
    fn masses(&self) -> Vec<f64>;
    /// The target's integral.
    fn integral(&self) -> f64;
    /// An upper bound of the target (for the rejection sampling of starts).
    fn bound(&self) -> f32;
}

fn ids(n: usize) -> Vec<SampleId> {
    (0..n as u32)
        .map(|pixel| SampleId { pixel, index: 0 })
        .collect()
}

fn read_1d(chains: &Chains, dim: u32) -> Vec<f32> {
    let mut v = vec![0.0; chains.len()];
    chains.fill_1d(&ids(chains.len()), dim, &mut v);
    v
}

/// 1D: a step, a zero gap and a narrow peak, g(u) on dimension 0.
fn g1(u: f32) -> f32 {
    let step = if u < 0.3 { 2.0 } else { 0.25 };
    let gap = if (0.4..0.45).contains(&u) { 0.0 } else { 1.0 };
    let peak = 6.0 * (-((u - 0.7) / 0.03).powi(2)).exp();
    gap * (step + peak)
}

struct OneD;

impl Target for OneD {
    fn eval(&self, chains: &Chains, out: &mut [f32]) {
        for (o, u) in out.iter_mut().zip(read_1d(chains, 0)) {
            *o = g1(u);
        }
    }
    fn cells(&self) -> usize {
        64
    }
    fn cell(&self, s: &[f32]) -> usize {
        (s[0] * 64.0) as usize
    }
    fn masses(&self) -> Vec<f64> {
        quadrature_1d(64, |u| f64::from(g1(u as f32)))
    }
    fn integral(&self) -> f64 {
        self.masses().iter().sum()
    }
    fn bound(&self) -> f32 {
        8.5
    }
}

/// 2D: two bumps on a dim floor, x on dimension 0 and y on dimension 5
/// (dimensions 1–4 are never read, as a path skips the dimensions of
/// decisions it does not take).
fn g2(x: f32, y: f32) -> f32 {
    let bump = |cx: f32, cy: f32, r: f32| (-((x - cx).powi(2) + (y - cy).powi(2)) / (r * r)).exp();
    0.05 + 4.0 * bump(0.25, 0.3, 0.06) + 2.0 * bump(0.7, 0.75, 0.1)
}

struct TwoD;

impl Target for TwoD {
    fn eval(&self, chains: &Chains, out: &mut [f32]) {
        let (x, y) = (read_1d(chains, 0), read_1d(chains, 5));
        for ((o, x), y) in out.iter_mut().zip(x).zip(y) {
            *o = g2(x, y);
        }
    }
    fn cells(&self) -> usize {
        16 * 16
    }
    fn cell(&self, s: &[f32]) -> usize {
        (s[5] * 16.0) as usize * 16 + (s[0] * 16.0) as usize
    }
    fn masses(&self) -> Vec<f64> {
        let (cells, refine) = (16, 16);
        let h = 1.0 / (cells * refine) as f64;
        let mut m = vec![0.0; cells * cells];
        for j in 0..cells * refine {
            for i in 0..cells * refine {
                let (x, y) = ((i as f64 + 0.5) * h, (j as f64 + 0.5) * h);
                m[(j / refine) * cells + i / refine] += f64::from(g2(x as f32, y as f32)) * h * h;
            }
        }
        m
    }
    fn integral(&self) -> f64 {
        self.masses().iter().sum()
    }
    fn bound(&self) -> f32 {
        4.2
    }
}

/// A variable number of dimensions: dimension 0 decides whether dimension
/// 3 is read at all (a path that ends or goes on), f = g1(u0) where u0 <
/// 0.5, else g1(u0)·2·u3. The marginal of u0 is g1; u3 is uniform where it
/// is not read and has density 2·u3 where it is.
struct Variable;

impl Target for Variable {
    fn eval(&self, chains: &Chains, out: &mut [f32]) {
        let u0 = read_1d(chains, 0);
        let longer: Vec<SampleId> = ids(chains.len())
            .into_iter()
            .filter(|id| u0[id.pixel as usize] >= 0.5)
            .collect();
        let mut u3 = vec![0.0; longer.len()];
        chains.fill_1d(&longer, 3, &mut u3);
        for (o, u) in out.iter_mut().zip(&u0) {
            *o = g1(*u);
        }
        for (id, u) in longer.iter().zip(u3) {
            out[id.pixel as usize] *= 2.0 * u;
        }
    }
    fn cells(&self) -> usize {
        32 + 32 * 4
    }
    fn cell(&self, s: &[f32]) -> usize {
        let i = (s[0] * 64.0) as usize;
        if i < 32 {
            i
        } else {
            // Accepted long states stored dimension 3.
            32 + (i - 32) * 4 + (s[3] * 4.0) as usize
        }
    }
    fn masses(&self) -> Vec<f64> {
        let g = quadrature_1d(64, |u| f64::from(g1(u as f32)));
        let mut m = g[..32].to_vec();
        for gi in &g[32..] {
            // ∫ 2y dy over the quarters of [0, 1): (2k + 1)/16.
            m.extend((0..4).map(|k| gi * f64::from(2 * k + 1) / 16.0));
        }
        m
    }
    fn integral(&self) -> f64 {
        self.masses().iter().sum()
    }
    fn bound(&self) -> f32 {
        17.0
    }
}

/// ∫ of `f` over each of `cells` equal cells of [0, 1) (midpoint rule, 256
/// points per cell).
fn quadrature_1d(cells: usize, f: impl Fn(f64) -> f64) -> Vec<f64> {
    let refine = 256;
    let h = 1.0 / (cells * refine) as f64;
    (0..cells)
        .map(|c| {
            (0..refine)
                .map(|k| f(((c * refine + k) as f64 + 0.5) * h) * h)
                .sum()
        })
        .collect()
}

/// `n` chains started exactly in the target (rejection sampling of fresh
/// proposals), run for `steps` mutations; returns the chains and each
/// chain's current target value.
fn run(target: &dyn Target, n: usize, steps: u32, mutation: Mutation, seed: u32) -> Chains {
    let mut chains = Chains::new(seed);
    chains.resize(n);
    for slot in 0..n {
        chains.start(slot, slot as u32);
    }
    let mut rng = SplitMix(u64::from(seed));
    let mut value = vec![0.0f32; n];
    let mut pending: Vec<usize> = (0..n).collect();
    let mut out = vec![0.0f32; n];
    while !pending.is_empty() {
        for &slot in &pending {
            chains.propose_fresh(slot);
        }
        target.eval(&chains, &mut out);
        pending.retain(|&slot| {
            let keep = rng.unit() * target.bound() < out[slot];
            if keep {
                chains.accept(slot);
                value[slot] = out[slot];
            }
            !keep
        });
    }
    for _ in 0..steps {
        step(target, &mut chains, &mut value, &mutation);
    }
    chains
}

/// One Metropolis step of every chain; `value` holds the current states'
/// target values.
fn step(target: &dyn Target, chains: &mut Chains, value: &mut [f32], mutation: &Mutation) {
    let mut out = vec![0.0f32; chains.len()];
    chains.propose(mutation);
    target.eval(chains, &mut out);
    for (slot, (v, o)) in value.iter_mut().zip(out).enumerate() {
        if chains.acceptance_draw(slot) < acceptance(*v, o) {
            chains.accept(slot);
            *v = o;
        }
    }
}

/// Pearson's chi-square p-value of the chains' final states against the
/// target's cell masses scaled by `distort` (cells with an expected count
/// below 5 pooled).
fn p_value(target: &dyn Target, chains: &Chains, distort: impl Fn(usize) -> f64) -> f64 {
    let mut observed = vec![0.0f64; target.cells()];
    for slot in 0..chains.len() {
        observed[target.cell(chains.current(slot))] += 1.0;
    }
    let masses: Vec<f64> = target
        .masses()
        .iter()
        .enumerate()
        .map(|(c, m)| m * distort(c))
        .collect();
    let total: f64 = masses.iter().sum();
    let n = chains.len() as f64;
    let (mut chi2, mut dof) = (0.0, 0usize);
    let (mut pool_o, mut pool_e) = (0.0, 0.0);
    for (o, m) in observed.iter().zip(&masses) {
        let e = n * m / total;
        if e < 5.0 {
            assert!(e > 0.0 || *o == 0.0, "a state where the target is zero");
            pool_o += o;
            pool_e += e;
        } else {
            chi2 += (o - e) * (o - e) / e;
            dof += 1;
        }
    }
    if pool_e > 0.0 {
        chi2 += (pool_o - pool_e) * (pool_o - pool_e) / pool_e;
        dof += 1;
    }
    let dist = ChiSquared::new((dof - 1) as f64).expect("dof > 0");
    1.0 - dist.cdf(chi2)
}

fn check_stationary(target: &dyn Target, large_step: f32, seed: u32) {
    let mutation = Mutation {
        large_step,
        ..Mutation::default()
    };
    let chains = run(target, 60_000, 24, mutation, seed);
    let p = p_value(target, &chains, |_| 1.0);
    eprintln!("large_step {large_step}: p = {p:.4}");
    assert!(
        p > SIGNIFICANCE,
        "chain states do not follow the target (p = {p})"
    );
    // Power: the same states against a target with 10 % more mass in the
    // first half of the cells are rejected.
    let half = target.cells() / 2;
    let wrong = p_value(target, &chains, |c| if c < half { 1.1 } else { 1.0 });
    assert!(
        wrong < SIGNIFICANCE,
        "a 10 % distortion passed (p = {wrong})"
    );
}

#[test]
fn one_dimensional_chain_keeps_its_target() {
    check_stationary(&OneD, 0.3, 1);
    check_stationary(&OneD, 0.0, 2);
}

#[test]
fn two_dimensional_chain_keeps_its_target() {
    check_stationary(&TwoD, 0.3, 3);
    check_stationary(&TwoD, 0.0, 4);
}

#[test]
fn variable_dimension_chain_keeps_its_target() {
    check_stationary(&Variable, 0.3, 5);
    check_stationary(&Variable, 0.0, 6);
}

/// Chains that start uniformly distributed rather than in the target
/// reach it (large steps forget the start): after 200 steps their final
/// states pass the same test.
#[test]
fn chains_started_uniformly_converge() {
    let target = TwoD;
    let n = 40_000;
    let mut chains = Chains::new(9);
    chains.resize(n);
    let mut value = vec![0.0f32; n];
    let mut out = vec![0.0f32; n];
    for slot in 0..n {
        chains.start(slot, slot as u32);
        chains.propose_fresh(slot);
    }
    target.eval(&chains, &mut out);
    for slot in 0..n {
        chains.accept(slot);
        value[slot] = out[slot];
    }
    for _ in 0..200 {
        step(&target, &mut chains, &mut value, &Mutation::default());
    }
    let p = p_value(&target, &chains, |_| 1.0);
    assert!(p > SIGNIFICANCE, "p = {p}");
}

/// The bootstrap estimate of the normalisation b = ∫f (the mean of f over
/// fresh proposals) and the Metropolis estimate of another integral,
/// ∫ h with h = f·x (expected values of both proposal and current state,
/// b·E[h/f]), each lie within 4 standard errors of the truth. The
/// Metropolis standard error comes from independent chains (each chain's
/// own estimate is one draw), so correlation within a chain cannot shrink
/// it.
#[test]
fn normalisation_and_estimates_lie_within_their_confidence_intervals() {
    let target = TwoD;
    let truth_b = target.integral();
    // Bootstrap: fresh proposals only.
    let n = 200_000;
    let mut boot = Chains::new(11);
    boot.resize(n);
    for slot in 0..n {
        boot.start(slot, slot as u32);
        boot.propose_fresh(slot);
    }
    let mut f = vec![0.0f32; n];
    target.eval(&boot, &mut f);
    let mean = f.iter().map(|&v| f64::from(v)).sum::<f64>() / n as f64;
    let var = f
        .iter()
        .map(|&v| (f64::from(v) - mean).powi(2))
        .sum::<f64>()
        / (n - 1) as f64;
    let se = (var / n as f64).sqrt();
    eprintln!("b = {mean} ± {se}, truth {truth_b}");
    assert!(
        (mean - truth_b).abs() < 4.0 * se,
        "b = {mean} ± {se}, truth {truth_b}"
    );
    assert!(se < 0.01 * truth_b, "the bootstrap is too small to test");

    // ∫ f·x: expected-value splatting over independent chains.
    let truth_h: f64 = {
        let refine = 512;
        let h = 1.0 / refine as f64;
        (0..refine * refine)
            .map(|k| {
                let (x, y) = (
                    ((k % refine) as f64 + 0.5) * h,
                    ((k / refine) as f64 + 0.5) * h,
                );
                f64::from(g2(x as f32, y as f32)) * x * h * h
            })
            .sum()
    };
    let (chains_n, steps) = (4000, 64u32);
    let mut chains = run(&target, chains_n, 0, Mutation::default(), 12);
    let mut value: Vec<f32> = Vec::with_capacity(chains_n);
    let mut x: Vec<f32> = Vec::with_capacity(chains_n);
    for slot in 0..chains_n {
        let s = chains.current(slot);
        value.push(g2(s[0], s[5]));
        x.push(s[0]);
    }
    let mut sums = vec![0.0f64; chains_n];
    let mut out = vec![0.0f32; chains_n];
    for _ in 0..steps {
        chains.propose(&Mutation::default());
        target.eval(&chains, &mut out);
        let px = read_1d(&chains, 0);
        for slot in 0..chains_n {
            let a = acceptance(value[slot], out[slot]);
            // h/f = x at both states.
            sums[slot] += f64::from(a * px[slot] + (1.0 - a) * x[slot]);
            if chains.acceptance_draw(slot) < a {
                chains.accept(slot);
                value[slot] = out[slot];
                x[slot] = px[slot];
            }
        }
    }
    let per_chain: Vec<f64> = sums
        .iter()
        .map(|s| truth_b * s / f64::from(steps))
        .collect();
    let m = per_chain.iter().sum::<f64>() / chains_n as f64;
    let v = per_chain.iter().map(|e| (e - m).powi(2)).sum::<f64>() / (chains_n - 1) as f64;
    let se = (v / chains_n as f64).sqrt();
    eprintln!("∫h = {m} ± {se}, truth {truth_h}");
    assert!(
        (m - truth_h).abs() < 4.0 * se,
        "∫h = {m} ± {se}, truth {truth_h}"
    );
    assert!(se < 0.01 * truth_h, "too few chains to test");
}
