//! The wide BVH that rays traverse.
//!
//! obvhs builds a binary BVH (PLOC with reinsertion and SAH leaf
//! collapsing); [`WideBvh::build`] collapses it into nodes of up to eight
//! children whose boxes are stored structure-of-arrays, so that one node is
//! tested against a ray with SIMD: all eight lanes at once with AVX where
//! the CPU has AVX2 (detected at run time, [`Isa`]), else four at a time
//! (glam's `Vec4`: SSE on x86_64, a scalar fallback elsewhere). A leaf is a
//! range of items (packets of primitives) that the caller stores.
//!
//! Traversal intersects a node's leaves as soon as the node is visited and
//! keeps only inner nodes on its stack, so each step is one box test and no
//! branch has to guess whether the next entry is a leaf. With AVX2 the hit
//! children go onto the stack without branches (their number and order
//! are what a CPU predicts worst): closest-hit rays push them sorted by a
//! bitonic network over the eight lanes' distances, shadow rays packed in
//! lane order by a permutation table.
//!
//! A traversal is a loop of node visits ([`WideBvh::closest_step`],
//! [`WideBvh::any_step`]) over its state between two visits, a [`Walk`]:
//! one ray's query loops until its walk is over, and a batch query keeps
//! two walks and steps them in turn (`accel/interleave.rs`), so that while
//! one ray waits for its next node to arrive from memory the other's
//! visit runs. A shadow ray's visit can also be taken apart ([`Visit`]),
//! so that a walk through a top level can stop between the instances a
//! node's leaves lead to.
//!
//! Box tests follow Ize's "Robust BVH Ray Traversal" (2013): the far
//! distance is enlarged by the worst-case rounding error of the slab test,
//! so a box never misses a ray that touches it, flat boxes (axis-aligned
//! triangles) included.

#[cfg(target_arch = "x86_64")]
mod packet;

use super::huge::HugeArray;
use glam::{Vec3, Vec3A, Vec4};
use obvhs::aabb::Aabb;
use obvhs::bvh2::Bvh2;
use std::mem::MaybeUninit;
use std::ops::Range;

#[cfg(target_arch = "x86_64")]
pub use packet::{PACKET, PacketLeafVisitor, RayPacket, lane_mask, lanes_of};

/// Children per node.
const WIDTH: usize = 8;

/// SIMD groups of four lanes per node.
const GROUPS: usize = WIDTH / 4;

/// Node levels at most; a subtree deeper than this becomes one leaf (only
/// degenerate inputs get there), which bounds the traversal stack.
const MAX_DEPTH: usize = 48;

/// Traversal stack entries needed at most: a node pushes at most `WIDTH`
/// children and pops one.
const STACK_SIZE: usize = (WIDTH - 1) * MAX_DEPTH + 1;

/// `1 + 2γ₃`: enlarging a slab test's far distance by this factor covers
/// its rounding error.
const FAR_SCALE: f32 = 1.0 + 2.0 * (3.0 * f32::EPSILON * 0.5) / (1.0 - 3.0 * f32::EPSILON * 0.5);

/// A node: up to eight child boxes and what each child is.
#[derive(Debug, Clone, Copy)]
#[repr(C, align(64))]
struct Node {
    /// `bounds[0][axis]` holds the children's minimum coordinates along
    /// `axis`, four lanes per group; `bounds[1]` the maximum. Unused lanes
    /// hold an empty box (min +∞, max −∞), which no ray hits.
    bounds: [[[Vec4; GROUPS]; 3]; 2],
    /// Per child: a node index, or [`LEAF`] plus the first item of a leaf.
    /// (The leaf flags are these sign bits rather than a separate mask, so
    /// that a node is 256 bytes: four cache lines instead of five.)
    child: [u32; WIDTH],
    /// Per child: the number of items of a leaf (unused for nodes).
    count: [u32; WIDTH],
}

/// The bit of [`Node::child`] that marks a leaf.
const LEAF: u32 = 1 << 31;

const _: () = assert!(std::mem::size_of::<Node>() == 256);
// `RayBoxes` addresses the bounds by byte offsets from the node's start.
const _: () = assert!(std::mem::offset_of!(Node, bounds) == 0);

impl Node {
    const EMPTY: Node = Node {
        bounds: [
            [[Vec4::INFINITY; GROUPS]; 3],
            [[Vec4::NEG_INFINITY; GROUPS]; 3],
        ],
        child: [0; WIDTH],
        count: [0; WIDTH],
    };

    /// Makes `lane` the child with box `aabb`: node `child`, or a leaf of
    /// `count` items from `child` on.
    fn set_lane(&mut self, lane: usize, aabb: &Aabb, child: u32, leaf: Option<u32>) {
        for axis in 0..3 {
            self.bounds[0][axis][lane / 4][lane % 4] = aabb.min[axis];
            self.bounds[1][axis][lane / 4][lane % 4] = aabb.max[axis];
        }
        // Node indices and items count far below 2^31 in any scene that
        // fits in memory (a node or packet takes 160 bytes or more).
        assert!(child < LEAF, "more than 2^31 BVH nodes or leaf items");
        self.child[lane] = child;
        if let Some(count) = leaf {
            self.child[lane] |= LEAF;
            self.count[lane] = count;
        }
    }

    /// The box of `lane`, or `None` where the lane is unused (an empty box).
    fn lane_box(&self, lane: usize) -> Option<Aabb> {
        let corner = |side: usize| {
            let b = &self.bounds[side];
            Vec3A::new(
                b[0][lane / 4][lane % 4],
                b[1][lane / 4][lane % 4],
                b[2][lane / 4][lane % 4],
            )
        };
        let (min, max) = (corner(0), corner(1));
        min.cmple(max).all().then_some(Aabb { min, max })
    }

    /// Bit `lane` is set where the child is a leaf: the sign bits of
    /// `child`, read four lanes at a time (MOVMSKPS on x86_64).
    #[inline(always)]
    fn leaves(&self) -> u32 {
        let signs = |c: &[u32]| Vec4::from_array([c[0], c[1], c[2], c[3]].map(f32::from_bits));
        signs(&self.child[..4]).is_negative_bitmask()
            | signs(&self.child[4..]).is_negative_bitmask() << 4
    }

