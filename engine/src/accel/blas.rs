//! The bottom level: one hierarchy over the primitives of a shape (or of
//! all static shapes together), in that hierarchy's own space.
//!
//! Primitives are stored in leaf order, triangles and spheres as packets
//! of four ([`Tri4`], [`Sphere4`]) tested together with SIMD. A deforming mesh is refitted as
//! its vertices move ([`Blas::update`]); under motion blur it keeps its
//! triangles at shutter open and close and intersects them where they are
//! at each ray's time. The renderer's batches of rays go through the
//! level two rays at a time, their traversals interleaved
//! ([`interleave`]).

use super::hierarchy::{Hierarchy, Update, UpdatePolicy};
use super::huge::HugeArray;
use super::sphere::Sphere4;
#[cfg(target_arch = "x86_64")]
use super::triangle::PacketPrep;
use super::triangle::{RayPrep, Tri4};
use super::wide::{Isa, LeafCost, LeafVisitor, RayBoxes};
#[cfg(target_arch = "x86_64")]
use super::wide::{PACKET, PacketLeafVisitor, RayPacket, lane_mask, lanes_of};
use super::{Hit, Primitive, ray_is_valid};
use crate::settings::BuildQuality;
use glam::{Vec3, Vec3A};
use obvhs::aabb::Aabb;
use rayon::prelude::*;
#[cfg(target_arch = "x86_64")]
use std::arch::x86_64::*;
use std::borrow::Cow;
use std::ops::Range;

/// What a leaf holds: triangles or spheres, four at a time.
#[derive(Debug, Clone, Copy)]
enum Packet {
    /// Up to four triangles: `count` primitives from `first` on.
    Triangles { tris: Tri4, first: u32, count: u32 },
    /// Up to four spheres: `count` primitives from `first` on.
    Spheres {
        spheres: Sphere4,
        first: u32,
        count: u32,
    },
}

impl Packet {
    /// The primitives (leaf-order indices) the packet holds.
    fn members(&self) -> Range<u32> {
        let (Packet::Triangles { first, count, .. } | Packet::Spheres { first, count, .. }) = *self;
        first..first + count
    }
}

/// The primitives at shutter close, for geometry that deforms while the
/// shutter is open.
#[derive(Clone)]
struct Closing {
    packets: HugeArray<Packet>,
    prims: HugeArray<Primitive>,
}

/// A bottom-level hierarchy and its primitives in leaf order.
#[derive(Clone, Default)]
pub struct Blas {
    hierarchy: Hierarchy,
    packets: HugeArray<Packet>,
    prims: HugeArray<Primitive>,
    closing: Option<Closing>,
    /// Per leaf-order index, the index of the primitive in the input.
    order: Vec<u32>,
    /// See [`Blas::version`].
    version: u64,
    /// Whether any packet holds spheres: queries of a level without them
    /// are compiled without the sphere test, which frees the registers
    /// that hold the ray for it.
    spheres: bool,
}

/// The next [`Blas::version`].
static NEXT_VERSION: std::sync::atomic::AtomicU64 = std::sync::atomic::AtomicU64::new(1);

fn next_version() -> u64 {
    NEXT_VERSION.fetch_add(1, std::sync::atomic::Ordering::Relaxed)
}

/// A ray as a bottom level's queries take it: origin, direction, shutter
/// time and its per-ray constants.
struct Ray {
    origin: Vec3,
    dir: Vec3,
    tau: f32,
    prep: RayPrep,
    boxes: RayBoxes,
}

impl Ray {
    #[inline(always)]
    fn new<I: Isa>(origin: Vec3, dir: Vec3, tau: f32) -> Self {
        Self {
            origin,
            dir,
            tau,
            prep: RayPrep::new_with::<I>(origin, dir),
            boxes: RayBoxes::new(origin, dir),
        }
    }
}

mod interleave;
pub(super) use interleave::Lane;

impl Blas {
    /// Builds the hierarchy over `prims` (and, for geometry that deforms
    /// while the shutter is open, their shapes at shutter close, `close`,
    /// of the same length: a box then contains both).
    ///
    /// # Panics
    ///
    /// If `close` is not as long as `prims`.
    pub fn build(prims: &[Primitive], close: Option<&[Primitive]>, quality: BuildQuality) -> Self {
        let mut blas = Self::default();
        blas.rebuild(prims, close, quality);
        blas
    }

