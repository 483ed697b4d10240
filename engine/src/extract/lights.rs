//! The light table: every light of the frame and the distribution that
//! chooses one per next-event estimate, proportional to power, uniform, or
//! by each light's importance at the shading point ([`LightSelection`]).
//!
//! Spatial selection weighs the lights that report [`LightBounds`] by
//! [`LightBounds::importance`] at the shading point and gives lights
//! without bounds (environments, directional lights) together the fixed
//! share n∞ / (n∞ + 1), as pbrt-v4's light sampler does. Up to
//! [`FLAT_LIMIT`] bounded lights, every light's importance is evaluated
//! (two passes: the total, then the walk to the chosen light), so the
//! choice is exactly in proportion to it; beyond, the lights are chosen
//! through a [`LightTree`] in O(log n). [`LightTable::select_at`] and
//! [`LightTable::pmf_at`] compute the same sums in the same order, so the
//! probability an emitter hit is weighted with is bit for bit the one its
//! sample was drawn with. The wavefront asks for a batch of points at once
//! ([`LightTable::select_many`], [`LightTable::pmf_many`]): the same
//! values, with each light's importance evaluated at four points per
//! instruction, so that the points' long chains of square roots and
//! divisions overlap, and the choice among the lights made for four
//! points at a time too.

use super::light_tree::LightTree;
use crate::settings::LightSelection;
use radiant_core::glam::{Vec3, Vec4};
use radiant_core::{BoundsLanes, Effects, Light, LightBounds, PreparedBounds};

/// Most bounded lights whose importance spatial selection evaluates one by
/// one; more are chosen through a [`LightTree`].
pub const FLAT_LIMIT: usize = 16;

/// The scene's lights with their selection probabilities.
#[derive(Default)]
pub struct LightTable {
    lights: Vec<Box<dyn Light>>,
    cdf: Vec<f32>,
    pmf: Vec<f32>,
    delta: Vec<bool>,
    /// Whether any light reads the 2D samples of its `sample`.
    point_samples: bool,
    environment: Vec<usize>,
    selection: LightSelection,
    /// Spatial selection: the lights with bounds, and theirs.
    bounded: Vec<(u32, LightBounds)>,
    /// Spatial selection among at most [`FLAT_LIMIT`] bounded lights:
    /// their bounds, four lights a lane group, in `bounded`'s order.
    lanes: Vec<BoundsLanes>,
    /// The same lights one per lane group (each in all four lanes), to
    /// weigh four shading points at once ([`LightTable::select_many`]).
    each: Vec<BoundsLanes>,
    /// Spatial selection: the lights without bounds.
    unbounded: Vec<u32>,
    /// Spatial selection: the share of the unbounded lights.
    p_unbounded: f32,
    /// Spatial selection: each light's place in `bounded` (`u32::MAX` if
    /// it has no bounds).
    slot_of: Vec<u32>,
    /// Spatial selection among more than [`FLAT_LIMIT`] bounded lights.
    tree: Option<LightTree>,
}

/// What spatial selection chooses with ([`LightTable::spatial`]): the
/// bounded lights in their order (light index and bounds), the unbounded
/// lights, their share, and the tree over the bounded lights' slots where
/// there are more than [`FLAT_LIMIT`].
#[derive(Debug, Clone, Copy)]
pub struct SpatialTables<'a> {
    /// (light index, bounds) per slot.
    pub bounded: &'a [(u32, LightBounds)],
    /// Indices of the lights without bounds.
    pub unbounded: &'a [u32],
    /// The probability of choosing one of `unbounded`.
    pub p_unbounded: f32,
    /// The hierarchy over the slots of `bounded`.
    pub tree: Option<&'a LightTree>,
}