    /// Bit `lane` is set where the lane holds a child: its box is not
    /// empty (an unused lane's minimum is +∞ and its maximum −∞).
    #[cfg(target_arch = "x86_64")]
    #[inline(always)]
    fn used(&self) -> u32 {
        let [min, max] = [&self.bounds[0][0], &self.bounds[1][0]];
        min[0].cmple(max[0]).bitmask() | min[1].cmple(max[1]).bitmask() << 4
    }

    /// The item range of leaf `lane`.
    #[inline(always)]
    fn items(&self, lane: usize) -> Range<usize> {
        let first = (self.child[lane] & !LEAF) as usize;
        first..first + self.count[lane] as usize
    }
}

/// An inner node waiting on the traversal stack, with the distance at which
/// the ray enters its box.
#[derive(Debug, Clone, Copy)]
struct Entry {
    node: u32,
    t: f32,
}

/// A traversal between two node visits ([`WideBvh::closest_step`],
/// [`WideBvh::any_step`]): the node to visit next, the nodes waiting, and
/// how far hits count. A batch query keeps several walks and steps them in
/// turn, so that one ray's cache misses overlap the others' work.
pub struct Walk {
    stack: Stack,
    current: usize,
    /// Hits count within this distance: the closest so far, for a
    /// closest-hit walk.
    pub tmax: f32,
}

impl Walk {
    /// A walk from the root, for hits within `tmax`.
    #[inline(always)]
    pub fn new(tmax: f32) -> Self {
        Self {
            stack: Stack::new(),
            current: 0,
            tmax,
        }
    }

    /// Starts over from the root, for hits within `tmax`.
    #[inline(always)]
    pub fn restart(&mut self, tmax: f32) {
        self.stack.len = 0;
        self.current = 0;
        self.tmax = tmax;
    }
}

/// What an any-hit visit's box test found ([`WideBvh::visit`]): the
/// node, the leaves and the inner children the ray reaches, and the
/// distances at which it enters their boxes. The visit takes the leaves
/// in lane order ([`Visit::any_leaf`]), then goes on to the next node
/// ([`Visit::descend_any`]), and may be left between the two (a shadow
/// ray's batch through a top level enters a leaf's instances at later
/// steps).
pub struct Visit<'a> {
    node: &'a Node,
    leaves: u32,
    inner: u32,
    t_near: [f32; WIDTH],
}

impl Visit<'_> {
    /// The items of the next leaf in lane order not yet taken.
    #[inline(always)]
    pub fn any_leaf(&mut self) -> Option<Range<usize>> {
        if self.leaves == 0 {
            return None;
        }
        let lane = self.leaves.trailing_zeros() as usize;
        self.leaves &= self.leaves - 1;
        Some(self.node.items(lane))
    }

    /// Moves an any-hit `walk` on to the next pending node; `false` where
    /// none is left.
    #[inline(always)]
    pub fn descend_any<I: Isa>(&self, walk: &mut Walk) -> bool {
        walk.stack
            .push::<I>(self.node, self.inner, &self.t_near, false);
        match walk.stack.pop_node() {
            Some(node) => {
                walk.current = node as usize;
                true
            }
            None => false,
        }
    }
}

/// A fixed-capacity stack of entries that lives on the call stack and is
/// not initialised up front (a ray touches only its first few slots).
/// Structure-of-arrays, so that the AVX2 traversal writes a node's eight
/// children at once ([`Stack::push_avx`]); `WIDTH` slots of slack
/// above the deepest entry take those writes' unused lanes.
struct Stack {
    nodes: [MaybeUninit<u32>; STACK_SIZE + WIDTH],
    ts: [MaybeUninit<f32>; STACK_SIZE + WIDTH],
    len: usize,
}

/// The pushed `lanes` (a bit each) in order of decreasing distance `t`,
/// then the others: the distances, with the lane number in their three
/// lowest bits (distances are never negative, so their bits order as
/// integers; the last bits only break near-ties), go through an
/// eight-lane bitonic sorting network, lanes not pushed set to −1.
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2")]
#[inline]
fn sorted_order(lanes: u32, t: std::arch::x86_64::__m256) -> std::arch::x86_64::__m256i {
    use std::arch::x86_64::*;
    let bits = _mm256_setr_epi32(1, 2, 4, 8, 16, 32, 64, 128);
    let chosen = _mm256_and_si256(_mm256_set1_epi32(lanes as i32), bits);
    let skipped = _mm256_cmpeq_epi32(chosen, _mm256_setzero_si256());
    let ids = _mm256_setr_epi32(0, 1, 2, 3, 4, 5, 6, 7);
    let keys = _mm256_or_si256(
        _mm256_andnot_si256(_mm256_set1_epi32(7), _mm256_castps_si256(t)),
        ids,
    );
    let mut keys = _mm256_or_si256(keys, skipped);
    // Decreasing: sort pairs, merge into fours, then into eight (each
    // step: partner lanes, then the larger to the lower position).
    macro_rules! exchange {
        ($partner:expr, $low_takes_max:literal) => {{
            let partner = $partner;
            let (lo, hi) = (
                _mm256_min_epi32(keys, partner),
                _mm256_max_epi32(keys, partner),
            );
            keys = _mm256_blend_epi32::<$low_takes_max>(lo, hi);
        }};
    }
    exchange!(_mm256_shuffle_epi32::<0xB1>(keys), 0x55);
    exchange!(_mm256_shuffle_epi32::<0x1B>(keys), 0x33);
    exchange!(_mm256_shuffle_epi32::<0xB1>(keys), 0x55);
    let reverse = _mm256_setr_epi32(7, 6, 5, 4, 3, 2, 1, 0);
    exchange!(_mm256_permutevar8x32_epi32(keys, reverse), 0x0F);
    exchange!(_mm256_shuffle_epi32::<0x4E>(keys), 0x33);
    exchange!(_mm256_shuffle_epi32::<0xB1>(keys), 0x55);
    _mm256_and_si256(keys, _mm256_set1_epi32(7))
}