    fn rebuild(&mut self, prims: &[Primitive], close: Option<&[Primitive]>, quality: BuildQuality) {
        let boxes = boxes(prims, close);
        let (mut order, mut packets) = (Vec::with_capacity(prims.len()), packet_room(prims));
        let hierarchy = Hierarchy::build(&boxes, quality, LeafCost::PACKETS, |leaf| {
            store_leaf(leaf, prims, &mut order, &mut packets)
        });
        debug_assert_eq!(order.len(), prims.len());
        self.hierarchy = hierarchy;
        self.prims = HugeArray::from_fn(order.len(), |k| prims[order[k] as usize]);
        self.closing = close.map(|close| closing(close, &order, &packets));
        self.packets = packets;
        self.order = order;
        self.spheres = has_spheres(&self.packets);
        self.version = next_version();
    }

    /// Follows primitives that moved: `prims` (and `close`, as in
    /// [`Blas::build`]) are the new shapes of the primitives given to the
    /// last build, in the same input order. Refits, or rebuilds where the
    /// refitted tree has degraded past `policy` — then [`Blas::order`]
    /// changes, and so must the shading data laid out by it.
    ///
    /// # Panics
    ///
    /// If the primitive count changed.
    pub fn update(
        &mut self,
        prims: &[Primitive],
        close: Option<&[Primitive]>,
        policy: UpdatePolicy,
    ) -> Update {
        assert_eq!(prims.len(), self.order.len(), "the primitive count changed");
        let start = std::time::Instant::now();
        let boxes = boxes(prims, close);
        let (mut order, mut packets) = (Vec::new(), packet_room(prims));
        let update = self.hierarchy.update(&boxes, policy, |leaf| {
            store_leaf(leaf, prims, &mut order, &mut packets)
        });
        if update.rebuilt {
            self.order = order;
            self.packets = packets;
            self.spheres = has_spheres(&self.packets);
        } else {
            // Same leaves, same order: repack the moved triangles.
            repack(&mut self.packets, prims, &self.order);
        }
        // The same number of primitives (asserted above): in place.
        self.prims
            .par_iter_mut()
            .zip(&self.order)
            .with_min_len(4096)
            .for_each(|(p, &i)| *p = prims[i as usize]);
        self.closing = close.map(|close| closing(close, &self.order, &self.packets));
        self.version = next_version();
        Update {
            time: start.elapsed(),
            ..update
        }
    }

    /// A number that changes whenever the primitives or the hierarchy do
    /// (a build, a refit, a rebuild), unique among the bottom levels of the
    /// process: what a copy of the level elsewhere (the GPU's) is keyed by.
    pub fn version(&self) -> u64 {
        self.version
    }

    /// Per leaf-order index, the index of the primitive in the input of the
    /// last build.
    pub fn order(&self) -> &[u32] {
        &self.order
    }

    /// The primitives in leaf order (at shutter open).
    pub fn primitives(&self) -> &[Primitive] {
        &self.prims
    }

    /// Number of primitives.
    pub fn len(&self) -> usize {
        self.prims.len()
    }

    /// Whether there are no primitives.
    pub fn is_empty(&self) -> bool {
        self.prims.is_empty()
    }

    /// Whether the primitives move while the shutter is open.
    pub fn deforms(&self) -> bool {
        self.closing.is_some()
    }

    /// The flags its queries are compiled with ([`by_flags!`]): whether
    /// it moves under the shutter, whether it holds spheres.
    #[inline(always)]
    pub(super) fn flags(&self) -> (bool, bool) {
        (self.closing.is_some(), self.spheres)
    }

    /// The hierarchy (for its SAH cost and bounds).
    pub fn hierarchy(&self) -> &Hierarchy {
        &self.hierarchy
    }

    /// The box around the primitives at every shutter time.
    pub fn bounds(&self) -> Option<Aabb> {
        self.hierarchy.wide.bounds()
    }

    /// Boxes whose union holds the primitives: those of the hierarchy's
    /// top two levels (up to 64). Transformed one by one, they bound a
    /// turned instance much more tightly than its whole box turned.
    pub fn cover(&self) -> Vec<Aabb> {
        self.hierarchy.wide.cover()
    }

    /// The primitives at shutter close (leaf order), for geometry that
    /// deforms while the shutter is open.
    pub fn closing_primitives(&self) -> Option<&[Primitive]> {
        self.closing.as_ref().map(|c| &c.prims[..])
    }

