//! Acceleration: the BVH over all primitives and robust ray queries.
//!
//! obvhs builds a binary BVH over the primitives' boxes, which `wide`
//! collapses into the 8-wide BVH that rays traverse. Primitives (triangles
//! and analytic spheres) are numbered in its leaf order, so a leaf's
//! primitives are contiguous and a hit's primitive index addresses the
//! shading arrays directly. A leaf's triangles are stored as packets of
//! four ([`triangle::Tri4`]) and tested together with SIMD.
//!
//! Triangles use the watertight test of Woop et al. 2013. Spawned rays
//! start at origins offset by a conservative bound on the hit point's
//! floating-point error ([`offset`]), which keeps self-intersection away at
//! every scene scale without a fixed epsilon.

pub mod offset;
pub mod sphere;
pub mod triangle;
mod wide;

use glam::{Vec3, Vec3A};
use obvhs::BvhBuildParams;
use obvhs::aabb::Aabb;
use std::ops::Range;
use std::time::Duration;
use triangle::{RayPrep, Tri4};
use wide::{Avx2, Baseline, Isa, LeafVisitor, RayBoxes, WideBvh};

/// A primitive as the intersector sees it.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Primitive {
    /// A triangle by its vertices.
    Triangle([Vec3; 3]),
    /// A sphere by centre and radius.
    Sphere(Vec3, f32),
}

impl Primitive {
    /// The bounding box, or `None` where a coordinate is not finite (such
    /// a primitive is never hit).
    fn aabb(&self) -> Option<Aabb> {
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

/// The closest hit of a ray.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct Hit {
    /// Distance along the ray (in units of the direction's length).
    pub t: f32,
    /// Index of the primitive (in BVH order).
    pub prim: u32,
    /// Barycentric coordinates of vertices 1 and 2 (triangles only).
    pub b1: f32,
    /// See `b1`.
    pub b2: f32,
}

impl Hit {
    /// What a ray that hits nothing gets from batch queries: `t` infinite,
    /// `prim` `u32::MAX`.
    pub const MISS: Hit = Hit {
        t: f32::INFINITY,
        prim: u32::MAX,
        b1: 0.0,
        b2: 0.0,
    };
}

/// BVH quality preset.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum BuildQuality {
    /// Fast build, slower traversal.
    Fast,
    /// The trade-off for very large scenes.
    Medium,
    /// Slow build (about twice Medium's), best traversal.
    High,
}

impl BuildQuality {
    /// Primitives up to which scenes get [`BuildQuality::High`] by default.
    pub const HIGH_UP_TO: usize = 1 << 20;

    /// The default for a scene of `primitives`: `High` up to
    /// [`Self::HIGH_UP_TO`] (0.27 s instead of 0.14 s for 169k triangles on
    /// one core; the Cornell box renders 4.5 % faster), `Medium` beyond,
    /// where the build's time starts to count.
    pub fn default_for(primitives: usize) -> Self {
        if primitives <= Self::HIGH_UP_TO {
            Self::High
        } else {
            Self::Medium
        }
    }

    /// obvhs' parameters for the binary BVH.
    fn params(self) -> BvhBuildParams {
        let mut params = match self {
            BuildQuality::Fast => BvhBuildParams::fast_build(),
            BuildQuality::Medium => BvhBuildParams::medium_build(),
            BuildQuality::High => BvhBuildParams::slow_build(),
        };
        // One primitive per leaf: the wide BVH's collapse picks the leaves.
        params.max_prims_per_leaf = 1;
        params
    }
}

/// What a leaf holds: triangles four at a time, or one sphere.
#[derive(Debug, Clone, Copy)]
enum Packet {
    /// Up to four triangles, primitives `first`, `first + 1`, ….
    Triangles { tris: Tri4, first: u32 },
    /// A sphere, primitive `prim`.
    Sphere {
        centre: Vec3,
        radius: f32,
        prim: u32,
    },
}

