//! A bounding volume hierarchy that can follow its primitives as they
//! move: built by obvhs, collapsed into the wide BVH rays traverse, and
//! refitted — the tree kept, every box recomputed — when the primitives
//! move, until its SAH cost has grown past a threshold, when it is built
//! anew ([`UpdatePolicy`]).
//!
//! Both levels of the accelerator use it: a deforming mesh's bottom level
//! over triangles, and the top level over instances.

use super::wide::{LeafCost, WideBvh};
use crate::settings::BuildQuality;
use glam::Vec3A;
use obvhs::BvhBuildParams;
use obvhs::aabb::Aabb;
use obvhs::bvh2::Bvh2;
use rayon::prelude::*;
use std::ops::Range;
use std::time::{Duration, Instant};

/// When a refitted hierarchy is rebuilt.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct UpdatePolicy {
    /// Rebuild once the SAH cost after a refit exceeds the cost at the
    /// last build by this factor.
    pub rebuild_above: f32,
}

impl Default for UpdatePolicy {
    /// Rebuild at 1.3× the built cost (see the README's animation
    /// benchmark: refitting costs a few percent of a rebuild, and tracing
    /// time follows the SAH cost).
    fn default() -> Self {
        Self { rebuild_above: 1.3 }
    }
}

/// What an update of a hierarchy did.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct Update {
    /// Whether it was built anew (its primitives' order changed).
    pub rebuilt: bool,
    /// SAH cost after the update over the cost at the last build.
    pub degradation: f32,
    /// Time the update took.
    pub time: Duration,
}

/// obvhs' parameters for the binary BVH of `quality` whose leaves cost
/// `cost`.
fn params(quality: BuildQuality, cost: LeafCost) -> BvhBuildParams {
    let mut params = match quality {
        BuildQuality::Fast => BvhBuildParams::fast_build(),
        BuildQuality::Medium => BvhBuildParams::medium_build(),
        BuildQuality::High => {
            let slow = BvhBuildParams::slow_build();
            BvhBuildParams {
                reinsertion_batch_ratio: cost.reinsertion.unwrap_or(slow.reinsertion_batch_ratio),
                ..slow
            }
        }
    };
    // One primitive per leaf: the wide BVH's collapse picks the leaves.
    params.max_prims_per_leaf = 1;
    params
}

/// Boxes for the builder: a primitive without a finite box gets a point box
/// inside the scene, so that it cannot spoil the boxes above it (such a
/// primitive is never hit).
fn usable(boxes: &[Option<Aabb>]) -> Vec<Aabb> {
    let somewhere = boxes.iter().flatten().next().map_or(Vec3A::ZERO, |b| b.min);
    let point = Aabb::new(somewhere, somewhere);
    boxes.iter().map(|b| b.unwrap_or(point)).collect()
}

/// A wide BVH with the binary one it was collapsed from (kept for refits).
#[derive(Clone, Default)]
pub struct Hierarchy {
    /// What rays traverse.
    pub wide: WideBvh,
    bvh2: Bvh2,
    cost: Option<LeafCost>,
    quality: Option<BuildQuality>,
    built_cost: f32,
}

impl Hierarchy {
    /// Builds a hierarchy over primitives with boxes `boxes` (`None` where
    /// a primitive has no finite box). `leaf` receives each leaf's
    /// primitives (input indices), stores them, and returns the range of
    /// items traversal hands back for that leaf.
    pub fn build(
        boxes: &[Option<Aabb>],
        quality: BuildQuality,
        cost: LeafCost,
        leaf: impl FnMut(&[u32]) -> Range<u32>,
    ) -> Self {
        if boxes.is_empty() {
            return Self::default();
        }
        let mut core_time = Duration::default();
        let mut bvh2 =
            obvhs::bvh2::builder::build_bvh2(&usable(boxes), params(quality, cost), &mut core_time);
        // Parents before children (reinsertion leaves them in any order), so
        // that a refit is one backward sweep rather than a walk of the tree
        // first; the wide tree's sources name the nodes in this order.
        bvh2.reorder_in_stack_traversal_order();
        let wide = WideBvh::build(&bvh2, cost, leaf);
        let built_cost = wide.sah_cost(cost);
        Self {
            wide,
            bvh2,
            cost: Some(cost),
            quality: Some(quality),
            built_cost,
        }
    }