/// Per set of lanes (a bit each): those lanes' numbers in increasing
/// order, one per byte from the lowest, then zeros.
const PACK: [u64; 256] = {
    let mut table = [0u64; 256];
    let mut lanes = 0;
    while lanes < 256 {
        let (mut lane, mut at) = (0, 0);
        while lane < WIDTH {
            if lanes & (1 << lane) != 0 {
                table[lanes] |= (lane as u64) << (8 * at);
                at += 1;
            }
            lane += 1;
        }
        lanes += 1;
    }
    table
};

impl Stack {
    #[inline(always)]
    fn new() -> Self {
        Self {
            nodes: [const { MaybeUninit::uninit() }; STACK_SIZE + WIDTH],
            ts: [const { MaybeUninit::uninit() }; STACK_SIZE + WIDTH],
            len: 0,
        }
    }

    /// Pushes the children of `node` in `lanes` (a bit per lane), with
    /// their entry distances `t`; with `sorted`, so that the entries pushed
    /// are in order of decreasing distance (the nearest is popped first).
    /// Without `sorted` the distances may be left unwritten (shadow rays
    /// never read them): pop those entries with [`Self::pop_node`].
    #[inline(always)]
    fn push<I: Isa>(&mut self, node: &Node, lanes: u32, t: &[f32; WIDTH], sorted: bool) {
        #[cfg(target_arch = "x86_64")]
        if I::AVX2 {
            // SAFETY: `Avx2` traversals run only on CPUs with AVX2 (`Isa`).
            return unsafe { self.push_avx(node, lanes, t, sorted) };
        }
        self.push_lanes(node, lanes, t, sorted);
    }

    /// [`Self::push`] one lane at a time.
    #[inline(always)]
    fn push_lanes(&mut self, node: &Node, mut lanes: u32, t: &[f32; WIDTH], sorted: bool) {
        let base = self.len;
        while lanes != 0 {
            let lane = lanes.trailing_zeros() as usize;
            lanes &= lanes - 1;
            let e = Entry {
                node: node.child[lane],
                t: t[lane],
            };
            let mut i = self.len;
            // Panics rather than overflowing; `MAX_DEPTH` rules that out.
            self.write(i, e);
            self.len += 1;
            while sorted && i > base {
                let below = self.read(i - 1);
                if below.t >= e.t {
                    break;
                }
                self.write(i, below);
                self.write(i - 1, e);
                i -= 1;
            }
        }
    }

    /// [`Self::push`] without branches: the pushed lanes' children and
    /// distances are permuted to the front — sorted by distance
    /// ([`sorted_order`]) or in lane order, the last lane popped first
    /// ([`PACK`]) — and all eight lanes are written from the top of the
    /// stack, which grows by the number pushed.
    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx2")]
    #[inline]
    fn push_avx(&mut self, node: &Node, lanes: u32, t: &[f32; WIDTH], sorted: bool) {
        use std::arch::x86_64::*;
        // SAFETY: `t` and `node.child` hold eight 32-bit values each.
        let (t, child) = unsafe {
            (
                _mm256_loadu_ps(t.as_ptr()),
                _mm256_loadu_si256(node.child.as_ptr().cast()),
            )
        };
        let order = if sorted {
            sorted_order(lanes, t)
        } else {
            _mm256_cvtepu8_epi32(_mm_cvtsi64_si128(PACK[lanes as usize & 0xff] as i64))
        };
        let nodes = _mm256_permutevar8x32_epi32(child, order);
        // Panics rather than overflowing; `MAX_DEPTH` rules that out.
        let (nodes_at, ts_at) = (
            self.nodes[self.len..self.len + WIDTH].as_mut_ptr(),
            self.ts[self.len..self.len + WIDTH].as_mut_ptr(),
        );
        // SAFETY: both point at eight slots of the stack (checked above).
        unsafe {
            _mm256_storeu_si256(nodes_at.cast(), nodes);
            if sorted {
                _mm256_storeu_ps(ts_at.cast(), _mm256_permutevar8x32_ps(t, order));
            }
        }
        self.len += lanes.count_ones() as usize;
    }

    #[inline(always)]
    fn write(&mut self, i: usize, e: Entry) {
        self.nodes[i].write(e.node);
        self.ts[i].write(e.t);
    }

    /// Entry `i`, which must have been written.
    #[inline(always)]
    fn read(&self, i: usize) -> Entry {
        // SAFETY: callers read only slots below `len`, which have been
        // written.
        unsafe {
            Entry {
                node: self.nodes[i].assume_init(),
                t: self.ts[i].assume_init(),
            }
        }
    }

    #[inline(always)]
    fn pop(&mut self) -> Option<Entry> {
        self.len = self.len.checked_sub(1)?;
        Some(self.read(self.len))
    }

    /// The node of the top entry, popped, without its distance (which an
    /// unsorted push may have left unwritten).
    #[inline(always)]
    fn pop_node(&mut self) -> Option<u32> {
        self.len = self.len.checked_sub(1)?;
        // SAFETY: slots below `len` have had their node written.
        Some(unsafe { self.nodes[self.len].assume_init() })
    }
}

/// The instruction set a traversal is compiled for, as a type parameter,
/// so that one generic traversal serves every set.
///
/// Sealed: [`Avx2`] may only be used inside functions compiled with
/// `#[target_feature(enable = "avx2")]`, which in turn are only called once
/// the CPU was seen to support it ([`Avx2::detected`]).
pub trait Isa: sealed::Sealed {
    /// Whether the box test may use 256-bit AVX instructions.
    const AVX2: bool;
}

mod sealed {
    pub trait Sealed {}
    impl Sealed for super::Baseline {}
    impl Sealed for super::Avx2 {}
}

/// The target's baseline: SSE2 on x86_64, portable code elsewhere.
#[derive(Debug, Clone, Copy)]
pub struct Baseline;