    /// Primitive `i` (leaf order) at shutter time `tau` (triangles of a
    /// deforming mesh are interpolated vertex by vertex).
    ///
    /// A static primitive is borrowed where it is stored, so that its
    /// reader loads it from there: a copy on the stack, written a field at
    /// a time and read back a vertex (16 bytes) at a time, would stall
    /// each read until the writes retire.
    #[inline(always)]
    pub fn primitive(&self, i: usize, tau: f32) -> Cow<'_, Primitive> {
        match (&self.closing, &self.prims[i]) {
            (Some(c), Primitive::Triangle(a)) => match c.prims[i] {
                Primitive::Triangle(b) => {
                    Cow::Owned(Primitive::Triangle(std::array::from_fn(|k| {
                        a[k] + (b[k] - a[k]) * tau
                    })))
                }
                Primitive::Sphere(..) => Cow::Borrowed(&self.prims[i]),
            },
            (_, p) => Cow::Borrowed(p),
        }
    }

    /// The closest hit of `origin + t·dir` within `tmax` at shutter time
    /// `tau`, its primitive numbered from `base`; [`Hit::MISS`] if none.
    #[inline(always)]
    pub(super) fn closest<I: Isa>(
        &self,
        origin: Vec3,
        dir: Vec3,
        tmax: f32,
        tau: f32,
        base: u32,
    ) -> Hit {
        if self.packets.is_empty() || !ray_is_valid(origin, dir, tmax) {
            return Hit::MISS;
        }
        by_flags!(
            self.flags(),
            self.closest_in::<I>(origin, dir, tau, tmax, base)
        )
    }

    /// [`Blas::closest`] with the query compiled for motion (`MOVING`) and
    /// for spheres (`SPHERES`) as this level needs.
    #[inline(always)]
    fn closest_in<I: Isa, const MOVING: bool, const SPHERES: bool>(
        &self,
        origin: Vec3,
        dir: Vec3,
        tau: f32,
        tmax: f32,
        base: u32,
    ) -> Hit {
        // Prepared here, in each combination of flags, so that one that
        // does not read the ray's origin, direction or time stores none.
        let ray = &Ray::new::<I>(origin, dir, tau);
        let mut query = self.query::<MOVING, SPHERES>(ray);
        query.base = base;
        self.hierarchy
            .wide
            .closest::<I>(&ray.boxes, tmax, &mut query);
        query.best
    }

    /// [`Blas::any`] as [`Blas::closest_in`].
    #[inline(always)]
    fn any_in<I: Isa, const MOVING: bool, const SPHERES: bool>(
        &self,
        origin: Vec3,
        dir: Vec3,
        tau: f32,
        tmax: f32,
    ) -> bool {
        let ray = &Ray::new::<I>(origin, dir, tau);
        let mut query = self.query::<MOVING, SPHERES>(ray);
        self.hierarchy.wide.any::<I>(&ray.boxes, tmax, &mut query)
    }

    /// A query of `ray` against this level's packets.
    #[inline(always)]
    fn query<'a, const MOVING: bool, const SPHERES: bool>(
        &'a self,
        ray: &Ray,
    ) -> Query<'a, MOVING, SPHERES> {
        let closing = self.closing.as_ref().map_or(&[][..], |c| &c.packets);
        Query::new(&self.packets, closing, ray)
    }

    /// The closest hits of the rays `origins[i] + t·dirs[i]` of `lanes`
    /// (a bit each), t in (0, `tmax[i]`) at shutter time 0, in one
    /// traversal of the hierarchy ([`RayPacket`]), their primitives
    /// numbered from `base`: for rays that visit the same nodes, such as
    /// the camera rays of one pixel. The other lanes hold rays too (copies
    /// of one of `lanes`) and get [`Hit::MISS`]. `None` where the eight
    /// cannot share a traversal (their directions' signs or dominant axes
    /// differ, a ray is not finite, or this level moves under the
    /// shutter): then trace them one by one.
    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx2")]
    pub(super) fn closest_packet(
        &self,
        origins: &[Vec3; PACKET],
        dirs: &[Vec3; PACKET],
        lanes: u32,
        tmax: &[f32; PACKET],
        base: u32,
    ) -> Option<[Hit; PACKET]> {
        let valid = (0..PACKET).all(|i| ray_is_valid(origins[i], dirs[i], f32::INFINITY));
        if self.packets.is_empty() || self.closing.is_some() || !valid {
            return None;
        }
        let (origin, dir) = (lanes_of(origins), lanes_of(dirs));
        let rays = RayPacket::new(origin, dir)?;
        let prep = PacketPrep::new(origin, dir)?;
        // Lanes with no room for a hit (`tmax` not positive, or NaN) miss.
        let mut tmax = *tmax;
        let mut active = lanes;
        for (lane, t) in tmax.iter_mut().enumerate() {
            if t.is_nan() || *t <= 0.0 || lanes & (1 << lane) == 0 {
                *t = 0.0;
                active &= !(1 << lane);
            }
        }
        Some(if self.spheres {
            self.closest_packet_in::<true>(&rays, prep, (origins, dirs), active, tmax, base)
        } else {
            self.closest_packet_in::<false>(&rays, prep, (origins, dirs), active, tmax, base)
        })
    }

    /// [`Blas::closest_packet`] compiled with or without the sphere test.
    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx2")]
    fn closest_packet_in<const SPHERES: bool>(
        &self,
        rays: &RayPacket,
        prep: PacketPrep,
        (origins, dirs): (&[Vec3; PACKET], &[Vec3; PACKET]),
        active: u32,
        mut tmax: [f32; PACKET],
        base: u32,
    ) -> [Hit; PACKET] {
        let mut query = PacketQuery::<SPHERES> {
            packets: &self.packets,
            origins,
            dirs,
            prep,
            base,
            prim: [Hit::MISS.prim; PACKET],
            b1: [0.0; PACKET],
            b2: [0.0; PACKET],
        };
        self.hierarchy
            .wide
            .closest_packet(rays, &mut tmax, active, &mut query);
        std::array::from_fn(|lane| match query.prim[lane] {
            prim if prim == Hit::MISS.prim => Hit::MISS,
            prim => Hit {
                t: tmax[lane],
                prim,
                inst: 0,
                b1: query.b1[lane],
                b2: query.b2[lane],
            },
        })
    }

    /// Whether anything blocks `origin + t·dir` for t in (0, `tmax`) at
    /// shutter time `tau`.
    #[inline(always)]
    pub(super) fn any<I: Isa>(&self, origin: Vec3, dir: Vec3, tmax: f32, tau: f32) -> bool {
        if self.packets.is_empty() || !ray_is_valid(origin, dir, tmax) {
            return false;
        }
        by_flags!(self.flags(), self.any_in::<I>(origin, dir, tau, tmax))
    }
}