impl LightTable {
    /// Builds the table; with [`LightSelection::Power`] lights are chosen in
    /// proportion to [`Light::power`] (uniformly if no light reports a
    /// positive power), with [`LightSelection::Uniform`] uniformly.
    pub fn new(lights: Vec<Box<dyn Light>>, selection: LightSelection) -> Self {
        let powers: Vec<f64> = lights
            .iter()
            .map(|l| {
                let p = match selection {
                    // Spatial selection keeps power as its table for
                    // `select` (bdpt's choice of a light subpath's light).
                    LightSelection::Power | LightSelection::Spatial => l.power() as f64,
                    LightSelection::Uniform => 1.0,
                };
                if p.is_finite() && p > 0.0 { p } else { 0.0 }
            })
            .collect();
        let total: f64 = powers.iter().sum();
        let pmf: Vec<f32> = if total > 0.0 {
            powers.iter().map(|p| (p / total) as f32).collect()
        } else {
            vec![1.0 / lights.len().max(1) as f32; lights.len()]
        };
        let mut acc = 0.0f64;
        let mut cdf: Vec<f32> = pmf
            .iter()
            .map(|&p| {
                acc += p as f64;
                acc as f32
            })
            .collect();
        if let Some(last) = cdf.last_mut() {
            *last = 1.0;
        }
        let delta = lights.iter().map(|l| l.is_delta()).collect();
        let point_samples = lights.iter().any(|l| l.uses_point_samples());
        let environment = (0..lights.len())
            .filter(|&i| lights[i].effects().contains(Effects::ENVIRONMENT))
            .collect();
        let (mut bounded, mut unbounded) = (Vec::new(), Vec::new());
        for (i, light) in lights.iter().enumerate() {
            match light.bounds() {
                Some(b) if b.phi > 0.0 && b.phi.is_finite() => bounded.push((i as u32, b)),
                // A light with bounds but no power never gets a sample.
                Some(_) => {}
                None => unbounded.push(i as u32),
            }
        }
        let prepared: Vec<PreparedBounds> = bounded.iter().map(|(_, b)| b.prepare()).collect();
        let (lanes, each) = if bounded.len() <= FLAT_LIMIT {
            (
                prepared.chunks(4).map(BoundsLanes::new).collect(),
                prepared.chunks(1).map(BoundsLanes::new).collect(),
            )
        } else {
            (Vec::new(), Vec::new())
        };
        let mut slot_of = vec![u32::MAX; lights.len()];
        for (slot, (i, _)) in bounded.iter().enumerate() {
            slot_of[*i as usize] = slot as u32;
        }
        let tree = (bounded.len() > FLAT_LIMIT).then(|| {
            let b: Vec<LightBounds> = bounded.iter().map(|(_, b)| *b).collect();
            LightTree::new(&b)
        });
        let p_unbounded = match (unbounded.len(), bounded.is_empty()) {
            (0, _) => 0.0,
            (_, true) => 1.0,
            (n, false) => n as f32 / (n + 1) as f32,
        };
        Self {
            lights,
            cdf,
            pmf,
            delta,
            point_samples,
            environment,
            selection,
            bounded,
            lanes,
            each,
            unbounded,
            p_unbounded,
            slot_of,
            tree,
        }
    }

    /// Whether the choice depends on the shading point
    /// ([`LightSelection::Spatial`] with more than one light).
    #[inline]
    pub fn is_spatial(&self) -> bool {
        self.selection == LightSelection::Spatial && self.lights.len() > 1
    }

