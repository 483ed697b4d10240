//! Closest hits of eight coherent rays in one traversal.
//!
//! Camera rays through one pixel (a batch holds a pixel's samples one
//! after the other) start at the same point and leave in nearly the same
//! direction, so they visit the same nodes. [`WideBvh::closest_packet`]
//! visits each of those nodes once for the eight of them: the rays are the
//! eight AVX lanes, tested against one child box after another, instead of
//! each ray testing the eight boxes of every node it visits on its own.
//!
//! Each lane's box test is the single-ray test's operations in the same
//! order, so a lane meets exactly the boxes its ray would alone. A leaf
//! goes to a [`PacketLeafVisitor`] with the lanes that reach it (a bottom
//! level tests one triangle against all of them, `Tri4::test_rays`; a top
//! level enters its instances lane by lane), so every ray gets the hit
//! that [`WideBvh::closest`] finds (up to which of two primitives at
//! exactly the same distance wins, which depends on the order the leaves
//! are visited in). The rays must share the signs of their directions
//! ([`RayPacket::new`]), which makes the near and far side of each box the
//! same for all lanes; rays of one pixel do unless they straddle an axis,
//! and eight incoherent rays almost never.

use super::{FAR_SCALE, MAX_DEPTH, Node, OFFSETS, Offsets, WIDTH, WideBvh};
use glam::Vec3;
use std::arch::x86_64::*;
use std::mem::MaybeUninit;
use std::ops::Range;

/// What a packet's traversal does at a leaf: intersects the leaf's items
/// with some of the packet's rays. Implementations mark the method
/// `#[inline(always)]`, so that it compiles into the traversal.
pub trait PacketLeafVisitor {
    /// Intersects items `range` with the rays of `lanes` (a bit each) for
    /// their closest hits, each within its `tmax`, which it lowers to the
    /// hits it finds.
    fn closest(&mut self, range: Range<usize>, lanes: u32, tmax: &mut [f32; PACKET]);
}

/// Rays per packet: the lanes of one AVX register.
pub const PACKET: usize = 8;

/// Eight rays whose directions share their signs, structure-of-arrays.
#[derive(Debug, Clone, Copy)]
pub struct RayPacket {
    /// Per axis: the rays' origins along it.
    origin: [__m256; 3],
    /// Per axis: the inverse of the rays' directions along it.
    inv_dir: [__m256; 3],
    /// The byte offsets of the near and far sides of a node's boxes, as
    /// [`super::RayBoxes`] holds them: the same for every lane.
    offsets: &'static Offsets,
}

/// An inner node waiting on a packet's stack: the lanes that entered its
/// box, and the nearest distance at which one of them did.
#[derive(Debug, Clone, Copy)]
struct Entry {
    node: u32,
    lanes: u32,
    t: f32,
}

/// A node pushes at most `WIDTH` children and pops one.
const STACK_SIZE: usize = (WIDTH - 1) * MAX_DEPTH + 1;

/// Eight points or vectors, structure-of-arrays: per axis, the eight
/// coordinates along it in order. (An 8×3 transpose in eleven
/// instructions: four 128-bit loads and inserts per pair, five shuffles.)
#[target_feature(enable = "avx2")]
#[inline]
pub fn lanes_of(v: &[Vec3; PACKET]) -> [__m256; 3] {
    // SAFETY: `v` is 24 contiguous f32 (a `Vec3` is three f32 without
    // padding); the loads read 16 bytes at f32 offsets 0 to 20.
    unsafe {
        let p = v.as_ptr().cast::<f32>();
        let load = |at: usize| _mm_loadu_ps(p.add(at));
        // x0 y0 z0 x1 | x4 y4 z4 x5, y1 z1 x2 y2 | y5 z5 x6 y6,
        // z2 x3 y3 z3 | z6 x7 y7 z7.
        let m03 = _mm256_insertf128_ps::<1>(_mm256_castps128_ps256(load(0)), load(12));
        let m14 = _mm256_insertf128_ps::<1>(_mm256_castps128_ps256(load(4)), load(16));
        let m25 = _mm256_insertf128_ps::<1>(_mm256_castps128_ps256(load(8)), load(20));
        // x2 y2 x3 y3 | x6 y6 x7 y7 and y0 z0 y1 z1 | y4 z4 y5 z5.
        let xy = _mm256_shuffle_ps::<0b10_01_11_10>(m14, m25);
        let yz = _mm256_shuffle_ps::<0b01_00_10_01>(m03, m14);
        [
            _mm256_shuffle_ps::<0b10_00_11_00>(m03, xy),
            _mm256_shuffle_ps::<0b11_01_10_00>(yz, xy),
            _mm256_shuffle_ps::<0b11_00_11_01>(yz, m25),
        ]
    }
}