/// Whether any of `packets` holds spheres.
fn has_spheres(packets: &[Packet]) -> bool {
    packets.iter().any(|p| matches!(p, Packet::Spheres { .. }))
}

/// The boxes of `prims` (containing their shapes at shutter close too).
fn boxes(prims: &[Primitive], close: Option<&[Primitive]>) -> Vec<Option<Aabb>> {
    match close {
        None => prims
            .par_iter()
            .with_min_len(4096)
            .map(Primitive::aabb)
            .collect(),
        Some(close) => {
            assert_eq!(close.len(), prims.len(), "open and close differ in length");
            prims
                .par_iter()
                .with_min_len(4096)
                .zip(close)
                .map(|(a, b)| Some(a.aabb()?.union(&b.aabb()?)))
                .collect()
        }
    }
}

/// Room for the packets of `prims`: at most one per primitive (address
/// space only; the packets written take memory).
fn packet_room(prims: &[Primitive]) -> HugeArray<Packet> {
    HugeArray::with_capacity(prims.len())
}

/// Stores one leaf of input primitives `leaf`: triangles first, then
/// spheres, in packets of four; returns its range of packets.
fn store_leaf(
    leaf: &[u32],
    prims: &[Primitive],
    order: &mut Vec<u32>,
    packets: &mut HugeArray<Packet>,
) -> Range<u32> {
    let start = packets.len() as u32;
    let (tris, spheres): (Vec<u32>, Vec<u32>) = leaf
        .iter()
        .partition(|&&i| matches!(prims[i as usize], Primitive::Triangle(_)));
    for (group, triangles) in [(&tris, true), (&spheres, false)] {
        for chunk in group.chunks(4) {
            let first = order.len() as u32;
            order.extend_from_slice(chunk);
            let (members, count) = (chunk.iter().map(|&i| prims[i as usize]), chunk.len() as u32);
            packets.push(if triangles {
                let tris = pack(members);
                Packet::Triangles { tris, first, count }
            } else {
                let spheres = pack_spheres(members);
                Packet::Spheres {
                    spheres,
                    first,
                    count,
                }
            });
        }
    }
    start..packets.len() as u32
}

/// The triangles among `prims` as one packet.
fn pack(prims: impl Iterator<Item = Primitive>) -> Tri4 {
    let mut vertices = [[Vec3::ZERO; 3]; 4];
    let mut n = 0;
    for p in prims {
        if let Primitive::Triangle(v) = p {
            vertices[n] = v;
            n += 1;
        }
    }
    Tri4::new(&vertices[..n])
}

/// The spheres among `prims` as one packet.
fn pack_spheres(prims: impl Iterator<Item = Primitive>) -> Sphere4 {
    let mut spheres = [(Vec3::ZERO, 0.0); 4];
    let mut n = 0;
    for p in prims {
        if let Primitive::Sphere(c, r) = p {
            spheres[n] = (c, r);
            n += 1;
        }
    }
    Sphere4::new(&spheres[..n])
}

