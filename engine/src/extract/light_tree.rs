//! The light tree: a bounding volume hierarchy over the lights'
//! [`LightBounds`], for spatial light selection among many lights
//! (pbrt-v4's `BVHLightSampler`, after Conty and Kulla 2018).
//!
//! Each node holds the union of its lights' bounds (box, power, normal
//! cone, emission angle). Selection walks from the root, choosing a child
//! in proportion to its [`LightBounds::importance`] at the shading point
//! and multiplying the probabilities on the way; the probability of a
//! given light ([`LightTree::pmf`]) walks the same way along the light's
//! recorded branch bits, with the same arithmetic, so it equals the
//! probability selection reported bit for bit. The tree splits at the
//! median of the lights' centres along the widest axis, so it is balanced
//! and at most 64 levels deep for any number of lights that fits in memory.

use radiant_core::LightBounds;
use radiant_core::glam::Vec3;

/// One node: a light, or two children (the first right after the node).
#[derive(Debug, Clone, Copy)]
pub struct Node {
    /// The union of the bounds of the node's lights.
    pub bounds: LightBounds,
    /// Leaf: the light's slot. Interior: the second child's index.
    pub index: u32,
    /// Whether the node is one light.
    pub leaf: bool,
}

/// A hierarchy over lights, addressed by their slot (0..n in the order
/// they were given).
#[derive(Debug, Clone, Default)]
pub struct LightTree {
    nodes: Vec<Node>,
    /// Per slot: the branch bits from the root (bit d set: second child
    /// at depth d) and the depth of its leaf.
    trail: Vec<(u64, u32)>,
}

impl LightTree {
    /// Builds the tree over `bounds` (at least one).
    pub fn new(bounds: &[LightBounds]) -> Self {
        let mut tree = Self {
            nodes: Vec::with_capacity(2 * bounds.len()),
            trail: vec![(0, 0); bounds.len()],
        };
        let mut slots: Vec<u32> = (0..bounds.len() as u32).collect();
        if !slots.is_empty() {
            tree.build(bounds, &mut slots, 0, 0);
        }
        tree
    }

    fn build(&mut self, bounds: &[LightBounds], slots: &mut [u32], bits: u64, depth: u32) -> usize {
        let at = self.nodes.len();
        if let [slot] = slots {
            self.nodes.push(Node {
                bounds: bounds[*slot as usize],
                index: *slot,
                leaf: true,
            });
            self.trail[*slot as usize] = (bits, depth);
            return at;
        }
        let centre = |s: &u32| {
            let b = &bounds[*s as usize];
            (b.min + b.max) * 0.5
        };
        let (lo, hi) = slots.iter().fold(
            (Vec3::splat(f32::INFINITY), Vec3::splat(f32::NEG_INFINITY)),
            |(lo, hi), s| (lo.min(centre(s)), hi.max(centre(s))),
        );
        let extent = hi - lo;
        let axis = if extent.x >= extent.y && extent.x >= extent.z {
            0
        } else if extent.y >= extent.z {
            1
        } else {
            2
        };
        slots.sort_by(|a, b| centre(a)[axis].total_cmp(&centre(b)[axis]));
        let mid = slots.len() / 2;
        // Placeholder, filled once the children exist.
        self.nodes.push(Node {
            bounds: bounds[slots[0] as usize],
            index: 0,
            leaf: false,
        });
        let (left, right) = slots.split_at_mut(mid);
        let first = self.build(bounds, left, bits, depth + 1);
        let second = self.build(bounds, right, bits | (1 << depth), depth + 1);
        self.nodes[at] = Node {
            bounds: union(&self.nodes[first].bounds, &self.nodes[second].bounds),
            index: second as u32,
            leaf: false,
        };
        at
    }

    /// The nodes, root first (for backends that walk the tree themselves).
    pub fn nodes(&self) -> &[Node] {
        &self.nodes
    }

    /// The branch bits from the root (bit d set: second child at depth d)
    /// and the depth of the leaf of `slot`.
    pub fn trail(&self, slot: usize) -> Option<(u64, u32)> {
        self.trail.get(slot).copied()
    }

    /// Chooses a light slot for the shading point `p` with the uniform
    /// sample `u`; `None` where no light can reach `p`.
    #[inline]
    pub fn select(&self, p: Vec3, mut u: f32) -> Option<(usize, f32)> {
        let mut node = 0usize;
        let mut pmf = 1.0f32;
        loop {
            let n = self.nodes.get(node)?;
            if n.leaf {
                return (n.bounds.importance(p) > 0.0).then_some((n.index as usize, pmf));
            }
            let (first, second) = (node + 1, n.index as usize);
            let p_first = self.first_probability(first, second, p)?;
            if u < p_first {
                u = (u / p_first).min(radiant_core::ONE_MINUS_EPSILON);
                pmf *= p_first;
                node = first;
            } else {
                u = ((u - p_first) / (1.0 - p_first)).clamp(0.0, radiant_core::ONE_MINUS_EPSILON);
                pmf *= 1.0 - p_first;
                node = second;
            }
        }
    }