impl Isa for Baseline {
    const AVX2: bool = false;
}

/// AVX2 (x86_64 CPUs since 2013): eight lanes per instruction.
#[derive(Debug, Clone, Copy)]
pub struct Avx2;

impl Isa for Avx2 {
    const AVX2: bool = true;
}

impl Avx2 {
    /// Whether this CPU supports AVX2.
    pub fn detected() -> bool {
        #[cfg(target_arch = "x86_64")]
        return std::arch::is_x86_feature_detected!("avx2");
        #[cfg(not(target_arch = "x86_64"))]
        return false;
    }
}

/// Per-ray constants of the box test.
#[derive(Debug, Clone, Copy)]
pub struct RayBoxes {
    origin: [f32; 3],
    inv_dir: [f32; 3],
    /// Per axis: the byte offset in a [`Node`] of the first four lanes of
    /// the bounds the ray meets first along that axis (the minima where the
    /// direction is positive), and of those it meets last. Offsets rather
    /// than side indices, so that a node test loads them without
    /// recomputing addresses.
    ///
    /// Both are read from their [`OFFSETS`] entry, which the ray refers
    /// to rather than copies (a ray entering a hierarchy then writes six
    /// fewer words).
    offsets: &'static Offsets,
}

/// [`RayBoxes`]' byte offsets: (near, far) per axis.
type Offsets = ([u32; 3], [u32; 3]);

/// [`RayBoxes::offsets`] by the signs of the direction's components (bit
/// `axis` set where it is negative): a table, so that each ray entering a
/// hierarchy refers to them rather than computes.
static OFFSETS: [Offsets; 8] = {
    let mut table = [([0; 3], [0; 3]); 8];
    let mut signs = 0;
    while signs < 8 {
        let mut axis = 0;
        while axis < 3 {
            let side = (signs >> axis) & 1;
            table[signs].0[axis] = (side * SIDE_BYTES + axis * AXIS_BYTES) as u32;
            table[signs].1[axis] = ((side ^ 1) * SIDE_BYTES + axis * AXIS_BYTES) as u32;
            axis += 1;
        }
        signs += 1;
    }
    table
};

/// Bytes between `Node::bounds[0]` and `Node::bounds[1]`, and between
/// consecutive axes.
const SIDE_BYTES: usize = 3 * AXIS_BYTES;
const AXIS_BYTES: usize = GROUPS * std::mem::size_of::<Vec4>();

impl RayBoxes {
    /// Prepares the ray `origin + t·dir` (both finite).
    #[inline]
    pub fn new(origin: Vec3, dir: Vec3) -> Self {
        // A zero component gives an infinite inverse: the slab test then
        // yields ±∞, or 0·∞ = NaN for a face through the origin, which
        // `max_of`/`min_of` drop (the ray lies in the face: no constraint).
        Self::from_inverse(origin, Vec3A::ONE / Vec3A::from(dir))
    }

    /// [`RayBoxes::new`] from the direction's inverse `inv_dir` (`1/dir`
    /// per component), where the caller has it already.
    #[inline(always)]
    pub fn from_inverse(origin: Vec3, inv_dir: Vec3A) -> Self {
        let offsets = &OFFSETS[inv_dir.cmplt(Vec3A::ZERO).bitmask() as usize & 7];
        Self {
            origin: origin.to_array(),
            inv_dir: inv_dir.to_array(),
            offsets,
        }
    }

    /// Four lanes of `node`'s bounds at byte `offset` (one of
    /// [`RayBoxes::offsets`]) plus group `g`.
    #[inline(always)]
    fn lanes(node: &Node, offset: u32, g: usize) -> Vec4 {
        // SAFETY: `offset` is side · SIDE_BYTES + axis · AXIS_BYTES with
        // side < 2 and axis < 3, so with g < GROUPS it addresses a whole
        // `Vec4` of `node.bounds`.
        unsafe {
            let bytes = (node as *const Node).cast::<u8>();
            bytes
                .add(offset as usize + g * std::mem::size_of::<Vec4>())
                .cast::<Vec4>()
                .read()
        }
    }

    /// Which children of `node` the ray meets for t in (0, `tmax`): a bit
    /// mask, and the distances at which it enters their boxes.
    #[inline(always)]
    fn test<I: Isa>(&self, node: &Node, tmax: f32) -> (u32, [f32; WIDTH]) {
        #[cfg(target_arch = "x86_64")]
        if I::AVX2 {
            // SAFETY: `Avx2` traversals run only on CPUs with AVX2 (`Isa`).
            return unsafe { self.test_avx(node, tmax) };
        }
        self.test_sse(node, tmax)
    }

    /// [`Self::test`] with 256-bit AVX: the same operations, in the same
    /// order, on all eight lanes at once (so the same results).
    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx2")]
    #[inline]
    fn test_avx(&self, node: &Node, tmax: f32) -> (u32, [f32; WIDTH]) {
        use std::arch::x86_64::*;
        let mut t_near = _mm256_setzero_ps();
        let mut t_far = _mm256_set1_ps(tmax);
        let bytes = (node as *const Node).cast::<u8>();
        for axis in 0..3 {
            let origin = _mm256_set1_ps(self.origin[axis]);
            let inv_dir = _mm256_set1_ps(self.inv_dir[axis]);
            // SAFETY: both offsets address a group pair of `node.bounds`
            // (`RayBoxes::lanes`): eight contiguous f32 in a 64-byte
            // aligned node, at a multiple of 32 bytes (an aligned load).
            let bounds = |offset: u32| unsafe { _mm256_load_ps(bytes.add(offset as usize).cast()) };
            let lo = _mm256_mul_ps(_mm256_sub_ps(bounds(self.offsets.0[axis]), origin), inv_dir);
            let hi = _mm256_mul_ps(_mm256_sub_ps(bounds(self.offsets.1[axis]), origin), inv_dir);
            // MAXPS/MINPS keep the second operand where the first is NaN,
            // as `max_of` and `min_of` do.
            t_near = _mm256_max_ps(lo, t_near);
            t_far = _mm256_min_ps(hi, t_far);
        }
        let far = _mm256_mul_ps(t_far, _mm256_set1_ps(FAR_SCALE));
        let mask = _mm256_movemask_ps(_mm256_cmp_ps::<_CMP_LE_OQ>(t_near, far)) as u32;
        let mut t = [0.0; WIDTH];
        // SAFETY: `t` holds eight f32.
        unsafe { _mm256_storeu_ps(t.as_mut_ptr(), t_near) };
        (mask, t)
    }