    /// Refits every box to the primitives' new boxes `boxes` (by input
    /// index, as given to [`Hierarchy::build`]); the tree and the leaves'
    /// contents stay. Returns the SAH cost over the cost at the last build.
    pub fn refit(&mut self, boxes: &[Option<Aabb>]) -> f32 {
        let Some(cost) = self.cost else {
            return 1.0;
        };
        // Primitives without a finite box get a point box inside the scene.
        let somewhere = boxes.iter().flatten().next().map_or(Vec3A::ZERO, |b| b.min);
        let point = Aabb::new(somewhere, somewhere);
        let bvh2 = &mut self.bvh2;
        let indices = &bvh2.primitive_indices;
        bvh2.nodes
            .par_iter_mut()
            .with_min_len(4096)
            .filter(|n| n.is_leaf())
            .for_each(|node| {
                let first = node.first_index as usize;
                let prims = &indices[first..first + node.prim_count as usize];
                let aabb = prims.iter().fold(Aabb::empty(), |a, &p| {
                    a.union(boxes[p as usize].as_ref().unwrap_or(&point))
                });
                node.set_aabb(aabb);
            });
        bvh2.refit_all();
        self.wide.refit(bvh2);
        self.degradation_of(cost)
    }

    /// The SAH cost now over the cost at the last build.
    fn degradation_of(&self, cost: LeafCost) -> f32 {
        if self.built_cost > 0.0 {
            self.wide.sah_cost(cost) / self.built_cost
        } else {
            1.0
        }
    }

    /// Follows primitives that moved to `boxes`: refits, and rebuilds (with
    /// `leaf` storing the new leaves, as in [`Hierarchy::build`]) where the
    /// refitted tree's SAH cost has grown past `policy`.
    pub fn update(
        &mut self,
        boxes: &[Option<Aabb>],
        policy: UpdatePolicy,
        leaf: impl FnMut(&[u32]) -> Range<u32>,
    ) -> Update {
        let start = Instant::now();
        let degradation = self.refit(boxes);
        if degradation <= policy.rebuild_above {
            return Update {
                rebuilt: false,
                degradation,
                time: start.elapsed(),
            };
        }
        let (Some(quality), Some(cost)) = (self.quality, self.cost) else {
            return Update::default();
        };
        *self = Self::build(boxes, quality, cost, leaf);
        Update {
            rebuilt: true,
            degradation: 1.0,
            time: start.elapsed(),
        }
    }

    /// The SAH cost now over the cost at the last build (1 right after a
    /// build).
    pub fn degradation(&self) -> f32 {
        self.cost.map_or(1.0, |c| self.degradation_of(c))
    }

    /// The SAH cost of the wide tree.
    pub fn sah_cost(&self) -> f32 {
        self.cost.map_or(0.0, |c| self.wide.sah_cost(c))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::accel::tests::lcg;

    /// Random boxes of up to a tenth of the unit cube (some `None`).
    fn boxes(seed: u64, n: usize) -> Vec<Option<Aabb>> {
        let mut s = seed;
        (0..n)
            .map(|i| {
                let p = Vec3A::new(lcg(&mut s), lcg(&mut s), lcg(&mut s));
                let e = Vec3A::new(lcg(&mut s), lcg(&mut s), lcg(&mut s)) * 0.1;
                (i % 97 != 5).then(|| Aabb::new(p, p + e))
            })
            .collect()
    }

    /// Whether every inner node's children come after it, the order in
    /// which obvhs refits in one backward sweep.
    fn parents_first(bvh2: &Bvh2) -> bool {
        bvh2.children_are_ordered_after_parents
            && bvh2
                .nodes
                .iter()
                .enumerate()
                .all(|(i, n)| n.is_leaf() || n.first_index as usize > i)
    }

    #[test]
    fn a_high_quality_build_reinserts_as_its_leaf_cost_asks() {
        // The top level's ratio against none: re-insertion must show in
        // the tree's cost, or `LeafCost::reinsertion` does not reach obvhs.
        let sah = |reinsertion| {
            let cost = LeafCost {
                reinsertion: Some(reinsertion),
                ..LeafCost::INSTANCES
            };
            Hierarchy::build(&boxes(3, 3000), BuildQuality::High, cost, |l| {
                0..l.len() as u32
            })
            .sah_cost()
        };
        let (none, thorough) = (
            sah(0.0),
            sah(LeafCost::INSTANCES.reinsertion.unwrap_or(0.0)),
        );
        assert!(thorough < 0.99 * none, "{thorough} against {none}");
    }

    #[test]
    fn builds_and_rebuilds_order_parents_before_children() {
        for quality in [BuildQuality::Fast, BuildQuality::Medium, BuildQuality::High] {
            let mut h = Hierarchy::build(&boxes(1, 3000), quality, LeafCost::PACKETS, |l| {
                0..l.len() as u32
            });
            assert!(parents_first(&h.bvh2), "{quality:?}: built");
            let always = UpdatePolicy { rebuild_above: 0.0 };
            let update = h.update(&boxes(2, 3000), always, |l| 0..l.len() as u32);
            assert!(update.rebuilt);
            assert!(parents_first(&h.bvh2), "{quality:?}: rebuilt");
        }
    }
}