/// A built BVH with its primitives in leaf order.
pub struct Accel {
    bvh: WideBvh,
    packets: Vec<Packet>,
    prims: Vec<Primitive>,
    /// Whether queries run the AVX2 traversal (the CPU has AVX2; only
    /// read on x86_64).
    #[cfg_attr(not(target_arch = "x86_64"), allow(dead_code))]
    avx2: bool,
    /// Time the build took.
    pub build_time: Duration,
}

impl Accel {
    /// Builds the BVH over `prims`; returns it and, for each BVH-order
    /// index, the index of the primitive in `prims`.
    pub fn build(prims: &[Primitive], quality: BuildQuality) -> (Self, Vec<u32>) {
        let start = std::time::Instant::now();
        let boxes: Vec<Option<Aabb>> = prims.iter().map(Primitive::aabb).collect();
        // Primitives with non-finite coordinates get a point box inside the
        // scene, so that they cannot spoil the boxes above them.
        let somewhere = boxes.iter().flatten().next().map_or(Vec3A::ZERO, |b| b.min);
        let point = Aabb::new(somewhere, somewhere);
        let boxes: Vec<Aabb> = boxes.into_iter().map(|b| b.unwrap_or(point)).collect();

        let mut order = Vec::with_capacity(prims.len());
        let mut packets = Vec::new();
        let bvh = if prims.is_empty() {
            WideBvh::default()
        } else {
            let mut core_time = Duration::default();
            let bvh2 = obvhs::bvh2::builder::build_bvh2(&boxes, quality.params(), &mut core_time);
            WideBvh::build(&bvh2, |leaf| {
                let start = packets.len() as u32;
                // Triangles first, so that they pack into runs of four.
                let (tris, spheres): (Vec<u32>, Vec<u32>) = leaf
                    .iter()
                    .partition(|&&i| matches!(prims[i as usize], Primitive::Triangle(_)));
                for chunk in tris.chunks(4) {
                    let first = order.len() as u32;
                    let vertices: Vec<[Vec3; 3]> = chunk
                        .iter()
                        .filter_map(|&i| match prims[i as usize] {
                            Primitive::Triangle(v) => Some(v),
                            Primitive::Sphere(..) => None,
                        })
                        .collect();
                    order.extend_from_slice(chunk);
                    packets.push(Packet::Triangles {
                        tris: Tri4::new(&vertices),
                        first,
                    });
                }
                for &i in &spheres {
                    if let Primitive::Sphere(centre, radius) = prims[i as usize] {
                        packets.push(Packet::Sphere {
                            centre,
                            radius,
                            prim: order.len() as u32,
                        });
                        order.push(i);
                    }
                }
                start..packets.len() as u32
            })
        };
        debug_assert_eq!(order.len(), prims.len());
        let ordered = order.iter().map(|&i| prims[i as usize]).collect();
        let accel = Self {
            bvh,
            packets,
            prims: ordered,
            avx2: Avx2::detected(),
            build_time: start.elapsed(),
        };
        (accel, order)
    }

    /// The primitives, in BVH order.
    pub fn primitives(&self) -> &[Primitive] {
        &self.prims
    }

    /// Finds the closest hit along `origin + t·dir` for `t` in (0, `tmax`).
    #[inline]
    pub fn intersect(&self, origin: Vec3, dir: Vec3, tmax: f32) -> Option<Hit> {
        #[cfg(target_arch = "x86_64")]
        let hit = if self.avx2 {
            // SAFETY: `avx2` is set only where the CPU supports AVX2.
            unsafe { self.intersect_avx2(origin, dir, tmax) }
        } else {
            self.intersect_with::<Baseline>(origin, dir, tmax)
        };
        #[cfg(not(target_arch = "x86_64"))]
        let hit = self.intersect_with::<Baseline>(origin, dir, tmax);
        (hit.prim != Hit::MISS.prim).then_some(hit)
    }