/// Rewrites the packets with the primitives' new shapes `prims` (input
/// order), keeping the leaf order `order`.
fn repack(packets: &mut [Packet], prims: &[Primitive], order: &[u32]) {
    packets
        .par_iter_mut()
        .with_min_len(1024)
        .for_each(|packet| {
            let range = packet.members();
            let members = order[range.start as usize..range.end as usize]
                .iter()
                .map(|&i| prims[i as usize]);
            match packet {
                Packet::Triangles { tris, .. } => *tris = pack(members),
                Packet::Spheres { spheres, .. } => *spheres = pack_spheres(members),
            }
        });
}

/// The packets of the shapes at shutter close `close` (input order),
/// laid out as the packets at shutter open, `open`.
fn closing(close: &[Primitive], order: &[u32], open: &[Packet]) -> Closing {
    let mut packets = HugeArray::from_slice(open);
    repack(&mut packets, close, order);
    Closing {
        packets,
        prims: HugeArray::from_fn(order.len(), |k| close[order[k] as usize]),
    }
}

/// One ray's query at the leaves: its packets (and, where `MOVING`,
/// their shapes at shutter close with the ray's time), its per-ray
/// constants and the closest hit so far. The flags are constants so that
/// static geometry's loops carry no test for motion, and those of a level
/// without spheres (`!SPHERES`) no sphere test: its packets are all
/// triangles, and the ray's origin and direction, which only the sphere
/// test reads, need no registers.
pub(in crate::accel) struct Query<'a, const MOVING: bool, const SPHERES: bool> {
    packets: &'a [Packet],
    closing: &'a [Packet],
    tau: f32,
    origin: Vec3,
    dir: Vec3,
    prep: RayPrep,
    /// Number of the first primitive, added to hits.
    base: u32,
    /// [`Hit::MISS`] until something is hit.
    best: Hit,
}

impl<'a, const MOVING: bool, const SPHERES: bool> Query<'a, MOVING, SPHERES> {
    #[inline(always)]
    fn new(packets: &'a [Packet], closing: &'a [Packet], ray: &Ray) -> Self {
        Self {
            packets,
            closing,
            tau: ray.tau,
            origin: ray.origin,
            dir: ray.dir,
            prep: ray.prep,
            base: 0,
            best: Hit::MISS,
        }
    }

    /// This query set up for `ray` in `blas` as [`Query::new`] would, in
    /// place: only the fields this kind of level reads are written (a ray
    /// entering a static level of triangles leaves its origin, direction
    /// and time unstored).
    #[inline(always)]
    fn restart(&mut self, blas: &'a Blas, ray: &Ray) {
        self.packets = &blas.packets;
        if MOVING {
            self.closing = blas.closing.as_ref().map_or(&[][..], |c| &c.packets);
            self.tau = ray.tau;
        }
        if SPHERES {
            self.origin = ray.origin;
            self.dir = ray.dir;
        }
        self.prep = ray.prep;
        self.base = 0;
        self.best = Hit::MISS;
    }

    /// The triangles of packet `i`, `tris`, at the ray's time.
    #[inline(always)]
    fn tris(&self, i: usize, tris: &Tri4) -> Tri4 {
        if !MOVING {
            return *tris;
        }
        match &self.closing[i] {
            Packet::Triangles { tris: end, .. } => tris.lerp(end, self.tau),
            Packet::Spheres { .. } => *tris,
        }
    }
}

impl<const MOVING: bool, const SPHERES: bool> LeafVisitor for Query<'_, MOVING, SPHERES> {
    #[inline(always)]
    fn closest(&mut self, range: Range<usize>, mut tmax: f32) -> f32 {
        for i in range {
            match self.packets[i] {
                Packet::Triangles {
                    ref tris, first, ..
                } => {
                    let hit = if MOVING {
                        self.tris(i, tris).closest(&self.prep, tmax)
                    } else {
                        tris.closest(&self.prep, tmax)
                    };
                    if let Some(h) = hit {
                        tmax = h.t;
                        self.best = Hit {
                            t: h.t,
                            prim: self.base + first + h.lane as u32,
                            inst: 0,
                            b1: h.b1,
                            b2: h.b2,
                        };
                    }
                }
                Packet::Spheres {
                    ref spheres, first, ..
                } if SPHERES => {
                    if let Some((lane, t)) = hit_spheres(spheres, self.origin, self.dir, tmax) {
                        tmax = t;
                        self.best = Hit {
                            t,
                            prim: self.base + first + lane as u32,
                            inst: 0,
                            b1: 0.0,
                            b2: 0.0,
                        };
                    }
                }
                // A level without spheres has none.
                Packet::Spheres { .. } => {}
            }
        }
        tmax
    }

    #[inline(always)]
    fn any(&mut self, range: Range<usize>, tmax: f32) -> bool {
        for i in range {
            let hit = match self.packets[i] {
                Packet::Triangles { ref tris, .. } => {
                    if MOVING {
                        self.tris(i, tris).any(&self.prep, tmax)
                    } else {
                        tris.any(&self.prep, tmax)
                    }
                }
                Packet::Spheres { ref spheres, .. } if SPHERES => {
                    any_sphere(spheres, self.origin, self.dir, tmax)
                }
                // A level without spheres has none.
                Packet::Spheres { .. } => false,
            };
            if hit {
                return true;
            }
        }
        false
    }
}

