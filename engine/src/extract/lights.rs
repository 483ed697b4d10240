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
//! sample was drawn with.

use super::light_tree::LightTree;
use crate::settings::LightSelection;
use radiant_core::glam::Vec3;
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
    environment: Vec<usize>,
    selection: LightSelection,
    /// Spatial selection: the lights with bounds, and theirs.
    bounded: Vec<(u32, LightBounds)>,
    /// Spatial selection among at most [`FLAT_LIMIT`] bounded lights:
    /// their bounds, four lights a lane group, in `bounded`'s order.
    lanes: Vec<BoundsLanes>,
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
        let lanes = if bounded.len() <= FLAT_LIMIT {
            prepared.chunks(4).map(BoundsLanes::new).collect()
        } else {
            Vec::new()
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
            environment,
            selection,
            bounded,
            lanes,
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
        if total <= 0.0 {
            return (first as usize, 0.0);
        }
        let target = (u - self.p_unbounded) / share * total;
        let mut acc = 0.0f32;
        let mut last = (first as usize, 0.0f32);
        for ((i, _), &w) in self.bounded.iter().zip(&weights) {
            if w <= 0.0 {
                continue;
            }
            acc += w;
            last = (*i as usize, w);
            if target < acc {
                break;
            }
        }
        (last.0, share * last.1 / total)
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
            return if total > 0.0 {
                share * weights[slot] / total
            } else {
                0.0
            };
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
        let mut total = 0.0f32;
        for &w in &weights[..self.bounded.len().min(FLAT_LIMIT)] {
            if w > 0.0 {
                total += w;
            }
        }
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

#[cfg(test)]
mod tests {
    use super::*;
    use radiant_core::LightSample;
    use radiant_core::glam::{Vec2, Vec3};

    struct Fixed(f32);
    impl Light for Fixed {
        fn power(&self) -> f32 {
            self.0
        }
        fn is_delta(&self) -> bool {
            true
        }
        fn sample(&self, _: &[Vec3], _: &[Vec2], _: &mut [LightSample]) {}
        fn effects(&self) -> Effects {
            Effects::DELTA_LIGHTS
        }
    }

    fn counts(selection: LightSelection) -> [usize; 3] {
        let table = LightTable::new(
            vec![
                Box::new(Fixed(1.0)),
                Box::new(Fixed(3.0)),
                Box::new(Fixed(0.0)),
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

    #[test]
    fn uniform_selection_ignores_power() {
        assert!(
            counts(LightSelection::Uniform)
                .iter()
                .all(|c| c.abs_diff(3333) <= 1)
        );
    }
}