    /// Spatial selection's tables, for backends that choose lights
    /// themselves (the GPU's); `None` where the choice does not depend on
    /// the shading point ([`is_spatial`](Self::is_spatial) is false).
    pub fn spatial(&self) -> Option<SpatialTables<'_>> {
        self.is_spatial().then(|| SpatialTables {
            bounded: &self.bounded,
            unbounded: &self.unbounded,
            p_unbounded: self.p_unbounded,
            tree: self.tree.as_ref(),
        })
    }

    /// Chooses a light for the shading point `p` with the uniform sample
    /// `u`; returns its index and probability (0 where no light can reach
    /// `p`: the sample then carries nothing). Without spatial selection,
    /// [`select`](Self::select).
    #[inline]
    pub fn select_at(&self, p: Vec3, u: f32) -> (usize, f32) {
        if !self.is_spatial() {
            let (i, pmf, _) = self.select(u);
            return (i, pmf);
        }
        if u < self.p_unbounded {
            let n = self.unbounded.len();
            let k = ((u / self.p_unbounded * n as f32) as usize).min(n - 1);
            return (self.unbounded[k] as usize, self.p_unbounded / n as f32);
        }
        let Some(&(first, _)) = self.bounded.first() else {
            return (0, 0.0);
        };
        let share = 1.0 - self.p_unbounded;
        if let Some(tree) = &self.tree {
            let v = ((u - self.p_unbounded) / share).clamp(0.0, radiant_core::ONE_MINUS_EPSILON);
            return match tree.select(p, v) {
                Some((slot, pmf)) => (self.bounded[slot].0 as usize, share * pmf),
                None => (first as usize, 0.0),
            };
        }
        let (weights, total) = self.importances(p);
        self.pick_bounded(&weights, total, u)
    }

    /// [`select_at`](Self::select_at) for each of `points` with its
    /// sample of `u`: the chosen light into `light` and its probability
    /// into `prob`, bit for bit as one call per point.
    pub fn select_many(&self, points: &[Vec3], u: &[f32], light: &mut [u32], prob: &mut [f32]) {
        let n = points.len().min(u.len()).min(light.len()).min(prob.len());
        let visit = |k: usize| {
            let (l, p) = self.select_at(points[k], u[k]);
            (l as u32, p)
        };
        if !self.is_flat_spatial() {
            for k in 0..n {
                (light[k], prob[k]) = visit(k);
            }
            return;
        }
        self.per_quad(&points[..n], |k, weights| {
            let m = (n - k).min(4);
            let uq = Vec4::from_array(std::array::from_fn(|j| u[k + j.min(m - 1)]));
            let (l, p) = self.pick_bounded_lanes(weights, uq);
            let p = p.to_array();
            for j in 0..m {
                (light[k + j], prob[k + j]) = if u[k + j] >= self.p_unbounded {
                    (self.bounded[l[j] as usize].0, p[j])
                } else {
                    visit(k + j)
                };
            }
        });
    }

    /// [`pmf_at`](Self::pmf_at) for each of `points` and its light of
    /// `light`, into `pmf`, bit for bit as one call per point.
    pub fn pmf_many(&self, points: &[Vec3], light: &[u32], pmf: &mut [f32]) {
        let n = points.len().min(light.len()).min(pmf.len());
        if !self.is_flat_spatial() {
            for k in 0..n {
                pmf[k] = self.pmf_at(points[k], light[k] as usize);
            }
            return;
        }
        let nb = self.bounded.len();
        self.per_quad(&points[..n], |k, weights| {
            let total = positive_sum_lanes(&weights[..nb]).to_array();
            for j in 0..(n - k).min(4) {
                let i = light[k + j] as usize;
                let slot = self.slot_of[i] as usize;
                pmf[k + j] = if slot < nb {
                    self.pmf_bounded(weights[slot][j], total[j])
                } else {
                    self.pmf_at(points[k + j], i)
                };
            }
        });
    }

    /// The probability that [`pick_bounded`](Self::pick_bounded) picks
    /// a bounded light of importance `weight` where the positive
    /// importances sum to `total`.
    #[inline]
    fn pmf_bounded(&self, weight: f32, total: f32) -> f32 {
        if total > 0.0 {
            (1.0 - self.p_unbounded) * weight / total
        } else {
            0.0
        }
    }

    /// Whether spatial selection weighs each bounded light one by one
    /// (at most [`FLAT_LIMIT`] of them, and at least one).
    #[inline]
    fn is_flat_spatial(&self) -> bool {
        self.is_spatial() && !self.each.is_empty()
    }

    /// Calls `visit(k, weights)` for the points from `k` on, four at a
    /// time (fewer at the end: the last point fills the other lanes),
    /// with `weights[slot]` the bounded light `slot`'s importances at
    /// those points. The importances are evaluated one light at four
    /// points at a time, a block of points per pass, from the points'
    /// coordinates gathered into lanes once per block: four independent
    /// evaluations instead of one long chain of square roots and
    /// divisions per point. Only for flat spatial selection
    /// ([`Self::is_flat_spatial`]).
    #[inline]
    fn per_quad(&self, points: &[Vec3], mut visit: impl FnMut(usize, &[Vec4; FLAT_LIMIT])) {
        const QUADS: usize = 16;
        let mut coords = [[Vec4::ZERO; 3]; QUADS];
        let mut weights = [[Vec4::ZERO; FLAT_LIMIT]; QUADS];
        for (b, block) in points.chunks(4 * QUADS).enumerate() {
            for (quad, c) in block.chunks(4).zip(&mut coords) {
                *c = std::array::from_fn(|axis| {
                    Vec4::from_array(std::array::from_fn(|j| quad[j.min(quad.len() - 1)][axis]))
                });
            }
            let quads = block.len().div_ceil(4);
            for (slot, lanes) in self.each.iter().enumerate() {
                for (w, c) in weights[..quads].iter_mut().zip(&coords) {
                    w[slot] = lanes.importance_at(*c);
                }
            }
            for (q, w) in weights[..quads].iter().enumerate() {
                visit(b * 4 * QUADS + 4 * q, w);
            }
        }
    }

    /// [`pick_bounded`](Self::pick_bounded) in four lanes: the slots
    /// (in `bounded`) that the samples `u` (each at least the unbounded
    /// lights' share) pick in proportion to the bounded lights'
    /// importances `weights[slot]`, and their probabilities, bit for bit
    /// lane by lane. Slot numbers and counts are held as floats (exact
    /// below 2²⁴), so that every step is a vector operation.
    #[inline]
    fn pick_bounded_lanes(&self, weights: &[Vec4; FLAT_LIMIT], u: Vec4) -> ([u32; 4], Vec4) {
        let weights = &weights[..self.bounded.len()];
        let total = positive_sum_lanes(weights);
        let share = 1.0 - self.p_unbounded;
        let target = (u - Vec4::splat(self.p_unbounded)) / Vec4::splat(share) * total;
        // `pick_by_weight`: how many running sums are at most the target,
        // or where that is all of them, the last light with a weight.
        let (mut sum, mut below, mut last) = (Vec4::ZERO, Vec4::ZERO, Vec4::ZERO);
        for (slot, &w) in weights.iter().enumerate() {
            let positive = w.cmpgt(Vec4::ZERO);
            sum += Vec4::select(positive, w, Vec4::ZERO);
            below += Vec4::select(sum.cmple(target), Vec4::ONE, Vec4::ZERO);
            last = Vec4::select(positive, Vec4::splat(slot as f32), last);
        }
        let count = Vec4::splat(weights.len() as f32);
        let none = total.cmple(Vec4::ZERO);
        let slot = Vec4::select(
            none,
            Vec4::ZERO,
            Vec4::select(below.cmplt(count), below, last),
        );
        let mut chosen = Vec4::ZERO;
        for (l, &w) in weights.iter().enumerate() {
            chosen = Vec4::select(slot.cmpeq(Vec4::splat(l as f32)), w, chosen);
        }
        let p = Vec4::select(none, Vec4::ZERO, Vec4::splat(share) * chosen / total);
        (slot.to_array().map(|s| s as u32), p)
    }

    /// The bounded light that `u` (at least the unbounded lights' share)
    /// picks in proportion to `weights` (the bounded lights' importances
    /// in their order; `total` the sum of the positive ones), and its
    /// probability.
    #[inline]
    fn pick_bounded(&self, weights: &[f32], total: f32, u: f32) -> (usize, f32) {
        let first = self.bounded[0].0 as usize;
        if total <= 0.0 {
            return (first, 0.0);
        }
        let share = 1.0 - self.p_unbounded;
        let target = (u - self.p_unbounded) / share * total;
        let slot = pick_by_weight(&weights[..self.bounded.len()], target);
        (self.bounded[slot].0 as usize, share * weights[slot] / total)
    }

    /// Probability that [`select_at`](Self::select_at) picks light `i` for
    /// the shading point `p` (the point an emitter-hit ray left from).
    #[inline]
    pub fn pmf_at(&self, p: Vec3, i: usize) -> f32 {
        if !self.is_spatial() {
            return self.pmf[i];
        }
        let slot = self.slot_of[i] as usize;
        if slot < self.bounded.len() {
            let share = 1.0 - self.p_unbounded;
            if let Some(tree) = &self.tree {
                return share * tree.pmf(p, slot);
            }
            let (weights, total) = self.importances(p);
            return self.pmf_bounded(weights[slot], total);
        }
        if self.unbounded.contains(&(i as u32)) {
            self.p_unbounded / self.unbounded.len() as f32
        } else {
            0.0
        }
    }

    /// Each bounded light's importance at `p` (at most [`FLAT_LIMIT`]
    /// lights, four at a time), and their sum over the positive ones in
    /// the lights' order: [`select_at`](Self::select_at) and
    /// [`pmf_at`](Self::pmf_at) take the same one.
    #[inline]
    fn importances(&self, p: Vec3) -> ([f32; FLAT_LIMIT], f32) {
        let mut weights = [0.0f32; FLAT_LIMIT];
        for (lanes, w) in self.lanes.iter().zip(weights.chunks_exact_mut(4)) {
            w.copy_from_slice(&lanes.importance(p).to_array());
        }
        let total = positive_sum(&weights[..self.bounded.len().min(FLAT_LIMIT)]);
        (weights, total)
    }

    /// Puts each `(i, light)` of `replacements` in place of light `i`,
    /// and chooses lights anew by `selection`.
    pub fn replace(
        &mut self,
        replacements: Vec<(usize, Box<dyn Light>)>,
        selection: LightSelection,
    ) {
        let mut lights = std::mem::take(&mut self.lights);
        for (i, light) in replacements {
            lights[i] = light;
        }
        *self = Self::new(lights, selection);
    }

    /// The lights.
    pub fn lights(&self) -> &[Box<dyn Light>] {
        &self.lights
    }

    /// Number of lights.
    pub fn len(&self) -> usize {
        self.lights.len()
    }

    /// Whether there is no light.
    pub fn is_empty(&self) -> bool {
        self.lights.is_empty()
    }

    /// Chooses a light with the uniform sample `u`; returns its index, its
    /// probability, and `u` rescaled to [0, 1) for reuse.
    #[inline]
    pub fn select(&self, u: f32) -> (usize, f32, f32) {
        let i = self
            .cdf
            .partition_point(|&c| c <= u)
            .min(self.cdf.len() - 1);
        let lo = if i == 0 { 0.0 } else { self.cdf[i - 1] };
        let p = self.pmf[i];
        let rescaled = if p > 0.0 {
            ((u - lo) / p).clamp(0.0, radiant_core::ONE_MINUS_EPSILON)
        } else {
            0.0
        };
        (i, p, rescaled)
    }

    /// Whether light `i` is a delta light (cannot be hit, no MIS).
    #[inline]
    pub fn is_delta(&self, i: usize) -> bool {
        self.delta[i]
    }

    /// Whether any light's `sample` reads its 2D samples
    /// ([`Light::uses_point_samples`]): where none does, they need not be
    /// drawn.
    #[inline]
    pub fn uses_point_samples(&self) -> bool {
        self.point_samples
    }

    /// Indices of the lights that rays leaving the scene can reach (those
    /// whose effects contain [`Effects::ENVIRONMENT`]).
    pub fn environment(&self) -> &[usize] {
        &self.environment
    }

    /// Probability of choosing light `i`.
    #[inline]
    pub fn pmf(&self, i: usize) -> f32 {
        self.pmf[i]
    }
}