    /// [`Self::test`] four lanes at a time.
    #[inline(always)]
    fn test_sse(&self, node: &Node, tmax: f32) -> (u32, [f32; WIDTH]) {
        let mut mask = 0;
        let mut t = [0.0; WIDTH];
        for g in 0..GROUPS {
            let mut t_near = Vec4::ZERO;
            let mut t_far = Vec4::splat(tmax);
            for axis in 0..3 {
                let (origin, inv_dir) = (
                    Vec4::splat(self.origin[axis]),
                    Vec4::splat(self.inv_dir[axis]),
                );
                let lo = (Self::lanes(node, self.offsets.0[axis], g) - origin) * inv_dir;
                let hi = (Self::lanes(node, self.offsets.1[axis], g) - origin) * inv_dir;
                t_near = max_of(lo, t_near);
                t_far = min_of(hi, t_far);
            }
            mask |= t_near.cmple(t_far * FAR_SCALE).bitmask() << (4 * g);
            t_near.write_to_slice(&mut t[4 * g..4 * g + 4]);
        }
        (mask, t)
    }
}

/// The larger of `new` and `acc` per lane; `acc` where `new` is NaN.
#[inline(always)]
fn max_of(new: Vec4, acc: Vec4) -> Vec4 {
    // glam's SSE2 and scalar `max` are `new > acc ? new : acc` (MAXPS).
    #[cfg(any(target_arch = "x86", target_arch = "x86_64"))]
    return new.max(acc);
    #[cfg(not(any(target_arch = "x86", target_arch = "x86_64")))]
    return Vec4::select(new.cmpgt(acc), new, acc);
}

/// The smaller of `new` and `acc` per lane; `acc` where `new` is NaN.
#[inline(always)]
fn min_of(new: Vec4, acc: Vec4) -> Vec4 {
    #[cfg(any(target_arch = "x86", target_arch = "x86_64"))]
    return new.min(acc);
    #[cfg(not(any(target_arch = "x86", target_arch = "x86_64")))]
    return Vec4::select(new.cmplt(acc), new, acc);
}

/// What traversal does at a leaf: intersects the leaf's items (a range
/// of the caller's storage) with the ray. Implementations mark their
/// methods `#[inline(always)]`, so that they compile into the traversal
/// with its instruction set (a closure might stay a call).
pub trait LeafVisitor {
    /// Intersects items `range` for the closest hit within `tmax`; returns
    /// the new `tmax` (the closest hit so far).
    fn closest(&mut self, range: Range<usize>, tmax: f32) -> f32;

    /// Whether any item of `range` is hit within `tmax`.
    fn any(&mut self, range: Range<usize>, tmax: f32) -> bool;
}

/// A wide BVH; its leaves are ranges of items stored elsewhere.
#[derive(Debug, Clone, Default)]
pub struct WideBvh {
    nodes: HugeArray<Node>,
    /// Per node and lane: the binary node the lane was collapsed from
    /// ([`NO_SOURCE`] for an unused lane), so that a refitted binary BVH
    /// can hand its boxes to the wide one ([`WideBvh::refit`]).
    sources: Vec<[u32; WIDTH]>,
}

/// An unused lane in [`WideBvh::sources`].
const NO_SOURCE: u32 = u32::MAX;

/// The cost model of a collapse: what testing a leaf of `count` primitives
/// costs relative to testing one node, and how many primitives a leaf may
/// hold.
#[derive(Debug, Clone, Copy)]
pub struct LeafCost {
    /// Cost of a leaf by its primitive count.
    pub cost: fn(u32) -> f32,
    /// Primitives per leaf at most.
    pub max_prims: u32,
    /// The share of the binary tree's nodes that a
    /// [`BuildQuality::High`](crate::settings::BuildQuality::High) build
    /// takes out and re-inserts where they cost least (obvhs'
    /// `reinsertion_batch_ratio`; 1 re-inserts each node once); `None`
    /// keeps the share of obvhs' own high-quality build.
    pub reinsertion: Option<f32>,
}

impl LeafCost {
    /// Triangles and spheres in packets of four: a packet costs a node.
    pub const PACKETS: LeafCost = LeafCost {
        cost: |count| count.div_ceil(4) as f32,
        max_prims: 8,
        reinsertion: None,
    };

    /// Instances: each is a whole traversal of its own hierarchy, worth
    /// several nodes; one per leaf. Every box the build saves a ray is
    /// worth that much, and a top level has few boxes, so its build
    /// re-inserts all of its nodes (a field of 10,000 bunnies: 5 % fewer
    /// instructions per ray; `engine/benches/ANIMATION.md`, "Stop 24").
    pub const INSTANCES: LeafCost = LeafCost {
        cost: |count| 4.0 * count as f32,
        max_prims: 1,
        reinsertion: Some(1.0),
    };
}