    /// Whether anything blocks `origin + t·dir` for `t` in (0, `tmax`).
    #[inline]
    pub fn occluded(&self, origin: Vec3, dir: Vec3, tmax: f32) -> bool {
        #[cfg(target_arch = "x86_64")]
        if self.avx2 {
            // SAFETY: `avx2` is set only where the CPU supports AVX2.
            return unsafe { self.occluded_avx2(origin, dir, tmax) };
        }
        self.occluded_with::<Baseline>(origin, dir, tmax)
    }

    /// Closest hits of a batch of rays: for each `slot` in `slots`, the ray
    /// `origins[slot] + t·dirs[slot]`, t in (0, ∞), gets its hit in
    /// `hits[slot]` ([`Hit::MISS`] if it hits nothing). The instruction
    /// set is chosen once for the batch and the loop compiled for it.
    ///
    /// # Panics
    ///
    /// If a slot is out of bounds of `origins`, `dirs` or `hits`.
    pub fn intersect_slots(
        &self,
        slots: &[u32],
        origins: &[Vec3],
        dirs: &[Vec3],
        hits: &mut [Hit],
    ) {
        #[cfg(target_arch = "x86_64")]
        if self.avx2 {
            // SAFETY: `avx2` is set only where the CPU supports AVX2.
            return unsafe { self.intersect_slots_avx2(slots, origins, dirs, hits) };
        }
        self.intersect_slots_with::<Baseline>(slots, origins, dirs, hits);
    }

    /// For a batch of shadow rays `origins[j] + t·dirs[j]`, t in
    /// (0, `tmax`): whether anything blocks ray `j`, in `blocked[j]`. The
    /// instruction set is chosen once for the batch.
    ///
    /// # Panics
    ///
    /// If the three slices differ in length.
    pub fn occluded_each(&self, origins: &[Vec3], dirs: &[Vec3], tmax: f32, blocked: &mut [bool]) {
        assert!(origins.len() == dirs.len() && dirs.len() == blocked.len());
        #[cfg(target_arch = "x86_64")]
        if self.avx2 {
            // SAFETY: `avx2` is set only where the CPU supports AVX2.
            return unsafe { self.occluded_each_avx2(origins, dirs, tmax, blocked) };
        }
        self.occluded_each_with::<Baseline>(origins, dirs, tmax, blocked);
    }

    /// [`Self::intersect`] compiled for AVX2.
    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx2")]
    fn intersect_avx2(&self, origin: Vec3, dir: Vec3, tmax: f32) -> Hit {
        self.intersect_with::<Avx2>(origin, dir, tmax)
    }

    /// [`Self::occluded`] compiled for AVX2.
    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx2")]
    fn occluded_avx2(&self, origin: Vec3, dir: Vec3, tmax: f32) -> bool {
        self.occluded_with::<Avx2>(origin, dir, tmax)
    }

    /// [`Self::intersect_slots`] compiled for AVX2.
    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx2")]
    fn intersect_slots_avx2(
        &self,
        slots: &[u32],
        origins: &[Vec3],
        dirs: &[Vec3],
        hits: &mut [Hit],
    ) {
        self.intersect_slots_with::<Avx2>(slots, origins, dirs, hits);
    }

    /// [`Self::occluded_each`] compiled for AVX2.
    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx2")]
    fn occluded_each_avx2(&self, origins: &[Vec3], dirs: &[Vec3], tmax: f32, blocked: &mut [bool]) {
        self.occluded_each_with::<Avx2>(origins, dirs, tmax, blocked);
    }

    /// [`Self::intersect_slots`] with the instruction set `I`.
    #[inline(always)]
    fn intersect_slots_with<I: Isa>(
        &self,
        slots: &[u32],
        origins: &[Vec3],
        dirs: &[Vec3],
        hits: &mut [Hit],
    ) {
        for &slot in slots {
            let i = slot as usize;
            hits[i] = self.intersect_with::<I>(origins[i], dirs[i], f32::INFINITY);
        }
    }

    /// [`Self::occluded_each`] with the instruction set `I`.
    #[inline(always)]
    fn occluded_each_with<I: Isa>(
        &self,
        origins: &[Vec3],
        dirs: &[Vec3],
        tmax: f32,
        blocked: &mut [bool],
    ) {
        for ((b, &o), &d) in blocked.iter_mut().zip(origins).zip(dirs) {
            *b = self.occluded_with::<I>(o, d, tmax);
        }
    }

