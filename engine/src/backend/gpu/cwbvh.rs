//! The wide layout of the GPU's hierarchies: obvhs' compressed wide BVH
//! (Ylitie, Karras and Laine 2017, "Efficient incoherent ray traversal on
//! GPUs through compressed wide BVHs"), traversed by `wgsl/cwbvh.wgsl`.
//!
//! obvhs builds a binary BVH with one item per leaf (the binary layout's
//! builder before leaf collapsing) and converts it with its own
//! `bvh2_to_cwbvh`: up to eight children per node, up to 3 items per leaf,
//! children ordered for octant-based traversal. Its 80-byte nodes
//! ([`CwBvhNode`]) go to the shared row array as they are, five `vec4f`
//! each, with their child and item references moved to the level's place
//! in the shared arrays:
//!
//! | row | x | y | z | w |
//! |---|---|---|---|---|
//! | 0 | grid origin x | y | z | exponent bytes x, y, z; inner-child mask |
//! | 1 | first child node | first item slot | child meta 0–3 | child meta 4–7 |
//! | 2 | min x 0–3 | min x 4–7 | max x 0–3 | max x 4–7 |
//! | 3, 4 | the same for y, z | | | |
//!
//! A child box is `origin + q · 2^e` per axis with byte `q` rounded
//! outwards, so it contains its child's exact box up to the rounding of
//! the child's offset from the origin in the conversion (half an ulp of
//! `255 · 2^e`), which the traversal's error bound covers.

use super::upload::Vec4;
use obvhs::BvhBuildParams;
use obvhs::aabb::Aabb;
use obvhs::bvh2::reinsertion::ReinsertionOptimizer;
use obvhs::cwbvh::bvh2_to_cwbvh::bvh2_to_cwbvh;
use obvhs::cwbvh::node::CwBvhNode;
use obvhs::ploc::PlocBuilder;

/// `vec4f` rows per node.
pub const ROWS: usize = 5;

/// Items per leaf at most (3 is what the node's meta bytes encode).
const MAX_LEAF: u32 = 3;

/// The rows of a node that holds nothing (the root of an empty level).
pub fn empty_node() -> [Vec4; ROWS] {
    bytemuck::cast(CwBvhNode::default())
}

/// Builds a compressed wide BVH over `boxes` (at least one) with the
/// binary builder's `params`, appends its nodes to `rows` (its root
/// first) and returns the order of the items in its leaves, whose slots
/// are numbered from `first_slot` on.
pub fn append(
    boxes: &[Aabb],
    params: &BvhBuildParams,
    first_slot: u32,
    rows: &mut Vec<Vec4>,
) -> Vec<u32> {
    let mut bvh2 = PlocBuilder::with_capacity(boxes.len()).build(
        params.ploc_search_distance,
        boxes,
        (0..boxes.len() as u32).collect(),
        params.sort_precision,
        params.search_depth_threshold,
    );
    ReinsertionOptimizer::default().run(&mut bvh2, params.reinsertion_batch_ratio, None);
    let wide = bvh2_to_cwbvh(&bvh2, MAX_LEAF, true, false);
    let base = (rows.len() / ROWS) as u32;
    for node in &wide.nodes {
        let placed = CwBvhNode {
            child_base_idx: node.child_base_idx + base,
            primitive_base_idx: node.primitive_base_idx + first_slot,
            ..*node
        };
        rows.extend(bytemuck::cast::<CwBvhNode, [Vec4; ROWS]>(placed));
    }
    wide.primitive_indices
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::Vec3A;

    /// A child's box decoded exactly (in f64), grown by the conversion's
    /// rounding bound (see the module docs).
    fn child_box(node: &CwBvhNode, c: usize) -> ([f64; 3], [f64; 3]) {
        let scale = |k: usize| f64::from(f32::from_bits(u32::from(node.e[k]) << 23));
        let lo = [
            node.child_min_x[c],
            node.child_min_y[c],
            node.child_min_z[c],
        ];
        let hi = [
            node.child_max_x[c],
            node.child_max_y[c],
            node.child_max_z[c],
        ];
        let p = node.p.to_array();
        let at = |q: [u8; 3], side: f64| {
            std::array::from_fn(|k| {
                let rounding = 255.0 * scale(k) / (1u64 << 24) as f64;
                f64::from(p[k]) + f64::from(q[k]) * scale(k) + side * rounding
            })
        };
        (at(lo, -1.0), at(hi, 1.0))
    }

    /// Every item is reachable from the root exactly once, in a leaf whose
    /// decoded box contains it, and references point into the level's
    /// place in the shared arrays.
    #[test]
    fn leaves_cover_every_item_once_within_their_boxes() {
        for n in [1usize, 2, 3, 9, 100, 1000] {
            let boxes: Vec<Aabb> = (0..n)
                .map(|i| {
                    let x = (i as f32 * 0.37).sin() * 5.0 + i as f32 * 0.01;
                    let min = Vec3A::new(x, (i % 7) as f32 * 0.3, -(i as f32) * 1e-3);
                    Aabb::new(min, min + Vec3A::new(0.1, 0.2 + (i % 3) as f32, 0.05))
                })
                .collect();
            let mut rows = empty_node().to_vec();
            let order = append(&boxes, &BvhBuildParams::medium_build(), 10, &mut rows);
            let nodes: Vec<CwBvhNode> = rows
                .chunks_exact(ROWS)
                .map(|r| bytemuck::cast(<[Vec4; ROWS]>::try_from(r).expect("whole nodes")))
                .collect();
            let mut seen = vec![0; n];
            let mut stack = vec![1usize];
            while let Some(i) = stack.pop() {
                let node = &nodes[i];
                for c in 0..8 {
                    if node.is_child_empty(c) {
                        continue;
                    }
                    let (lo, hi) = child_box(node, c);
                    if !node.is_leaf(c) {
                        stack.push(node.child_node_index(c) as usize);
                        continue;
                    }
                    let (first, count) = node.child_primitives(c);
                    for slot in first..first + count {
                        let item = order[(slot - 10) as usize] as usize;
                        seen[item] += 1;
                        let b = boxes[item];
                        for k in 0..3 {
                            assert!(lo[k] <= f64::from(b.min[k]), "n = {n}, axis {k}");
                            assert!(hi[k] >= f64::from(b.max[k]), "n = {n}, axis {k}");
                        }
                    }
                }
            }
            assert!(seen.iter().all(|&s| s == 1), "n = {n}: {seen:?}");
        }
    }
}