/// A packet of rays against one bottom level's packets of primitives:
/// triangles one at a time against all the rays ([`Tri4::test_rays`]),
/// spheres ray by ray.
#[cfg(target_arch = "x86_64")]
struct PacketQuery<'a, const SPHERES: bool> {
    packets: &'a [Packet],
    origins: &'a [Vec3; PACKET],
    dirs: &'a [Vec3; PACKET],
    prep: PacketPrep,
    /// Number of the first primitive, added to hits.
    base: u32,
    /// Per ray, of its closest hit so far (whose distance is the
    /// traversal's `tmax`): the primitive ([`Hit::MISS`]'s until one is
    /// hit) and the barycentrics.
    prim: [u32; PACKET],
    b1: [f32; PACKET],
    b2: [f32; PACKET],
}

#[cfg(target_arch = "x86_64")]
impl<const SPHERES: bool> PacketQuery<'_, SPHERES> {
    /// The triangles of `tris` (`count` from primitive `first` on) against
    /// `lanes`: lowers each lane's `tmax` to its hits and returns the
    /// lanes that the single-ray test must decide.
    #[target_feature(enable = "avx2")]
    #[inline]
    fn triangles(
        &mut self,
        tris: &Tri4,
        first: u32,
        count: u32,
        lanes: u32,
        tmax: &mut [f32; PACKET],
    ) -> u32 {
        let active = lane_mask(lanes);
        let mut redo = 0;
        // All four triangles against one `tmax`, the nearest hit kept (the
        // first of equally near ones), as `Tri4::closest` does.
        // SAFETY: `tmax` holds eight f32.
        let reach = unsafe { _mm256_loadu_ps(tmax.as_ptr()) };
        for j in 0..count as usize {
            let hits = tris.test_rays(j, &self.prep, reach, active);
            redo |= hits.redo;
            // SAFETY: as above.
            let nearest = unsafe { _mm256_loadu_ps(tmax.as_ptr()) };
            let nearer = _mm256_cmp_ps::<_CMP_LT_OQ>(hits.t, nearest);
            let hit = _mm256_and_ps(lane_mask(hits.hit), nearer);
            if _mm256_movemask_ps(hit) != 0 {
                // The hit lanes' new closest hits, blended in.
                let prim = _mm256_set1_epi32((self.base + first + j as u32) as i32);
                // SAFETY: the arrays hold eight 32-bit values each.
                unsafe {
                    let update = |at: *mut f32, new: __m256| {
                        _mm256_storeu_ps(at, _mm256_blendv_ps(_mm256_loadu_ps(at), new, hit));
                    };
                    update(tmax.as_mut_ptr(), hits.t);
                    update(self.b1.as_mut_ptr(), hits.b1);
                    update(self.b2.as_mut_ptr(), hits.b2);
                    update(self.prim.as_mut_ptr().cast(), _mm256_castsi256_ps(prim));
                }
            }
        }
        redo
    }
}

#[cfg(target_arch = "x86_64")]
impl<const SPHERES: bool> PacketLeafVisitor for PacketQuery<'_, SPHERES> {
    #[inline(always)]
    fn closest(&mut self, range: Range<usize>, lanes: u32, tmax: &mut [f32; PACKET]) {
        let mut redo = 0;
        for i in range.clone() {
            match self.packets[i] {
                Packet::Triangles {
                    ref tris,
                    first,
                    count,
                } => {
                    // SAFETY: packet traversals run only on CPUs with AVX2
                    // (`Blas::closest_packet`).
                    redo |= unsafe { self.triangles(tris, first, count, lanes, tmax) };
                }
                Packet::Spheres {
                    ref spheres, first, ..
                } if SPHERES => {
                    let mut each = lanes;
                    while each != 0 {
                        let lane = each.trailing_zeros() as usize;
                        each &= each - 1;
                        let (o, d) = (self.origins[lane], self.dirs[lane]);
                        if let Some((k, t)) = hit_spheres(spheres, o, d, tmax[lane]) {
                            tmax[lane] = t;
                            self.prim[lane] = self.base + first + k as u32;
                            (self.b1[lane], self.b2[lane]) = (0.0, 0.0);
                        }
                    }
                }
                // A level without spheres has none.
                Packet::Spheres { .. } => {}
            }
        }
        // The lanes the packet test left undecided: the leaf again, ray
        // by ray, from the hits found so far.
        while redo != 0 {
            let lane = redo.trailing_zeros() as usize;
            redo &= redo - 1;
            let ray = Ray {
                origin: self.origins[lane],
                dir: self.dirs[lane],
                tau: 0.0,
                prep: self.prep.lane(lane),
                boxes: RayBoxes::new(self.origins[lane], self.dirs[lane]),
            };
            let mut query = Query::<false, SPHERES>::new(self.packets, &[], &ray);
            query.base = self.base;
            tmax[lane] = query.closest(range.clone(), tmax[lane]);
            if query.best.prim != Hit::MISS.prim {
                let best = query.best;
                (self.prim[lane], self.b1[lane], self.b2[lane]) = (best.prim, best.b1, best.b2);
            }
        }
    }
}