impl RayPacket {
    /// The packet of rays with origins `origin` and directions `dir`
    /// (finite; [`lanes_of`] the rays'), or `None` where the directions'
    /// components do not all have the same signs.
    #[target_feature(enable = "avx2")]
    #[inline]
    pub fn new(origin: [__m256; 3], dir: [__m256; 3]) -> Option<Self> {
        // The quotients of `RayBoxes::new`: 1/d per component.
        let inv_dir = dir.map(|d| _mm256_div_ps(_mm256_set1_ps(1.0), d));
        let negative = inv_dir
            .map(|v| _mm256_movemask_ps(_mm256_cmp_ps::<_CMP_LT_OQ>(v, _mm256_setzero_ps())));
        if negative.iter().any(|&m| m != 0 && m != 0xff) {
            return None;
        }
        let signs = (negative[0] & 1) | (negative[1] & 2) | (negative[2] & 4);
        Some(Self {
            origin,
            inv_dir,
            offsets: &OFFSETS[signs as usize],
        })
    }
}

/// The lanes of a mask of eight bits as an AVX mask (all ones where set).
#[target_feature(enable = "avx2")]
#[inline]
pub fn lane_mask(lanes: u32) -> __m256 {
    let bits = _mm256_setr_epi32(1, 2, 4, 8, 16, 32, 64, 128);
    let chosen = _mm256_and_si256(_mm256_set1_epi32(lanes as i32), bits);
    _mm256_castsi256_ps(_mm256_cmpeq_epi32(chosen, bits))
}

/// The smallest of eight lanes.
#[target_feature(enable = "avx2")]
fn min_lane(v: __m256) -> f32 {
    let m = _mm_min_ps(_mm256_castps256_ps128(v), _mm256_extractf128_ps::<1>(v));
    let m = _mm_min_ps(m, _mm_movehl_ps(m, m));
    let m = _mm_min_ss(m, _mm_movehdup_ps(m));
    _mm_cvtss_f32(m)
}

/// One child's box against the packet's lanes.
#[derive(Clone, Copy)]
struct ChildHits {
    /// The lanes that meet the box within their `tmax`.
    lanes: u32,
    /// Each lane's entry distance.
    t_near: [f32; PACKET],
    /// The smallest entry distance of `lanes`.
    t_min: f32,
}

impl RayPacket {
    /// Child `c` of `node` against the `active` lanes (`active_mask`, the
    /// same as an AVX mask) with their `tmax`: the single-ray test's
    /// operations lane by lane ([`super::RayBoxes::test`]).
    #[target_feature(enable = "avx2")]
    #[inline]
    fn test_child(&self, node: &Node, c: usize, tmax: __m256, active_mask: __m256) -> ChildHits {
        let bytes = (node as *const Node).cast::<u8>();
        // SAFETY: an offset of `OFFSETS` plus 4·c, c < 8, addresses one
        // f32 of `node.bounds` (`RayBoxes::lanes`).
        let bound = |offset: u32| unsafe {
            _mm256_broadcast_ss(&*bytes.add(offset as usize + 4 * c).cast::<f32>())
        };
        let mut t_near = _mm256_setzero_ps();
        let mut t_far = tmax;
        for axis in 0..3 {
            let (origin, inv_dir) = (self.origin[axis], self.inv_dir[axis]);
            let lo = _mm256_mul_ps(_mm256_sub_ps(bound(self.offsets.0[axis]), origin), inv_dir);
            let hi = _mm256_mul_ps(_mm256_sub_ps(bound(self.offsets.1[axis]), origin), inv_dir);
            t_near = _mm256_max_ps(lo, t_near);
            t_far = _mm256_min_ps(hi, t_far);
        }
        let far = _mm256_mul_ps(t_far, _mm256_set1_ps(FAR_SCALE));
        let hit = _mm256_and_ps(_mm256_cmp_ps::<_CMP_LE_OQ>(t_near, far), active_mask);
        let mut hits = ChildHits {
            lanes: _mm256_movemask_ps(hit) as u32,
            t_near: [0.0; PACKET],
            t_min: f32::INFINITY,
        };
        if hits.lanes != 0 {
            // SAFETY: `t_near` holds eight f32.
            unsafe { _mm256_storeu_ps(hits.t_near.as_mut_ptr(), t_near) };
            hits.t_min = min_lane(_mm256_blendv_ps(_mm256_set1_ps(f32::INFINITY), t_near, hit));
        }
        hits
    }
}