impl WideBvh {
    /// Collapses `bvh2` into a wide BVH with the least SAH cost. `leaf`
    /// receives the primitives (as indices into `bvh2`'s input) of each
    /// leaf, stores them, and returns the range of items that traversal
    /// hands back for that leaf.
    pub fn build(bvh2: &Bvh2, cost: LeafCost, mut leaf: impl FnMut(&[u32]) -> Range<u32>) -> Self {
        if bvh2.nodes.is_empty() {
            return Self::default();
        }
        let plan = Collapse::new(bvh2, cost);
        let mut nodes = vec![Node::EMPTY];
        let mut sources = vec![[NO_SOURCE; WIDTH]];
        let mut prims = Vec::new();
        let mut make_leaf = |node: &mut Node, source: &mut u32, lane: usize, binary: usize| {
            prims.clear();
            push_primitives(bvh2, binary, &mut prims);
            let range = leaf(&prims);
            if !range.is_empty() {
                let aabb = bvh2.nodes[binary].aabb();
                node.set_lane(lane, aabb, range.start, Some(range.len() as u32));
                *source = binary as u32;
            }
        };
        if bvh2.nodes[0].is_leaf() {
            // A single leaf: one lane of the root holds it.
            make_leaf(&mut nodes[0], &mut sources[0][0], 0, 0);
            return Self {
                nodes: nodes.into(),
                sources,
            };
        }
        // (binary node, wide node it becomes, depth of that wide node)
        let mut work = vec![(0, 0, 1)];
        let mut children = Vec::with_capacity(WIDTH);
        while let Some((binary, wide, depth)) = work.pop() {
            children.clear();
            plan.children(binary, &mut children);
            for (lane, &(c, is_leaf)) in children.iter().enumerate() {
                if is_leaf || depth >= MAX_DEPTH {
                    make_leaf(&mut nodes[wide], &mut sources[wide][lane], lane, c);
                } else {
                    let index = nodes.len();
                    nodes.push(Node::EMPTY);
                    sources.push([NO_SOURCE; WIDTH]);
                    nodes[wide].set_lane(lane, bvh2.nodes[c].aabb(), index as u32, None);
                    sources[wide][lane] = c as u32;
                    work.push((c, index, depth + 1));
                }
            }
        }
        Self {
            nodes: nodes.into(),
            sources,
        }
    }

    /// Takes the boxes of `bvh2` — the binary BVH this one was collapsed
    /// from, refitted since — for every lane (the tree's shape and leaves
    /// stay as they are).
    pub fn refit(&mut self, bvh2: &Bvh2) {
        for (node, sources) in self.nodes.iter_mut().zip(&self.sources) {
            for (lane, &source) in sources.iter().enumerate() {
                if source != NO_SOURCE {
                    let aabb = bvh2.nodes[source as usize].aabb();
                    let (child, count) = (node.child[lane], node.count[lane]);
                    node.set_lane(
                        lane,
                        aabb,
                        child & !LEAF,
                        (child & LEAF != 0).then_some(count),
                    );
                }
            }
        }
    }

    /// The expected cost of a random ray's traversal under the surface
    /// area heuristic, in units of a node test: Σ over nodes of their area
    /// plus Σ over leaves of their area × `cost`, over the area of the
    /// whole tree. Refitting a tree to moved primitives makes it grow;
    /// comparing it with the cost at the last build says when to rebuild.
    pub fn sah_cost(&self, cost: LeafCost) -> f32 {
        let Some(root) = self.bounds() else {
            return 0.0;
        };
        let root_area = root.half_area();
        if root_area.partial_cmp(&0.0) != Some(std::cmp::Ordering::Greater) {
            return 0.0;
        }
        let mut total = root_area * NODE_COST;
        for node in self.nodes.iter() {
            for lane in 0..WIDTH {
                let Some(aabb) = node.lane_box(lane) else {
                    continue;
                };
                let weight = if node.child[lane] & LEAF != 0 {
                    (cost.cost)(node.count[lane])
                } else {
                    NODE_COST
                };
                total += aabb.half_area() * weight;
            }
        }
        total / root_area
    }

    /// The boxes of the root's children, and of their children where a
    /// child is a node: together they hold everything, in at most
    /// `WIDTH`² boxes.
    pub fn cover(&self) -> Vec<Aabb> {
        let Some(root) = self.nodes.first() else {
            return Vec::new();
        };
        let mut out = Vec::with_capacity(WIDTH * WIDTH);
        for lane in 0..WIDTH {
            let Some(aabb) = root.lane_box(lane) else {
                continue;
            };
            if root.child[lane] & LEAF != 0 {
                out.push(aabb);
            } else {
                let child = &self.nodes[root.child[lane] as usize];
                out.extend((0..WIDTH).filter_map(|l| child.lane_box(l)));
            }
        }
        out
    }

    /// The box around everything, or `None` for an empty hierarchy.
    pub fn bounds(&self) -> Option<Aabb> {
        let root = self.nodes.first()?;
        let mut lanes = (0..WIDTH).filter_map(|lane| root.lane_box(lane));
        let first = lanes.next()?;
        Some(lanes.fold(first, |a, b| a.union(&b)))
    }

    /// Every used lane, for tests: (node index, box, the item range of a
    /// leaf or `None`, the child node index of a node).
    #[cfg(test)]
    pub fn lanes(&self) -> Vec<(usize, Aabb, Option<Range<usize>>, usize)> {
        let mut out = Vec::new();
        for (index, node) in self.nodes.iter().enumerate() {
            for lane in 0..WIDTH {
                if let Some(aabb) = node.lane_box(lane) {
                    if node.child[lane] & LEAF != 0 {
                        out.push((index, aabb, Some(node.items(lane)), 0));
                    } else {
                        out.push((index, aabb, None, node.child[lane] as usize));
                    }
                }
            }
        }
        out
    }

    /// Whether the BVH holds no primitives.
    #[inline]
    pub fn is_empty(&self) -> bool {
        self.nodes.is_empty()
    }

    /// Node `index`, which must be 0 (the root of a non-empty tree) or a
    /// node's child: unchecked, since [`WideBvh::build`] writes only the
    /// indices of nodes it created into `child` (and refits keep them),
    /// and a bounds check would hold a register through the traversal.
    #[inline(always)]
    fn node(&self, index: usize) -> &Node {
        debug_assert!(index < self.nodes.len());
        // SAFETY: see above; traversals start at the root only where
        // `nodes` is not empty.
        unsafe { self.nodes.get_unchecked(index) }
    }