/// [`Sphere4::closest`], kept out of the triangle loops so that they
/// keep their registers (triangles are by far the common case).
#[inline(never)]
fn hit_spheres(spheres: &Sphere4, origin: Vec3, dir: Vec3, tmax: f32) -> Option<(usize, f32)> {
    spheres.closest(origin, dir, tmax)
}

/// [`Sphere4::any`], out of line as [`hit_spheres`].
#[inline(never)]
fn any_sphere(spheres: &Sphere4, origin: Vec3, dir: Vec3, tmax: f32) -> bool {
    spheres.any(origin, dir, tmax)
}

/// The box of `p`, or `None` where a coordinate is not finite.
impl Primitive {
    pub(super) fn aabb(&self) -> Option<Aabb> {
        let aabb = match *self {
            Primitive::Triangle([a, b, c]) => {
                let a = Vec3A::from(a);
                let b = Vec3A::from(b);
                let c = Vec3A::from(c);
                Aabb::new(a.min(b).min(c), a.max(b).max(c))
            }
            Primitive::Sphere(c, r) => {
                let c = Vec3A::from(c);
                let r = Vec3A::splat(r.abs());
                Aabb::new(c - r, c + r)
            }
        };
        (aabb.min.is_finite() && aabb.max.is_finite()).then_some(aabb)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    use crate::accel::tests::lcg;

    /// A grid of small triangles, and the same grid after a large,
    /// non-rigid move (a twist and a wave).
    fn soup(n: usize, twist: f32) -> Vec<Primitive> {
        let mut prims = Vec::new();
        let mut s = 3;
        for i in 0..n {
            let c = Vec3::new(lcg(&mut s), lcg(&mut s), lcg(&mut s)) * 10.0 - 5.0;
            let mut v = || c + (Vec3::new(lcg(&mut s), lcg(&mut s), lcg(&mut s)) - 0.5) * 0.6;
            let tri = [v(), v(), v()];
            let moved = tri.map(|p| {
                let a = twist * p.y;
                let (sin, cos) = a.sin_cos();
                Vec3::new(
                    cos * p.x - sin * p.z,
                    p.y + twist * (p.x * 0.7).sin(),
                    sin * p.x + cos * p.z,
                )
            });
            prims.push(if i % 50 == 49 {
                Primitive::Sphere(moved[0], 0.2)
            } else {
                Primitive::Triangle(moved)
            });
        }
        prims
    }

    /// Every leaf's box holds its primitives, every node's box its
    /// children's boxes.
    fn assert_boxes_contain(blas: &Blas, prims: &[Primitive]) {
        let lanes = blas.hierarchy.wide.lanes();
        let inside = |outer: &Aabb, inner: &Aabb| {
            outer.min.cmple(inner.min).all() && outer.max.cmpge(inner.max).all()
        };
        for (_, aabb, items, child) in &lanes {
            match items {
                Some(range) => {
                    for packet in &blas.packets[range.clone()] {
                        for i in packet.members() {
                            let p = prims[blas.order[i as usize] as usize];
                            let b = p.aabb().expect("finite primitives");
                            assert!(inside(aabb, &b), "{b:?} outside its leaf {aabb:?}");
                        }
                    }
                }
                None => {
                    for (node, b, ..) in &lanes {
                        if node == child {
                            assert!(inside(aabb, b), "child {b:?} outside {aabb:?}");
                        }
                    }
                }
            }
        }
    }

    #[test]
    fn refitted_boxes_contain_the_moved_primitives() {
        let before = soup(3000, 0.0);
        let mut blas = Blas::build(&before, None, BuildQuality::Medium);
        assert_boxes_contain(&blas, &before);
        for twist in [0.05, 0.4, 1.5] {
            let after = soup(3000, twist);
            let never = UpdatePolicy {
                rebuild_above: f32::INFINITY,
            };
            let update = blas.update(&after, None, never);
            assert!(!update.rebuilt);
            assert!(update.degradation > 0.0, "{update:?}");
            assert_boxes_contain(&blas, &after);
        }
    }

    #[test]
    fn refitted_and_rebuilt_hierarchies_find_the_same_hits() {
        let after = soup(2000, 0.8);
        let mut refitted = Blas::build(&soup(2000, 0.0), None, BuildQuality::Medium);
        let never = UpdatePolicy {
            rebuild_above: f32::INFINITY,
        };
        refitted.update(&after, None, never);
        let always = UpdatePolicy { rebuild_above: 0.0 };
        let mut rebuilt = Blas::build(&soup(2000, 0.0), None, BuildQuality::Medium);
        assert!(rebuilt.update(&after, None, always).rebuilt);
        let fresh = Blas::build(&after, None, BuildQuality::Medium);
        let mut s = 17;
        let mut hits = 0;
        for _ in 0..20_000 {
            let o = Vec3::new(lcg(&mut s), lcg(&mut s), lcg(&mut s)) * 16.0 - 8.0;
            let d = (Vec3::new(lcg(&mut s), lcg(&mut s), lcg(&mut s)) - 0.5).normalize();
            let closest = |b: &Blas| {
                let h = b.closest::<super::super::wide::Baseline>(o, d, f32::INFINITY, 0.0, 0);
                (h.prim != Hit::MISS.prim).then(|| (h.t, b.order[h.prim as usize]))
            };
            let expected = closest(&fresh);
            assert_eq!(closest(&refitted), expected);
            assert_eq!(closest(&rebuilt), expected);
            hits += usize::from(expected.is_some());
            let any = |b: &Blas| b.any::<super::super::wide::Baseline>(o, d, 3.0, 0.0);
            assert_eq!(any(&refitted), any(&fresh));
        }
        assert!(hits > 2000, "only {hits} rays hit");
    }

    #[test]
    fn deforming_triangles_are_hit_where_they_are_at_the_ray_time() {
        let open = soup(500, 0.0);
        let close = soup(500, 0.6);
        let moving = Blas::build(&open, Some(&close), BuildQuality::Medium);
        let mut s = 29;
        let mut hits = 0;
        for _ in 0..5000 {
            let tau = lcg(&mut s);
            let at: Vec<Primitive> = open
                .iter()
                .zip(&close)
                .map(|(a, b)| match (a, b) {
                    (Primitive::Triangle(a), Primitive::Triangle(b)) => {
                        Primitive::Triangle(std::array::from_fn(|k| a[k] + (b[k] - a[k]) * tau))
                    }
                    (Primitive::Sphere(c, r), Primitive::Sphere(..)) => Primitive::Sphere(*c, *r),
                    _ => unreachable!(),
                })
                .collect();
            let o = Vec3::new(lcg(&mut s), lcg(&mut s), lcg(&mut s)) * 16.0 - 8.0;
            let d = (Vec3::new(lcg(&mut s), lcg(&mut s), lcg(&mut s)) - 0.5).normalize();
            let h = moving.closest::<super::super::wide::Baseline>(o, d, f32::INFINITY, tau, 0);
            // Brute force over the triangles where they are at τ.
            let prep = RayPrep::new(o, d);
            let expected = at
                .iter()
                .enumerate()
                .filter_map(|(i, p)| match p {
                    Primitive::Triangle(v) => Tri4::new(std::slice::from_ref(v))
                        .closest(&prep, f32::INFINITY)
                        .map(|h| (h.t, i as u32)),
                    Primitive::Sphere(c, r) => {
                        crate::accel::sphere::intersect(o, d, *c, *r, f32::INFINITY)
                            .map(|t| (t, i as u32))
                    }
                })
                .min_by(|a, b| a.0.total_cmp(&b.0));
            let got = (h.prim != Hit::MISS.prim).then(|| (h.t, moving.order[h.prim as usize]));
            match (got, expected) {
                (None, None) => {}
                (Some((t, i)), Some((u, j))) => {
                    assert!((t - u).abs() <= 1e-4 * u.max(1.0), "t {t} vs {u}");
                    if i != j {
                        assert!((t - u).abs() <= 1e-5 * u.max(1.0));
                    }
                    hits += 1;
                }
                other => panic!("moving hierarchy and brute force disagree at τ {tau}: {other:?}"),
            }
        }
        assert!(hits > 100, "only {hits} rays hit");
    }
}