    /// Queries run the baseline traversal from now on, whatever the CPU
    /// supports (to test it against the AVX2 one).
    #[cfg(test)]
    fn use_baseline(&mut self) {
        self.avx2 = false;
    }

    /// [`Self::intersect`] with the instruction set `I`; [`Hit::MISS`]
    /// where nothing is hit.
    #[inline(always)]
    fn intersect_with<I: Isa>(&self, origin: Vec3, dir: Vec3, tmax: f32) -> Hit {
        if self.bvh.is_empty() || !ray_is_valid(origin, dir, tmax) {
            return Hit::MISS;
        }
        let prep = RayPrep::new(origin, dir);
        let mut query = Query::new(&self.packets, origin, dir, &prep);
        self.bvh
            .closest::<I>(&RayBoxes::new(origin, dir), tmax, &mut query);
        query.best
    }

    /// [`Self::occluded`] with the instruction set `I`.
    #[inline(always)]
    fn occluded_with<I: Isa>(&self, origin: Vec3, dir: Vec3, tmax: f32) -> bool {
        if self.bvh.is_empty() || !ray_is_valid(origin, dir, tmax) {
            return false;
        }
        let prep = RayPrep::new(origin, dir);
        let mut query = Query::new(&self.packets, origin, dir, &prep);
        self.bvh
            .any::<I>(&RayBoxes::new(origin, dir), tmax, &mut query)
    }
}

/// One ray's query at the leaves: its packets, its per-ray constants and
/// the closest hit so far.
struct Query<'a> {
    packets: &'a [Packet],
    origin: Vec3,
    dir: Vec3,
    prep: &'a RayPrep,
    /// [`Hit::MISS`] until something is hit.
    best: Hit,
}

impl<'a> Query<'a> {
    #[inline(always)]
    fn new(packets: &'a [Packet], origin: Vec3, dir: Vec3, prep: &'a RayPrep) -> Self {
        Self {
            packets,
            origin,
            dir,
            prep,
            best: Hit::MISS,
        }
    }
}

impl LeafVisitor for Query<'_> {
    #[inline(always)]
    fn closest(&mut self, range: Range<usize>, mut tmax: f32) -> f32 {
        for packet in &self.packets[range] {
            match *packet {
                Packet::Triangles { ref tris, first } => {
                    if let Some(h) = tris.closest(self.prep, tmax) {
                        tmax = h.t;
                        self.best = Hit {
                            t: h.t,
                            prim: first + h.lane as u32,
                            b1: h.b1,
                            b2: h.b2,
                        };
                    }
                }
                Packet::Sphere {
                    centre,
                    radius,
                    prim,
                } => {
                    if let Some(t) = hit_sphere(self.origin, self.dir, centre, radius, tmax) {
                        tmax = t;
                        self.best = Hit {
                            t,
                            prim,
                            b1: 0.0,
                            b2: 0.0,
                        };
                    }
                }
            }
        }
        tmax
    }

    #[inline(always)]
    fn any(&mut self, range: Range<usize>, tmax: f32) -> bool {
        for packet in &self.packets[range] {
            let hit = match *packet {
                Packet::Triangles { ref tris, .. } => tris.any(self.prep, tmax),
                Packet::Sphere { centre, radius, .. } => {
                    hit_sphere(self.origin, self.dir, centre, radius, tmax).is_some()
                }
            };
            if hit {
                return true;
            }
        }
        false
    }
}

/// Whether a query can hit anything: finite origin and direction, and a
/// positive `tmax` (not NaN). Other rays hit nothing.
#[inline(always)]
fn ray_is_valid(origin: Vec3, dir: Vec3, tmax: f32) -> bool {
    // x·0 is 0 for finite x and NaN for ±∞ and NaN: one comparison checks
    // all six coordinates.
    let zeros = Vec3A::from(origin) * 0.0 + Vec3A::from(dir) * 0.0;
    zeros.cmpeq(Vec3A::ZERO).all() && tmax > 0.0
}