    /// Visits the leaves that `ray` may hit in (0, `tmax`), inner nodes
    /// nearest first, with [`LeafVisitor::closest`]; boxes beyond the
    /// closest hit so far are skipped.
    #[inline(always)]
    pub fn closest<I: Isa>(&self, ray: &RayBoxes, tmax: f32, leaf: &mut impl LeafVisitor) {
        if self.nodes.is_empty() {
            return;
        }
        let mut walk = Walk::new(tmax);
        while self.closest_step::<I>(ray, &mut walk, leaf) {}
    }

    /// One node visit of [`Self::closest`] for the walk `walk`, whose
    /// `tmax` it lowers to each hit; `false` once the traversal is over.
    /// The hierarchy must not be empty.
    #[inline(always)]
    pub fn closest_step<I: Isa>(
        &self,
        ray: &RayBoxes,
        walk: &mut Walk,
        leaf: &mut impl LeafVisitor,
    ) -> bool {
        let node = self.node(walk.current);
        let mut tmax = walk.tmax;
        let (mask, t_near) = ray.test::<I>(node, tmax);
        // Leaves nearest first, until the next one starts beyond the hit.
        let leaf_lanes = node.leaves();
        let mut leaves = mask & leaf_lanes;
        while leaves != 0 {
            let mut lane = leaves.trailing_zeros() as usize;
            let mut rest = leaves & (leaves - 1);
            while rest != 0 {
                let other = rest.trailing_zeros() as usize;
                rest &= rest - 1;
                if t_near[other] < t_near[lane] {
                    lane = other;
                }
            }
            if t_near[lane] > tmax * FAR_SCALE {
                break;
            }
            leaves &= !(1 << lane);
            tmax = leaf.closest(node.items(lane), tmax);
        }
        walk.tmax = tmax;
        let inner = mask & !leaf_lanes;
        if inner != 0 && inner & (inner - 1) == 0 {
            // One child: straight down, without the stack's round trip.
            let lane = inner.trailing_zeros() as usize;
            if t_near[lane] <= tmax * FAR_SCALE {
                walk.current = node.child[lane] as usize;
                return true;
            }
        } else if inner != 0 {
            walk.stack.push::<I>(node, inner, &t_near, true);
        }
        // Next: the nearest pending node that is not beyond the hit.
        loop {
            let Some(e) = walk.stack.pop() else {
                return false;
            };
            if e.t <= tmax * FAR_SCALE {
                walk.current = e.node as usize;
                return true;
            }
        }
    }

    /// The box test of the node `walk` is at: what an any-hit visit goes
    /// on with. The hierarchy must not be empty.
    #[inline(always)]
    pub fn visit<I: Isa>(&self, ray: &RayBoxes, walk: &Walk) -> Visit<'_> {
        let node = self.node(walk.current);
        let (mask, t_near) = ray.test::<I>(node, walk.tmax);
        let leaf_lanes = node.leaves();
        Visit {
            node,
            leaves: mask & leaf_lanes,
            inner: mask & !leaf_lanes,
            t_near,
        }
    }

    /// Visits the leaves that `ray` may hit in (0, `tmax`) until
    /// [`LeafVisitor::any`] reports a hit; returns whether one did.
    #[inline(always)]
    pub fn any<I: Isa>(&self, ray: &RayBoxes, tmax: f32, leaf: &mut impl LeafVisitor) -> bool {
        if self.nodes.is_empty() {
            return false;
        }
        let mut walk = Walk::new(tmax);
        loop {
            if let Some(hit) = self.any_step::<I>(ray, &mut walk, leaf) {
                return hit;
            }
        }
    }

    /// One node visit of [`Self::any`] for the walk `walk` (whose `tmax`
    /// stays fixed): `Some` once the traversal is over, with whether
    /// something was hit; `None` while it goes on. The hierarchy must not
    /// be empty.
    #[inline(always)]
    pub fn any_step<I: Isa>(
        &self,
        ray: &RayBoxes,
        walk: &mut Walk,
        leaf: &mut impl LeafVisitor,
    ) -> Option<bool> {
        let mut visit = self.visit::<I>(ray, walk);
        while let Some(items) = visit.any_leaf() {
            if leaf.any(items, walk.tmax) {
                return Some(true);
            }
        }
        if visit.descend_any::<I>(walk) {
            None
        } else {
            Some(false)
        }
    }
}

/// SAH cost of visiting a node (testing the ray against its boxes),
/// relative to testing a packet of four triangles.
const NODE_COST: f32 = 1.0;

/// The cheapest way to collapse a binary BVH into `WIDTH`-wide nodes, by
/// dynamic programming over its subtrees (Ylitie et al., "Efficient
/// Incoherent Ray Traversal on GPUs Through Compressed Wide BVHs", 2017,
/// with the cost model of this traversal).
struct Collapse<'a> {
    bvh2: &'a Bvh2,
    /// Per binary node and `i` in 0..WIDTH: how it is best represented by
    /// at most `i + 1` children of a wide node: 0 as one child, `k` as the
    /// best `k` children from its first child and the rest from its second.
    split: Vec<[u8; WIDTH]>,
    /// Per binary node: whether, as one child, it is a leaf (else a node).
    as_leaf: Vec<bool>,
    /// Per inner binary node: as a wide node, how many of its children
    /// come from its first child (the rest from the second).
    node_split: Vec<u8>,
}