    /// Probability that [`select`](Self::select) picks `slot` at `p`.
    #[inline]
    pub fn pmf(&self, p: Vec3, slot: usize) -> f32 {
        let Some(&(bits, depth)) = self.trail.get(slot) else {
            return 0.0;
        };
        let mut node = 0usize;
        let mut pmf = 1.0f32;
        for d in 0..depth {
            let second = self.nodes[node].index as usize;
            let Some(p_first) = self.first_probability(node + 1, second, p) else {
                return 0.0;
            };
            if bits >> d & 1 == 0 {
                pmf *= p_first;
                node += 1;
            } else {
                pmf *= 1.0 - p_first;
                node = second;
            }
        }
        if self.nodes[node].bounds.importance(p) > 0.0 {
            pmf
        } else {
            0.0
        }
    }

    /// The probability of descending into `first` rather than `second`
    /// at `p`; `None` if neither can reach `p`.
    #[inline]
    fn first_probability(&self, first: usize, second: usize, p: Vec3) -> Option<f32> {
        let a = self.nodes[first].bounds.importance(p);
        let b = self.nodes[second].bounds.importance(p);
        let total = a + b;
        (total > 0.0).then(|| a / total)
    }
}

/// The bounds of two sets of lights together.
fn union(a: &LightBounds, b: &LightBounds) -> LightBounds {
    let (axis, cos_theta_o) = cone_union(a.axis, a.cos_theta_o, b.axis, b.cos_theta_o);
    LightBounds {
        min: a.min.min(b.min),
        max: a.max.max(b.max),
        phi: a.phi + b.phi,
        axis,
        cos_theta_o,
        cos_theta_e: a.cos_theta_e.min(b.cos_theta_e),
        two_sided: a.two_sided || b.two_sided,
    }
}

/// The smallest cone (axis, cos of its half angle) holding two cones
/// (pbrt-v4's `DirectionCone::Union`).
fn cone_union(wa: Vec3, cos_a: f32, wb: Vec3, cos_b: f32) -> (Vec3, f32) {
    let theta_a = cos_a.clamp(-1.0, 1.0).acos();
    let theta_b = cos_b.clamp(-1.0, 1.0).acos();
    let theta_d = wa.dot(wb).clamp(-1.0, 1.0).acos();
    let pi = std::f32::consts::PI;
    if (theta_d + theta_b).min(pi) <= theta_a {
        return (wa, cos_a);
    }
    if (theta_d + theta_a).min(pi) <= theta_b {
        return (wb, cos_b);
    }
    let theta_o = (theta_a + theta_d + theta_b) * 0.5;
    if theta_o >= pi {
        return (wa, -1.0);
    }
    let wr = wa.cross(wb);
    if wr.length_squared() == 0.0 {
        return (wa, -1.0);
    }
    let rotation = radiant_core::glam::Quat::from_axis_angle(wr.normalize(), theta_o - theta_a);
    // Widen a little so that rounding never narrows the cone.
    let cos_o = (theta_o + 1e-4).min(pi).cos();
    ((rotation * wa).normalize(), cos_o)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_cone_union_holds_both_cones() {
        let cases = [
            (Vec3::Z, 0.9f32, Vec3::X, 0.95f32),
            (Vec3::Z, 1.0, Vec3::new(0.0, 1.0, 1.0).normalize(), 1.0),
            (Vec3::Z, 0.0, -Vec3::Z, 0.5),
            (Vec3::Y, 0.99, Vec3::Y, 0.5),
        ];
        for (wa, ca, wb, cb) in cases {
            let (w, c) = cone_union(wa, ca, wb, cb);
            for (axis, cos) in [(wa, ca), (wb, cb)] {
                // The cone's edge in the plane of the two axes lies inside.
                let angle = w.dot(axis).clamp(-1.0, 1.0).acos() + cos.clamp(-1.0, 1.0).acos();
                assert!(
                    angle.min(std::f32::consts::PI) <= c.clamp(-1.0, 1.0).acos() + 1e-5,
                    "({wa}, {ca}) ∪ ({wb}, {cb}) = ({w}, {c}) misses ({axis}, {cos})"
                );
            }
        }
    }

    #[test]
    fn every_light_sits_at_its_recorded_branch() {
        let bounds: Vec<LightBounds> = (0..37)
            .map(|i| {
                let p = Vec3::new((i * 7 % 11) as f32, (i * 3 % 5) as f32, i as f32 * 0.1);
                LightBounds::point(p, 1.0 + i as f32, Vec3::Z, -1.0, 0.0)
            })
            .collect();
        let tree = LightTree::new(&bounds);
        assert_eq!(tree.nodes.len(), 2 * bounds.len() - 1);
        for (slot, &(bits, depth)) in tree.trail.iter().enumerate() {
            let mut node = 0;
            for d in 0..depth {
                node = if bits >> d & 1 == 0 {
                    node + 1
                } else {
                    tree.nodes[node].index as usize
                };
            }
            assert!(tree.nodes[node].leaf && tree.nodes[node].index as usize == slot);
            assert!(depth <= 6, "37 lights, depth {depth}");
        }
    }
}