/// The entry of `weights` that the inverse of their running sum picks for
/// `target` in [0, sum): the first entry whose running sum exceeds it, a
/// positive one (entries ≤ 0 count as 0); where rounding puts `target` at
/// or past the sum, the last positive entry. Branch-free over the entries:
/// a loop that stopped at the picked entry would mispredict about once per
/// shading point.
#[inline]
fn pick_by_weight(weights: &[f32], target: f32) -> usize {
    let mut sum = 0.0f32;
    let mut below = 0usize;
    for &w in weights {
        sum += if w > 0.0 { w } else { 0.0 };
        below += usize::from(sum <= target);
    }
    if below < weights.len() {
        return below;
    }
    weights.iter().rposition(|&w| w > 0.0).unwrap_or(0)
}

/// The sum of the positive entries of `weights`, in their order.
#[inline]
fn positive_sum(weights: &[f32]) -> f32 {
    let mut total = 0.0f32;
    for &w in weights {
        if w > 0.0 {
            total += w;
        }
    }
    total
}

/// [`positive_sum`] in four lanes: adding zero where a weight is not
/// positive leaves a sum that starts at +0 as it is, bit for bit.
#[inline]
fn positive_sum_lanes(weights: &[Vec4]) -> Vec4 {
    let mut total = Vec4::ZERO;
    for &w in weights {
        total += Vec4::select(w.cmpgt(Vec4::ZERO), w, Vec4::ZERO);
    }
    total
}

