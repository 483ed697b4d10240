//! The GPU's hierarchy layouts, built from obvhs BVHs over the items'
//! boxes (primitives of a bottom level, instances of the top level) and
//! appended to one array of `vec4f` rows that all levels share; a level's
//! root is a node index into it. [`BvhLayout`] picks the layout for the
//! whole frame:
//!
//! - binary: obvhs' binary BVH with up to 4 primitives per leaf, its nodes
//!   holding both children's boxes (four rows, 64 bytes: a child's box
//!   with its reference in `min.w` and its primitive count in `max.w`, 0
//!   for an inner child), so that a traversal step reads one node and
//!   tests two boxes;
//! - wide: obvhs' compressed wide BVH ([`super::cwbvh`], five rows, 80
//!   bytes: eight quantized child boxes).
//!
//! Leaves reference runs of item slots; [`Level::order`] says which item
//! each slot holds.

use super::BvhLayout;
use super::upload::Vec4;
use glam::Vec3A;
use obvhs::BvhBuildParams;
use obvhs::aabb::Aabb;
use obvhs::bvh2::Bvh2;
use std::time::Duration;

/// A binary node: four rows (see the module docs).
type Node = [Vec4; 4];

/// Primitives per leaf at most.
const MAX_LEAF: u32 = 4;

impl BvhLayout {
    /// `vec4f` rows per node.
    pub fn rows_per_node(self) -> usize {
        match self {
            BvhLayout::Binary => 4,
            BvhLayout::Wide => super::cwbvh::ROWS,
        }
    }
}

/// A built level: where its root is and the order of its items.
#[derive(Debug, Clone, PartialEq)]
pub struct Level {
    /// The root's index in the shared node array.
    pub root: u32,
    /// Per slot (leaf order), the index of the item in the input.
    pub order: Vec<u32>,
}

/// Builds a level of `layout` over `boxes` (one per item; `None` where an
/// item has no finite box), appends its nodes to `rows` and returns its
/// root and the order of the items in its leaves; leaves reference slots
/// from `first_slot` on.
pub fn build_level(
    boxes: &[Option<Aabb>],
    first_slot: u32,
    layout: BvhLayout,
    rows: &mut Vec<Vec4>,
) -> Level {
    let root = (rows.len() / layout.rows_per_node()) as u32;
    if boxes.is_empty() {
        match layout {
            BvhLayout::Binary => rows.extend(node([empty_child(), empty_child()])),
            BvhLayout::Wide => rows.extend(super::cwbvh::empty_node()),
        }
        return Level {
            root,
            order: Vec::new(),
        };
    }
    let somewhere = boxes.iter().flatten().next().map_or(Vec3A::ZERO, |b| b.min);
    let point = Aabb::new(somewhere, somewhere);
    let usable: Vec<Aabb> = boxes.iter().map(|b| b.unwrap_or(point)).collect();
    let params = BvhBuildParams::medium_build();
    match layout {
        BvhLayout::Binary => {
            let params = BvhBuildParams {
                max_prims_per_leaf: MAX_LEAF,
                ..params
            };
            let bvh = obvhs::bvh2::builder::build_bvh2(&usable, params, &mut Duration::default());
            rows.extend(flatten(&bvh, first_slot, root).into_iter().flatten());
            Level {
                root,
                order: bvh.primitive_indices.clone(),
            }
        }
        BvhLayout::Wide => {
            let order = super::cwbvh::append(&usable, &params, first_slot, rows);
            Level { root, order }
        }
    }
}

/// One child's two `vec4f`.
type Child = [[f32; 4]; 2];

/// A child that holds nothing: an inner reference to no node (`u32::MAX`,
/// which traversal treats as nothing to visit; a box test alone cannot
/// reject it, since slab tests take an inverted box for the whole space).
fn empty_child() -> Child {
    [
        [f32::MAX, f32::MAX, f32::MAX, f32::from_bits(u32::MAX)],
        [-f32::MAX, -f32::MAX, -f32::MAX, 0.0],
    ]
}

fn child(aabb: &Aabb, reference: u32, count: u32) -> Child {
    [
        [
            aabb.min.x,
            aabb.min.y,
            aabb.min.z,
            f32::from_bits(reference),
        ],
        [aabb.max.x, aabb.max.y, aabb.max.z, f32::from_bits(count)],
    ]
}

fn node([a, b]: [Child; 2]) -> Node {
    [a[0], a[1], b[0], b[1]]
}

/// The nodes of `bvh` in depth-first order (the root first), numbered
/// from `base` on.
fn flatten(bvh: &Bvh2, first_slot: u32, base: u32) -> Vec<Node> {
    let root = &bvh.nodes[0];
    if root.prim_count > 0 {
        // A single leaf: a node whose one child is it.
        let leaf = child(&root.aabb, first_slot + root.first_index, root.prim_count);
        return vec![node([leaf, empty_child()])];
    }
    // Depth first; each inner node's slot is filled in once its children
    // have indices.
    let mut nodes = vec![node([empty_child(), empty_child()])];
    let mut pending = vec![(0usize, 0usize)];
    while let Some((index, at)) = pending.pop() {
        let first = bvh.nodes[index].first_index as usize;
        let mut children = [empty_child(), empty_child()];
        for (k, c) in children.iter_mut().enumerate() {
            let n = &bvh.nodes[first + k];
            *c = if n.prim_count > 0 {
                child(&n.aabb, first_slot + n.first_index, n.prim_count)
            } else {
                let slot = nodes.len();
                nodes.push(node([empty_child(), empty_child()]));
                pending.push((first + k, slot));
                child(&n.aabb, base + slot as u32, 0)
            };
        }
        nodes[at] = node(children);
    }
    nodes
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::Vec3A;

    fn unit_box(x: f32) -> Option<Aabb> {
        Some(Aabb::new(
            Vec3A::new(x, 0.0, 0.0),
            Vec3A::new(x + 1.0, 1.0, 1.0),
        ))
    }

    /// Every item is reachable from the root exactly once, in a leaf whose
    /// box contains it.
    #[test]
    fn leaves_cover_every_item_once() {
        for n in [1usize, 2, 5, 100] {
            let boxes: Vec<_> = (0..n).map(|i| unit_box(i as f32 * 2.0)).collect();
            let mut rows: Vec<Vec4> = node([empty_child(), empty_child()]).to_vec();
            let level = build_level(&boxes, 10, BvhLayout::Binary, &mut rows);
            assert_eq!(level.root, 1);
            let mut seen = vec![0; n];
            let mut stack = vec![level.root];
            while let Some(i) = stack.pop() {
                let nd = &rows[4 * i as usize..4 * i as usize + 4];
                for c in [0, 2] {
                    let (lo, hi) = (nd[c], nd[c + 1]);
                    let (reference, count) = (lo[3].to_bits(), hi[3].to_bits());
                    if reference == u32::MAX {
                        assert_eq!(count, 0);
                        continue;
                    }
                    if count == 0 {
                        stack.push(reference);
                        continue;
                    }
                    for slot in reference..reference + count {
                        let item = level.order[(slot - 10) as usize] as usize;
                        seen[item] += 1;
                        let b = boxes[item].expect("finite");
                        assert!(lo[0] <= b.min.x && hi[0] >= b.max.x, "n = {n}");
                    }
                }
            }
            assert!(seen.iter().all(|&s| s == 1), "n = {n}: {seen:?}");
        }
    }
}