/// [`sphere::intersect`], kept out of the triangle loops so that they
/// keep their registers (triangles are by far the common case).
#[inline(never)]
fn hit_sphere(origin: Vec3, dir: Vec3, centre: Vec3, radius: f32, tmax: f32) -> Option<f32> {
    sphere::intersect(origin, dir, centre, radius, tmax)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn lcg(state: &mut u64) -> f32 {
        *state = state
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        (*state >> 40) as f32 / (1u64 << 24) as f32
    }

    fn brute_force(prims: &[Primitive], o: Vec3, d: Vec3) -> Option<(f32, usize)> {
        let prep = RayPrep::new(o, d);
        prims
            .iter()
            .enumerate()
            .filter_map(|(i, p)| match *p {
                Primitive::Triangle(v) => {
                    triangle::intersect(&prep, &v, f32::INFINITY).map(|h| (h.0, i))
                }
                Primitive::Sphere(c, r) => {
                    sphere::intersect(o, d, c, r, f32::INFINITY).map(|t| (t, i))
                }
            })
            .min_by(|a, b| a.0.total_cmp(&b.0))
    }

    #[test]
    fn bvh_agrees_with_brute_force_on_random_soups() {
        for (seed, count) in [(1u64, 1usize), (2, 2), (3, 50), (4, 2000)] {
            let mut s = seed;
            let mut prims = Vec::new();
            for i in 0..count {
                let c = Vec3::new(lcg(&mut s), lcg(&mut s), lcg(&mut s)) * 10.0 - 5.0;
                if i % 10 == 9 {
                    prims.push(Primitive::Sphere(c, 0.1 + lcg(&mut s)));
                } else {
                    let mut v =
                        || c + (Vec3::new(lcg(&mut s), lcg(&mut s), lcg(&mut s)) - 0.5) * 2.0;
                    prims.push(Primitive::Triangle([v(), v(), v()]));
                }
            }
            let (accel, order) = Accel::build(&prims, BuildQuality::Medium);
            // Both instruction sets (the same one twice without AVX2).
            let mut baseline = Accel::build(&prims, BuildQuality::Medium).0;
            baseline.use_baseline();
            for _ in 0..2000 {
                let o = Vec3::new(lcg(&mut s), lcg(&mut s), lcg(&mut s)) * 16.0 - 8.0;
                let d = (Vec3::new(lcg(&mut s), lcg(&mut s), lcg(&mut s)) - 0.5).normalize();
                let expected = brute_force(&prims, o, d);
                let got = accel.intersect(o, d, f32::INFINITY);
                match (expected, got) {
                    (None, None) => {}
                    (Some((t, i)), Some(h)) => {
                        assert!((t - h.t).abs() <= 1e-5 * t.max(1.0), "t {t} vs {}", h.t);
                        // Equal distances may pick either primitive.
                        if order[h.prim as usize] as usize != i {
                            assert_eq!(t, h.t);
                        }
                    }
                    other => panic!("BVH and brute force disagree: {other:?}"),
                }
                assert_eq!(accel.occluded(o, d, f32::INFINITY), expected.is_some());
                if let Some((t, _)) = expected {
                    assert!(!accel.occluded(o, d, t * 0.999));
                }
                assert_eq!(baseline.intersect(o, d, f32::INFINITY), got);
                for tmax in [f32::INFINITY, got.map_or(1.0, |h| h.t * 0.999)] {
                    assert_eq!(baseline.occluded(o, d, tmax), accel.occluded(o, d, tmax));
                }
            }
        }
    }

    #[test]
    fn empty_scene_hits_nothing() {
        let (accel, _) = Accel::build(&[], BuildQuality::Fast);
        assert!(
            accel
                .intersect(Vec3::ZERO, Vec3::Z, f32::INFINITY)
                .is_none()
        );
        assert!(!accel.occluded(Vec3::ZERO, Vec3::Z, f32::INFINITY));
    }

    #[test]
    fn single_primitive_scenes() {
        let tri = Primitive::Triangle([Vec3::ZERO, Vec3::X, Vec3::Y]);
        let (accel, order) = Accel::build(&[tri], BuildQuality::Medium);
        assert_eq!(order, [0]);
        let hit = accel.intersect(Vec3::new(0.2, 0.2, 1.0), -Vec3::Z, f32::INFINITY);
        assert_eq!(hit.map(|h| (h.t, h.prim)), Some((1.0, 0)));
        assert!(accel.occluded(Vec3::new(0.2, 0.2, 1.0), -Vec3::Z, 2.0));
        assert!(!accel.occluded(Vec3::new(0.2, 0.2, 1.0), -Vec3::Z, 1.0));

        let (accel, _) = Accel::build(&[Primitive::Sphere(Vec3::ZERO, 1.0)], BuildQuality::Fast);
        let hit = accel.intersect(Vec3::new(0.0, 0.0, -3.0), Vec3::Z, f32::INFINITY);
        assert_eq!(hit.map(|h| (h.t, h.prim)), Some((2.0, 0)));
    }

    #[test]
    fn degenerate_and_non_finite_primitives_are_never_hit() {
        let good = Primitive::Triangle([
            Vec3::new(-1.0, -1.0, 0.0),
            Vec3::new(3.0, -1.0, 0.0),
            Vec3::new(-1.0, 3.0, 0.0),
        ]);
        let prims = [
            // Zero area: collinear, a repeated vertex, a point.
            Primitive::Triangle([Vec3::ZERO, Vec3::new(0.5, 0.5, 0.5), Vec3::ONE]),
            Primitive::Triangle([Vec3::ZERO, Vec3::ZERO, Vec3::Y]),
            Primitive::Triangle([Vec3::splat(0.3); 3]),
            // Needles: long and thin, in front of the good triangle.
            Primitive::Triangle([
                Vec3::new(0.0, 0.0, 0.5),
                Vec3::new(1.0, 0.0, 0.5),
                Vec3::new(0.5, 1e-7, 0.5),
            ]),
            Primitive::Triangle([
                Vec3::new(0.0, 0.3, 0.6),
                Vec3::new(1.0, 0.3, 0.6),
                Vec3::new(0.0, 0.3, 0.6 + 1e-30),
            ]),
            // Not finite.
            Primitive::Triangle([Vec3::NAN, Vec3::X, Vec3::Y]),
            Primitive::Triangle([Vec3::INFINITY, Vec3::X, Vec3::Y]),
            Primitive::Sphere(Vec3::new(f32::NAN, 0.0, 0.0), 1.0),
            Primitive::Sphere(Vec3::ZERO, f32::INFINITY),
            good,
        ];
        let (accel, order) = Accel::build(&prims, BuildQuality::Medium);
        let mut sorted = order.clone();
        sorted.sort_unstable();
        assert_eq!(sorted, (0..prims.len() as u32).collect::<Vec<_>>());
        let mut s = 9;
        for _ in 0..5000 {
            let target = Vec3::new(lcg(&mut s), lcg(&mut s), 0.0) * 0.99;
            let o = Vec3::new(lcg(&mut s) - 0.5, lcg(&mut s) - 0.5, 2.0);
            let d = target - o;
            let hit = accel.intersect(o, d, f32::INFINITY);
            let h = hit.unwrap_or_else(|| panic!("ray to {target} missed"));
            assert!(h.t.is_finite() && h.b1.is_finite() && h.b2.is_finite());
            // Needles may be hit, and so may the collinear triangle (its
            // projection is a sliver after rounding); triangles with a
            // repeated vertex and non-finite primitives never.
            let input = order[h.prim as usize] as usize;
            assert!(matches!(input, 0 | 3 | 4 | 9), "hit primitive {input}");
            if input == 9 {
                assert!((h.t - 1.0).abs() < 1e-6);
            }
            assert!(accel.occluded(o, d, f32::INFINITY));
        }
    }

    #[test]
    fn bad_rays_hit_nothing() {
        let (accel, _) = Accel::build(
            &[
                Primitive::Triangle([-Vec3::X, Vec3::X, Vec3::Y]),
                Primitive::Sphere(Vec3::Z, 0.5),
            ],
            BuildQuality::Medium,
        );
        let (o, d) = (Vec3::new(0.0, 0.2, -1.0), Vec3::Z);
        assert!(accel.intersect(o, d, f32::INFINITY).is_some());
        for (o, d, tmax) in [
            (Vec3::NAN, d, f32::INFINITY),
            (o, Vec3::NAN, f32::INFINITY),
            (o, Vec3::ZERO, f32::INFINITY),
            (Vec3::INFINITY, -Vec3::ONE, f32::INFINITY),
            (o, d, f32::NAN),
            (o, d, 0.0),
            (o, d, -1.0),
        ] {
            assert_eq!(accel.intersect(o, d, tmax), None, "{o} {d} {tmax}");
            assert!(!accel.occluded(o, d, tmax), "{o} {d} {tmax}");
        }
    }

    #[test]
    fn axis_aligned_rays_find_flat_tiles_at_shared_edges() {
        // A plane of axis-aligned unit squares (flat boxes in every node);
        // rays straight down (two direction components zero) at every tile
        // corner and edge midpoint must hit, whatever the BVH looks like.
        let n = 12;
        let mut prims = Vec::new();
        for i in 0..n {
            for j in 0..n {
                let p = |di: i32, dj: i32| Vec3::new((i + di) as f32, (j + dj) as f32, 0.0) * 0.5;
                prims.push(Primitive::Triangle([p(0, 0), p(1, 0), p(1, 1)]));
                prims.push(Primitive::Triangle([p(0, 0), p(1, 1), p(0, 1)]));
            }
        }
        let (accel, _) = Accel::build(&prims, BuildQuality::Medium);
        for i in 0..=2 * n {
            for j in 0..=2 * n {
                let o = Vec3::new(i as f32, j as f32, 4.0) * Vec3::new(0.25, 0.25, 1.0);
                for d in [
                    -Vec3::Z,
                    Vec3::new(0.0, 1e-3, -1.0),
                    Vec3::new(-1e-3, 0.0, -1.0),
                ] {
                    let target = o + d * 4.0 / -d.z;
                    let inside = target.x >= 0.0
                        && target.y >= 0.0
                        && target.x <= 0.5 * n as f32
                        && target.y <= 0.5 * n as f32;
                    if inside {
                        let hit = accel.intersect(o, d, f32::INFINITY);
                        assert!(
                            hit.is_some(),
                            "ray down at ({}, {}) along {d} leaked",
                            o.x,
                            o.y
                        );
                        assert!(accel.occluded(o, d, f32::INFINITY));
                    }
                }
            }
        }
    }

    #[test]
    fn coincident_primitives_build_a_usable_hierarchy() {
        // Thousands of identical triangles give the builder nothing to
        // split; traversal must stay within its stack and find them.
        let tri = [Vec3::ZERO, Vec3::X, Vec3::Y];
        let mut prims = vec![Primitive::Triangle(tri); 5000];
        prims.push(Primitive::Triangle(tri.map(|v| v + Vec3::Z)));
        let (accel, order) = Accel::build(&prims, BuildQuality::High);
        let hit = accel.intersect(Vec3::new(0.2, 0.2, 2.0), -Vec3::Z, f32::INFINITY);
        assert_eq!(
            hit.map(|h| (h.t, order[h.prim as usize])),
            Some((1.0, 5000))
        );
        let hit = accel.intersect(Vec3::new(0.2, 0.2, 0.5), -Vec3::Z, f32::INFINITY);
        assert_eq!(hit.map(|h| h.t), Some(0.5));
        assert!(accel.occluded(Vec3::new(0.2, 0.2, 0.5), -Vec3::Z, 1.0));
        assert!(!accel.occluded(Vec3::new(0.2, 0.2, 0.5), Vec3::Z, 0.4));
    }
}