#[cfg(test)]
mod tests {
    use super::*;
    use radiant_core::glam::{Vec2, Vec3};
    use radiant_core::{LightBounds, LightSample};

    /// A delta light of the given power, with bounds where spatial
    /// selection should weigh it.
    struct Fixed(f32, Option<LightBounds>);
    impl Light for Fixed {
        fn power(&self) -> f32 {
            self.0
        }
        fn bounds(&self) -> Option<LightBounds> {
            self.1
        }
        fn is_delta(&self) -> bool {
            true
        }
        fn sample(&self, _: &[Vec3], _: &[Vec2], _: &mut [LightSample]) {}
        fn effects(&self) -> Effects {
            Effects::DELTA_LIGHTS
        }
    }

    /// The branch-free pick against the scan it replaced (skip entries
    /// ≤ 0, stop at the first running sum above the target, else keep the
    /// last positive entry), on weights with zeros and targets on and
    /// past the running sums' boundaries.
    #[test]
    fn pick_by_weight_is_the_inverse_of_the_running_sum() {
        let scan = |weights: &[f32], target: f32| {
            let (mut acc, mut last) = (0.0f32, 0);
            for (i, &w) in weights.iter().enumerate() {
                if w <= 0.0 {
                    continue;
                }
                acc += w;
                last = i;
                if target < acc {
                    break;
                }
            }
            last
        };
        let cases: [&[f32]; 5] = [
            &[1.0],
            &[0.25, 0.75],
            &[0.0, 0.5, 0.0, 0.5, 0.0],
            &[
                3.0, 0.0, 1e-9, 2.0, 0.0, 0.0, 5.0, 1.0, 0.5, 0.0, 0.0, 0.0, 7.0, 0.0, 0.1, 0.0,
            ],
            &[0.0, 0.0, 2.0, 0.0],
        ];
        for weights in cases {
            let total: f32 = weights.iter().filter(|&&w| w > 0.0).sum();
            let mut targets: Vec<f32> = (0..=1000).map(|i| i as f32 / 1000.0 * total).collect();
            let mut sum = 0.0f32;
            for &w in weights {
                sum += w.max(0.0);
                targets.extend([sum, sum.next_down(), sum.next_up()]);
            }
            // Targets are never negative: u ≥ the unbounded lights' share.
            for target in targets.into_iter().filter(|&t| t >= 0.0) {
                assert_eq!(
                    pick_by_weight(weights, target),
                    scan(weights, target),
                    "{weights:?} at {target}"
                );
            }
        }
    }