/// The lanes whose entry distance `t` is within their `tmax` (scaled as
/// the box test scales it), a bit each.
#[target_feature(enable = "avx2")]
#[inline]
fn within(t: __m256, tmax: &[f32; PACKET]) -> u32 {
    // SAFETY: `tmax` holds eight f32.
    let far = _mm256_mul_ps(
        unsafe { _mm256_loadu_ps(tmax.as_ptr()) },
        _mm256_set1_ps(FAR_SCALE),
    );
    _mm256_movemask_ps(_mm256_cmp_ps::<_CMP_LE_OQ>(t, far)) as u32
}

/// The lanes of `lanes` that may still meet a box entered at `t` at the
/// nearest (see [`within`]).
#[target_feature(enable = "avx2")]
#[inline]
fn lanes_within(tmax: &[f32; PACKET], t: f32, lanes: u32) -> u32 {
    within(_mm256_set1_ps(t), tmax) & lanes
}

/// Of the children in `children` (a bit each, at least one), the one
/// with the smallest `t_min`; the first of equal ones.
#[inline(always)]
fn nearest_child(children: u32, t_min: impl Fn(usize) -> f32) -> usize {
    let mut nearest = children.trailing_zeros() as usize;
    let mut rest = children & (children - 1);
    while rest != 0 {
        let other = rest.trailing_zeros() as usize;
        rest &= rest - 1;
        if t_min(other) < t_min(nearest) {
            nearest = other;
        }
    }
    nearest
}