impl<'a> Collapse<'a> {
    fn new(bvh2: &'a Bvh2, leaf_cost: LeafCost) -> Self {
        let n = bvh2.nodes.len();
        // Children before parents: the reverse of a preorder.
        let mut order = Vec::with_capacity(n);
        let mut pending = vec![0];
        while let Some(i) = pending.pop() {
            order.push(i);
            let node = &bvh2.nodes[i];
            if !node.is_leaf() {
                let first = node.first_index as usize;
                pending.extend([first, first + 1]);
            }
        }
        let mut cost = vec![[0.0f32; WIDTH]; n];
        let mut split = vec![[0u8; WIDTH]; n];
        let mut as_leaf = vec![true; n];
        let mut node_split = vec![1u8; n];
        let mut prims = vec![0u32; n];
        for &i in order.iter().rev() {
            let node = &bvh2.nodes[i];
            let area = node.aabb().half_area();
            let packets = leaf_cost.cost;
            if node.is_leaf() {
                prims[i] = node.prim_count;
                cost[i] = [area * packets(node.prim_count); WIDTH];
                continue;
            }
            let (l, r) = (node.first_index as usize, node.first_index as usize + 1);
            prims[i] = prims[l] + prims[r];
            // Best split of `slots` children between the two subtrees.
            let (left, right) = (cost[l], cost[r]);
            let best_split = |slots: usize| {
                (1..slots)
                    .map(|k| (left[k - 1] + right[slots - k - 1], k as u8))
                    .min_by(|a, b| a.0.total_cmp(&b.0))
                    .unwrap_or((f32::INFINITY, 0))
            };
            let (children_cost, k) = best_split(WIDTH);
            node_split[i] = k;
            let as_node = area * NODE_COST + children_cost;
            let as_one_leaf = if prims[i] <= leaf_cost.max_prims {
                area * packets(prims[i])
            } else {
                f32::INFINITY
            };
            as_leaf[i] = as_one_leaf <= as_node;
            cost[i][0] = as_one_leaf.min(as_node);
            for slots in 2..=WIDTH {
                let (c, k) = best_split(slots);
                if c < cost[i][slots - 2] {
                    cost[i][slots - 1] = c;
                    split[i][slots - 1] = k;
                } else {
                    cost[i][slots - 1] = cost[i][slots - 2];
                    split[i][slots - 1] = split[i][slots - 2];
                }
            }
        }
        Self {
            bvh2,
            split,
            as_leaf,
            node_split,
        }
    }

    /// The children of the wide node that binary node `index` (an inner
    /// node) becomes, as (binary node, whether it is a leaf).
    fn children(&self, index: usize, out: &mut Vec<(usize, bool)>) {
        let first = self.bvh2.nodes[index].first_index as usize;
        let k = usize::from(self.node_split[index]);
        self.emit(first, k, out);
        self.emit(first + 1, WIDTH - k, out);
    }

    /// Appends the best representation of binary node `index` by at most
    /// `slots` children.
    fn emit(&self, index: usize, slots: usize, out: &mut Vec<(usize, bool)>) {
        let k = usize::from(self.split[index][slots - 1]);
        if k == 0 {
            out.push((index, self.as_leaf[index]));
        } else {
            let first = self.bvh2.nodes[index].first_index as usize;
            self.emit(first, k, out);
            self.emit(first + 1, slots - k, out);
        }
    }
}

/// Appends the primitives under binary node `index` to `prims`.
fn push_primitives(bvh2: &Bvh2, index: usize, prims: &mut Vec<u32>) {
    // More than one node only past `MAX_DEPTH`, where a whole subtree
    // becomes one leaf.
    let mut pending = vec![index];
    while let Some(i) = pending.pop() {
        let node = &bvh2.nodes[i];
        let first = node.first_index as usize;
        if node.is_leaf() {
            let range = first..first + node.prim_count as usize;
            prims.extend_from_slice(&bvh2.primitive_indices[range]);
        } else {
            pending.extend([first + 1, first]);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::accel::tests::lcg;

    /// Pushes random lanes of a node with random distances (ties and
    /// zeros included) on a stack that already holds an entry, and checks
    /// what pops: exactly the pushed children, nearest first where sorted,
    /// last lane first otherwise, then the older entry.
    fn check_pushes<I: Isa>() {
        let mut node = Node::EMPTY;
        for (lane, child) in node.child.iter_mut().enumerate() {
            *child = 100 + lane as u32;
        }
        let mut s = 3;
        for round in 0..20_000 {
            let lanes = (lcg(&mut s) * 256.0) as u32;
            let t: [f32; WIDTH] = std::array::from_fn(|_| match (lcg(&mut s) * 4.0) as u32 {
                0 => 0.0,
                1 => 0.5,
                _ => lcg(&mut s) * 10.0,
            });
            let sorted = round % 2 == 0;
            let mut stack = Stack::new();
            stack.write(0, Entry { node: 7, t: -1.0 });
            stack.len = 1;
            stack.push::<I>(&node, lanes, &t, sorted);
            // Unsorted pushes need not write the distances: their entries
            // pop as nodes only (NaN distances here, not checked).
            let mut popped = Vec::new();
            while let Some(e) = if sorted {
                stack.pop()
            } else {
                stack.pop_node().map(|node| Entry { node, t: f32::NAN })
            } {
                popped.push(e);
            }
            let old = popped.pop().expect("the older entry");
            assert_eq!(old.node, 7);
            let got: Vec<usize> = popped.iter().map(|e| (e.node - 100) as usize).collect();
            for (e, &lane) in popped.iter().zip(&got).filter(|_| sorted) {
                assert_eq!(e.t.to_bits(), t[lane].to_bits());
            }
            let mut want: Vec<usize> = (0..WIDTH).filter(|l| lanes & (1 << l) != 0).collect();
            if sorted {
                // In order of distance, up to the last three bits (the
                // AVX2 sort keys hold the lane there).
                let key = |e: &Entry| e.t.to_bits() & !7;
                assert!(
                    popped.windows(2).all(|w| key(&w[0]) <= key(&w[1])),
                    "{popped:?}"
                );
                let mut got = got.clone();
                got.sort_unstable();
                assert_eq!(got, want, "lanes {lanes:08b}");
            } else {
                want.reverse();
                assert_eq!(got, want, "lanes {lanes:08b}");
            }
        }
    }

    #[test]
    fn stacks_pop_exactly_the_pushed_children_in_order() {
        check_pushes::<Baseline>();
        #[cfg(target_arch = "x86_64")]
        if Avx2::detected() {
            // SAFETY: the CPU supports AVX2.
            unsafe { check_pushes_avx2() };
        }
    }

    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx2")]
    fn check_pushes_avx2() {
        check_pushes::<Avx2>();
    }
}