    fn counts(selection: LightSelection) -> [usize; 3] {
        let table = LightTable::new(
            vec![
                Box::new(Fixed(1.0, None)),
                Box::new(Fixed(3.0, None)),
                Box::new(Fixed(0.0, None)),
            ],
            selection,
        );
        let n = 9_999;
        let mut counts = [0usize; 3];
        for i in 0..n {
            let (l, p, r) = table.select((i as f32 + 0.5) / n as f32);
            counts[l] += 1;
            assert_eq!(p, table.pmf(l));
            assert!((0.0..1.0).contains(&r));
        }
        counts
    }

    #[test]
    fn selection_is_proportional_to_power() {
        let [a, b, c] = counts(LightSelection::Power);
        assert!(a.abs_diff(2500) <= 1 && b.abs_diff(7499) <= 1 && c == 0);
    }

    /// The batch calls against one call per point, bit for bit: 1, 2, 5
    /// and 16 bounded lights (the lane groups' edges), with and without
    /// an unbounded light, over more points than one block.
    #[test]
    fn batches_choose_and_weigh_as_one_call_per_point() {
        let cos = |deg: f32| deg.to_radians().cos();
        for (bounded, with_unbounded) in
            [(1, false), (2, false), (5, true), (16, false), (16, true)]
        {
            let mut lights: Vec<Box<dyn Light>> = (0..bounded)
                .map(|i| {
                    let t = i as f32;
                    let at = Vec3::new((t * 1.3).sin() * 2.0, 2.0 + t * 0.1, (t * 0.7).cos());
                    let b = LightBounds::point(at, 1.0 + t, -Vec3::Y, cos(60.0 + t), cos(20.0));
                    Box::new(Fixed(b.phi, Some(b))) as Box<dyn Light>
                })
                .collect();
            if with_unbounded {
                lights.push(Box::new(Fixed(2.0, None)));
            }
            let table = LightTable::new(lights, LightSelection::Spatial);
            let n = 203;
            let points: Vec<Vec3> = (0..n)
                .map(|i| {
                    let t = i as f32 * 0.618_034;
                    Vec3::new(
                        (t * 1.7).sin() * 3.0,
                        (t * 2.3).cos(),
                        (t * 0.9).sin() * 2.0,
                    )
                })
                .collect();
            let u: Vec<f32> = (0..n).map(|i| (i as f32 * 0.754_877_7).fract()).collect();
            let (mut light, mut prob) = (vec![0u32; n], vec![0.0f32; n]);
            table.select_many(&points, &u, &mut light, &mut prob);
            let mut pmf = vec![0.0f32; n];
            table.pmf_many(&points, &light, &mut pmf);
            let mut lit = 0;
            for k in 0..n {
                let (l, p) = table.select_at(points[k], u[k]);
                assert_eq!(
                    (light[k], prob[k].to_bits()),
                    (l as u32, p.to_bits()),
                    "{k}"
                );
                let q = table.pmf_at(points[k], l);
                assert_eq!(pmf[k].to_bits(), q.to_bits(), "{k}");
                lit += usize::from(p > 0.0);
            }
            assert!(lit > n / 2, "most points have a light to choose");
        }
    }

    #[test]
    fn uniform_selection_ignores_power() {
        assert!(
            counts(LightSelection::Uniform)
                .iter()
                .all(|c| c.abs_diff(3333) <= 1)
        );
    }
}