impl WideBvh {
    /// The packet form of [`WideBvh::closest`]: visits the leaves that
    /// each lane of `rays` in `active` may hit in (0, `tmax[lane]`), with
    /// `leaf`, which lowers `tmax` to the hits it finds.
    #[target_feature(enable = "avx2")]
    pub fn closest_packet(
        &self,
        rays: &RayPacket,
        tmax: &mut [f32; PACKET],
        active: u32,
        leaf: &mut impl PacketLeafVisitor,
    ) {
        if self.nodes.is_empty() || active == 0 {
            return;
        }
        let mut stack = [MaybeUninit::<Entry>::uninit(); STACK_SIZE];
        let mut len = 0;
        let (mut current, mut active) = (0, active);
        let mut children = [MaybeUninit::<ChildHits>::uninit(); WIDTH];
        loop {
            let node = self.node(current);
            // SAFETY: `tmax` holds eight f32.
            let tmax_v = unsafe { _mm256_loadu_ps(tmax.as_ptr()) };
            let active_mask = lane_mask(active);
            let (mut leaf_hits, mut inner_hits) = (0u32, 0u32);
            let leaf_lanes = node.leaves();
            let mut used = node.used();
            while used != 0 {
                let c = used.trailing_zeros() as usize;
                used &= used - 1;
                let hits = rays.test_child(node, c, tmax_v, active_mask);
                if hits.lanes != 0 {
                    children[c].write(hits);
                    if leaf_lanes & (1 << c) != 0 {
                        leaf_hits |= 1 << c;
                    } else {
                        inner_hits |= 1 << c;
                    }
                }
            }
            // SAFETY: the children of `leaf_hits` and `inner_hits` were
            // written above.
            let child = |c: usize| unsafe { children[c].assume_init_ref() };
            // Leaves nearest first, each lane skipping those its hits so far
            // put beyond reach.
            while leaf_hits != 0 {
                let c = nearest_child(leaf_hits, |c| child(c).t_min);
                leaf_hits &= !(1 << c);
                let hits = child(c);
                // SAFETY: `t_near` holds eight f32.
                let t_near = unsafe { _mm256_loadu_ps(hits.t_near.as_ptr()) };
                let lanes = hits.lanes & within(t_near, tmax);
                if lanes != 0 {
                    leaf.closest(node.items(c), lanes, tmax);
                }
            }
            // Inner children: the nearest is visited next, the others are
            // pushed farthest first.
            if inner_hits != 0 {
                let nearest = nearest_child(inner_hits, |c| child(c).t_min);
                let mut pending = inner_hits & !(1 << nearest);
                let base = len;
                while pending != 0 {
                    let c = pending.trailing_zeros() as usize;
                    pending &= pending - 1;
                    let e = Entry {
                        node: node.child[c],
                        lanes: child(c).lanes,
                        t: child(c).t_min,
                    };
                    // Insertion: entries above `base` by decreasing `t`.
                    let mut i = len;
                    len += 1;
                    // SAFETY: entries below `len` were written.
                    while i > base && unsafe { stack[i - 1].assume_init_ref() }.t < e.t {
                        stack[i] = stack[i - 1];
                        i -= 1;
                    }
                    stack[i].write(e);
                }
                let lanes = lanes_within(tmax, child(nearest).t_min, child(nearest).lanes);
                if lanes != 0 {
                    current = node.child[nearest] as usize;
                    active = lanes;
                    continue;
                }
            }
            // Next: the nearest pending node that a lane may still meet.
            loop {
                if len == 0 {
                    return;
                }
                len -= 1;
                // SAFETY: entries below the old `len` were written.
                let e = unsafe { stack[len].assume_init() };
                let lanes = lanes_within(tmax, e.t, e.lanes);
                if lanes != 0 {
                    current = e.node as usize;
                    active = lanes;
                    break;
                }
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// An AVX register's lanes.
    fn lanes(v: __m256) -> [f32; PACKET] {
        // SAFETY: an `__m256` is eight f32.
        unsafe { std::mem::transmute(v) }
    }

    #[test]
    fn lanes_of_transposes_eight_vectors() {
        if !is_x86_feature_detected!("avx2") {
            eprintln!("no AVX2: packets are never traced on this CPU");
            return;
        }
        // Every coordinate distinct, so a misplaced one shows.
        let v: [Vec3; PACKET] =
            std::array::from_fn(|i| Vec3::new(i as f32, 10.0 + i as f32, 20.0 + i as f32));
        // SAFETY: the CPU has AVX2 (checked above).
        let [x, y, z] = unsafe { lanes_of(&v) };
        assert_eq!(lanes(x), v.map(|p| p.x));
        assert_eq!(lanes(y), v.map(|p| p.y));
        assert_eq!(lanes(z), v.map(|p| p.z));
    }

    #[test]
    fn lane_masks_set_the_chosen_lanes() {
        if !is_x86_feature_detected!("avx2") {
            eprintln!("no AVX2: packets are never traced on this CPU");
            return;
        }
        for bits in [0u32, 1, 0x80, 0xa5, 0xff] {
            // SAFETY: the CPU has AVX2 (checked above).
            let mask = unsafe { _mm256_movemask_ps(lane_mask(bits)) } as u32;
            assert_eq!(mask, bits);
        }
    }

    #[test]
    fn packets_need_directions_of_one_sign_per_axis() {
        if !is_x86_feature_detected!("avx2") {
            eprintln!("no AVX2: packets are never traced on this CPU");
            return;
        }
        let origin = [Vec3::ZERO; PACKET];
        let mut dirs = [Vec3::new(1.0, -2.0, 0.5); PACKET];
        // SAFETY: the CPU has AVX2 (checked above).
        let packet =
            |dirs: &[Vec3; PACKET]| unsafe { RayPacket::new(lanes_of(&origin), lanes_of(dirs)) };
        let rays = packet(&dirs).expect("one sign per axis");
        assert!(std::ptr::eq(rays.offsets, &OFFSETS[0b010]));
        for axis in 0..3 {
            let mut odd = dirs;
            odd[6][axis] = -odd[6][axis];
            assert!(packet(&odd).is_none(), "axis {axis}");
        }
        // A zero component counts by its sign, as 1/±0 = ±∞ does.
        dirs[2].x = 0.0;
        assert!(packet(&dirs).is_some());
        dirs[2].x = -0.0;
        assert!(packet(&dirs).is_none());
    }
}
