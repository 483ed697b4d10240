//! Watertight ray–triangle intersection (Woop, Benthin and Wald 2013, as in
//! pbrt-v4): rays through shared edges and vertices hit exactly one of the
//! triangles that meet there, and hits closer than the computation's
//! rounding error are rejected.
//!
//! Triangles are tested four at a time ([`Tri4`], structure-of-arrays, one
//! triangle per SIMD lane). Each lane performs exactly the operations of
//! the one-triangle algorithm, in the same order and without fused
//! multiply–adds, so its results are bitwise those of the scalar test and
//! watertightness carries over. The ray's axis permutation only selects
//! which coordinate arrays are loaded, so it costs nothing.

#[cfg(target_arch = "x86_64")]
mod packet;

#[cfg(target_arch = "x86_64")]
pub use packet::{PacketHits, PacketPrep};

use super::wide::Isa;
use glam::{BVec4A, DVec3, Vec3, Vec3A, Vec4};

/// Per-ray constants of the watertight test.
#[derive(Debug, Clone, Copy)]
pub struct RayPrep {
    /// The origin's coordinates along the permuted axes.
    origin: [f32; 3],
    /// The shear constants (sx, sy, sz).
    shear: [f32; 3],
    /// The axes that become x, y and z: z is the direction's dominant axis,
    /// x and y follow cyclically, which keeps the triangles' winding.
    axes: [usize; 3],
}

/// [`RayPrep::axes`] by dominant axis.
const AXES: [[usize; 3]; 3] = [[1, 2, 0], [2, 0, 1], [0, 1, 2]];

/// Which of [`AXES`] is the ray's: the dominant axis of `dir` (the last
/// of equal ones but the first), chosen without branches: random
/// directions would mispredict them. The three comparisons it takes
/// (|x| > |y|, |y| > |z|, |x| > |z|) are made in one vector instruction
/// and their bits index [`AXES_BY_ORDER`].
#[inline(always)]
fn axes_index(dir: Vec3) -> usize {
    let a = Vec3A::from(dir).abs();
    let (lhs, rhs) = (Vec3A::new(a.x, a.y, a.x), Vec3A::new(a.y, a.z, a.z));
    AXES_BY_ORDER[lhs.cmpgt(rhs).bitmask() as usize & 7] as usize
}

/// [`axes_index`] by its comparisons' bits: bit 0 |x| > |y|, bit 1
/// |y| > |z|, bit 2 |x| > |z|. x dominates where it beats both, y where
/// x does not beat it and it beats z, z otherwise.
const AXES_BY_ORDER: [u8; 8] = {
    let mut table = [0u8; 8];
    let mut bits = 0;
    while bits < 8 {
        let (x_gt_y, y_gt_z, x_gt_z) = (bits & 1 != 0, bits & 2 != 0, bits & 4 != 0);
        table[bits] = if x_gt_y && x_gt_z {
            0
        } else if !x_gt_y && y_gt_z {
            1
        } else {
            2
        };
        bits += 1;
    }
    table
};

/// [`AXES`] as the lane selectors of a permutation (VPERMILPS), the
/// fourth lane kept.
#[cfg(target_arch = "x86_64")]
const PERMUTE: [[i32; 4]; 3] = [[1, 2, 0, 3], [2, 0, 1, 3], [0, 1, 2, 3]];

impl RayPrep {
    /// [`RayPrep::new`] with the instruction set `I`: with AVX2 the
    /// origin and direction are permuted in registers rather than through
    /// memory (the same values).
    #[inline(always)]
    pub fn new_with<I: Isa>(origin: Vec3, dir: Vec3) -> Self {
        #[cfg(target_arch = "x86_64")]
        if I::AVX2 {
            // SAFETY: `Avx2` traversals run only on CPUs with AVX2 (`Isa`).
            return unsafe { Self::new_avx(origin, dir) };
        }
        Self::new(origin, dir)
    }

    /// [`RayPrep::new`] by lane permutations: the origin and direction
    /// permuted by the ray's [`PERMUTE`] entry, the shear constants
    /// `(−dx, −dy, 1) / dz` in one division as there.
    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx2")]
    #[inline]
    fn new_avx(origin: Vec3, dir: Vec3) -> Self {
        use std::arch::x86_64::*;
        let k = axes_index(dir);
        // SAFETY: a `PERMUTE` entry is four i32, 16 bytes.
        let select = unsafe { _mm_loadu_si128(PERMUTE[k].as_ptr().cast()) };
        let o = _mm_permutevar_ps(Vec3A::from(origin).into(), select);
        let d = _mm_permutevar_ps(Vec3A::from(dir).into(), select);
        let dz = _mm_permute_ps::<0b10_10_10_10>(d);
        let numerator = _mm_blend_ps::<0b0100>(_mm_xor_ps(d, _mm_set1_ps(-0.0)), _mm_set1_ps(1.0));
        Self {
            origin: Vec3A::from(o).to_array(),
            shear: Vec3A::from(_mm_div_ps(numerator, dz)).to_array(),
            axes: AXES[k],
        }
    }

    /// Prepares the ray `origin + t·dir`.
    #[inline(always)]
    pub fn new(origin: Vec3, dir: Vec3) -> Self {
        let axes = AXES[axes_index(dir)];
        // Rotate the axes so that kz comes last: xyz, yzx or zxy (the
        // entries are below 3; `min` lets the compiler see it).
        let [kx, ky, kz] = axes.map(|k| k.min(2));
        let (o, d) = (origin.to_array(), dir.to_array());
        Self {
            origin: [o[kx], o[ky], o[kz]],
            // One division for all three: the same quotients as one by one.
            shear: (Vec3A::new(-d[kx], -d[ky], 1.0) / Vec3A::splat(d[kz])).to_array(),
            axes,
        }
    }
}

/// γₙ = nε/(1 − nε), the bound on the relative error of n roundings.
#[inline(always)]
const fn gamma(n: i32) -> f32 {
    let e = f32::EPSILON * 0.5;
    (n as f32 * e) / (1.0 - n as f32 * e)
}

/// Intersects a prepared ray with triangle `v`; returns (t, b1, b2) for a
/// hit with 0 < t < `tmax`.
#[inline]
pub fn intersect(ray: &RayPrep, v: &[Vec3; 3], tmax: f32) -> Option<(f32, f32, f32)> {
    Tri4::new(std::slice::from_ref(v))
        .closest(ray, tmax)
        .map(|h| (h.t, h.b1, h.b2))
}

/// Up to four triangles, structure-of-arrays: `v[i][axis]` holds that
/// coordinate of vertex `i` of each triangle. Unused lanes hold NaN, which
/// never hits.
#[derive(Debug, Clone, Copy)]
pub struct Tri4 {
    v: [[Vec4; 3]; 3],
}

/// The nearest hit in a [`Tri4`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LaneHit {
    /// Which triangle (0 to 3) was hit.
    pub lane: usize,
    /// Distance along the ray.
    pub t: f32,
    /// Barycentric coordinate of vertex 1.
    pub b1: f32,
    /// Barycentric coordinate of vertex 2.
    pub b2: f32,
}

/// What one [`Tri4`] test found: a bit per lane hit, and per lane the
/// distance, the edge functions of vertices 1 and 2, and 1/det.
struct Lanes {
    mask: u32,
    t: Vec4,
    e1: Vec4,
    e2: Vec4,
    inv_det: Vec4,
}

impl Tri4 {
    /// Packs `tris` (at most four; the rest of the lanes stay unused).
    pub fn new(tris: &[[Vec3; 3]]) -> Self {
        debug_assert!(tris.len() <= 4);
        let mut v = [[Vec4::NAN; 3]; 3];
        for (lane, tri) in tris.iter().take(4).enumerate() {
            for (vertex, p) in tri.iter().enumerate() {
                for axis in 0..3 {
                    v[vertex][axis][lane] = p[axis];
                }
            }
        }
        Self { v }
    }

    /// The triangles a fraction `s` of the way from these to `to` (vertex
    /// by vertex, linearly: a deforming mesh under motion blur). Shared
    /// vertices move identically, so the mesh stays watertight.
    #[inline(always)]
    pub fn lerp(&self, to: &Tri4, s: f32) -> Tri4 {
        let s = Vec4::splat(s);
        Tri4 {
            v: std::array::from_fn(|i| {
                std::array::from_fn(|a| self.v[i][a] + (to.v[i][a] - self.v[i][a]) * s)
            }),
        }
    }

    /// The nearest hit with 0 < t < `tmax`, if any (the lowest lane among
    /// equally near ones).
    #[inline(always)]
    pub fn closest(&self, ray: &RayPrep, tmax: f32) -> Option<LaneHit> {
        let lanes = self.test(ray, tmax);
        if lanes.mask == 0 {
            return None;
        }
        let t = lanes.t.to_array();
        let mut lane = lanes.mask.trailing_zeros() as usize;
        let mut rest = lanes.mask & (lanes.mask - 1);
        while rest != 0 {
            let other = rest.trailing_zeros() as usize;
            rest &= rest - 1;
            if t[other] < t[lane] {
                lane = other;
            }
        }
        // Arrays, not `Vec4` indexing (a jump table on the lane).
        let inv_det = lanes.inv_det.to_array()[lane];
        Some(LaneHit {
            lane,
            t: t[lane],
            b1: lanes.e1.to_array()[lane] * inv_det,
            b2: lanes.e2.to_array()[lane] * inv_det,
        })
    }

    /// Whether any triangle is hit with 0 < t < `tmax`.
    #[inline(always)]
    pub fn any(&self, ray: &RayPrep, tmax: f32) -> bool {
        self.test(ray, tmax).mask != 0
    }

    /// The watertight test on all four lanes.
    #[inline(always)]
    fn test(&self, ray: &RayPrep, tmax: f32) -> Lanes {
        // The ray's constants are read from memory at each packet
        // (volatile reads, which the compiler may not hoist): held in
        // registers through the whole traversal, as it otherwise does,
        // they crowd out the box test's constants.
        // SAFETY: reads of the ray's own fields.
        let (axes, origin, shear) = unsafe {
            let v = |x: &f32| std::ptr::read_volatile(x);
            (
                ray.axes.each_ref().map(|k| std::ptr::read_volatile(k)),
                ray.origin.each_ref().map(v),
                ray.shear.each_ref().map(v),
            )
        };
        let [ox, oy, oz] = origin.map(Vec4::splat);
        let [sx, sy, sz] = shear.map(Vec4::splat);
        // Translate to the ray origin, permute so the ray runs along +z,
        // and shear x and y (pbrt-v4 §6.5.3); z is scaled further below.
        let transform = |p: &[Vec4; 3]| {
            // SAFETY: `axes` is an entry of `AXES`, whose indices are
            // below 3.
            let [x, y, z] = axes.map(|k| unsafe { *p.get_unchecked(k) });
            let z = z - oz;
            (x - ox + sx * z, y - oy + sy * z, z)
        };
        let (x0, y0, z0) = transform(&self.v[0]);
        let (x1, y1, z1) = transform(&self.v[1]);
        let (x2, y2, z2) = transform(&self.v[2]);

        let mut e0 = x1 * y2 - y1 * x2;
        let mut e1 = x2 * y0 - y2 * x0;
        let mut e2 = x0 * y1 - y0 * x1;
        let zero = Vec4::ZERO;
        let on_edge = e0.cmpeq(zero) | e1.cmpeq(zero) | e2.cmpeq(zero);
        if on_edge.any() {
            [e0, e1, e2] = edges_in_f64(on_edge, [x0, x1, x2], [y0, y1, y2], [e0, e1, e2]);
        }
        // Inside: no edge function negative while another is positive.
        let inside = e0.min(e1).min(e2).cmpge(zero) | e0.max(e1).max(e2).cmple(zero);
        let det = e0 + e1 + e2;
        let (z0, z1, z2) = (z0 * sz, z1 * sz, z2 * sz);
        let t_scaled = e0 * z0 + e1 * z1 + e2 * z2;
        // 0 < t_scaled/det ≤ tmax, with both sides' signs flipped where
        // det < 0 (exact). A zero (degenerate triangle, ray in its plane)
        // or NaN determinant fails.
        let abs_det = det.abs();
        let t_signed = t_scaled * Vec4::ONE.copysign(det);
        let in_range = t_signed.cmpgt(zero) & t_signed.cmple(Vec4::splat(tmax) * abs_det);
        let mut hit = inside & in_range;
        let mut lanes = Lanes {
            mask: hit.bitmask(),
            t: zero,
            e1,
            e2,
            inv_det: zero,
        };
        if lanes.mask == 0 {
            return lanes;
        }
        let inv_det = Vec4::ONE / det;
        let t = t_scaled * inv_det;

        // Reject hits within the rounding error of t = 0 (pbrt-v4 §6.8.7).
        let g = |n| Vec4::splat(gamma(n));
        let max_zt = z0.abs().max(z1.abs()).max(z2.abs());
        let delta_z = g(3) * max_zt;
        let max_xt = x0.abs().max(x1.abs()).max(x2.abs());
        let max_yt = y0.abs().max(y1.abs()).max(y2.abs());
        let delta_x = g(5) * (max_xt + max_zt);
        let delta_y = g(5) * (max_yt + max_zt);
        let delta_e =
            Vec4::splat(2.0) * (g(2) * max_xt * max_yt + delta_y * max_xt + delta_x * max_yt);
        let max_e = e0.abs().max(e1.abs()).max(e2.abs());
        let delta_t = Vec4::splat(3.0)
            * (g(3) * max_e * max_zt + delta_e * max_zt + delta_z * max_e)
            * inv_det.abs();
        // `t < tmax` again after the division's rounding.
        hit &= t.cmplt(Vec4::splat(tmax));
        let near = hit & t.cmple(delta_t);
        hit &= t.cmpgt(delta_t);
        if near.any() {
            hit |= self.near_hits_in_f64(near, ray);
        }
        lanes.mask = hit.bitmask();
        lanes.t = t;
        lanes.inv_det = inv_det;
        lanes
    }
}

impl Tri4 {
    /// Decides the hits of the lanes in `near`, whose `t` came out positive
    /// but within its rounding error of zero, from the plane equation in
    /// double precision (about 2⁻²⁹ of the single-precision error). A ray
    /// leaving a surface starts beyond its error bound on the side it heads
    /// to, so the surface it leaves and coplanar neighbours lie behind it
    /// (t < 0) and are rejected, while a face really met just ahead — the
    /// adjacent face of an edge the ray starts next to — is kept.
    #[cold]
    #[inline(never)]
    fn near_hits_in_f64(&self, near: BVec4A, ray: &RayPrep) -> BVec4A {
        let [kx, ky, kz] = ray.axes.map(|k| k.min(2));
        let mut keep = [false; 4];
        let mut mask = near.bitmask();
        while mask != 0 {
            let lane = mask.trailing_zeros() as usize;
            mask &= mask - 1;
            let vertex = |i: usize| {
                let p = self.v[i];
                DVec3::new(p[kx][lane].into(), p[ky][lane].into(), p[kz][lane].into())
            };
            let (v0, v1, v2) = (vertex(0), vertex(1), vertex(2));
            let origin = DVec3::from(ray.origin.map(f64::from));
            // The ray in the permuted axes is origin + t'·(−sx, −sy, 1),
            // with t = t'·sz.
            let dir = DVec3::new(-f64::from(ray.shear[0]), -f64::from(ray.shear[1]), 1.0);
            let n = (v1 - v0).cross(v2 - v0);
            let t = (v0 - origin).dot(n) / dir.dot(n) * f64::from(ray.shear[2]);
            keep[lane] = t > 0.0;
        }
        BVec4A::new(keep[0], keep[1], keep[2], keep[3])
    }
}

/// The edge functions recomputed in double precision on the lanes of
/// `redo`, where one of them came out exactly zero in single precision.
#[cold]
#[inline(never)]
fn edges_in_f64(redo: BVec4A, x: [Vec4; 3], y: [Vec4; 3], mut e: [Vec4; 3]) -> [Vec4; 3] {
    let mut mask = redo.bitmask();
    while mask != 0 {
        let lane = mask.trailing_zeros() as usize;
        mask &= mask - 1;
        let p = |i: usize| (f64::from(x[i][lane]), f64::from(y[i][lane]));
        let cross = |(px, py): (f64, f64), (qx, qy): (f64, f64)| (px * qy - py * qx) as f32;
        e[0][lane] = cross(p(1), p(2));
        e[1][lane] = cross(p(2), p(0));
        e[2][lane] = cross(p(0), p(1));
    }
    e
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn hits_inside_and_misses_outside() {
        let tri = [Vec3::ZERO, Vec3::X, Vec3::Y];
        let ray = RayPrep::new(Vec3::new(0.25, 0.25, 1.0), -Vec3::Z);
        let (t, b1, b2) = intersect(&ray, &tri, f32::INFINITY).unwrap();
        assert!((t - 1.0).abs() < 1e-6 && (b1 - 0.25).abs() < 1e-6 && (b2 - 0.25).abs() < 1e-6);
        assert!(intersect(&ray, &tri, 0.5).is_none(), "beyond tmax");
        let miss = RayPrep::new(Vec3::new(0.75, 0.75, 1.0), -Vec3::Z);
        assert!(intersect(&miss, &tri, f32::INFINITY).is_none());
        let behind = RayPrep::new(Vec3::new(0.25, 0.25, 1.0), Vec3::Z);
        assert!(intersect(&behind, &tri, f32::INFINITY).is_none());
    }

    /// The table's dominant axis against the rule's three comparisons, on
    /// every sign and tie of a few magnitudes.
    #[test]
    fn dominant_axes_are_those_of_the_scalar_rule() {
        // The rule as three scalar comparisons, ties included.
        let scalar = |d: Vec3| {
            let a = d.abs();
            let x_gt_y = a.x > a.y;
            let is_x = x_gt_y & (a.x > a.z);
            let is_y = !x_gt_y & (a.y > a.z);
            2 - 2 * usize::from(is_x) - usize::from(is_y)
        };
        let values = [-2.0f32, -1.0, -0.5, 0.0, -0.0, 0.5, 1.0, 2.0];
        for &x in &values {
            for &y in &values {
                for &z in &values {
                    let d = Vec3::new(x, y, z);
                    assert_eq!(axes_index(d), scalar(d), "{d}");
                }
            }
        }
        assert_eq!(axes_index(Vec3::new(3.0, -1.0, 2.0)), 0);
        assert_eq!(axes_index(Vec3::new(1.0, -3.0, 2.0)), 1);
        assert_eq!(axes_index(Vec3::new(1.0, 1.0, 1.0)), 2);
    }

    /// The AVX2 preparation against the portable one, bit for bit, on
    /// random directions and on directions with equal, zero and negative
    /// components (the dominant axis's ties).
    #[test]
    fn prepared_rays_are_the_same_with_avx2() {
        #[cfg(target_arch = "x86_64")]
        if super::super::wide::Avx2::detected() {
            let mut s = 7u32;
            let mut r = || {
                s = s.wrapping_mul(1664525).wrapping_add(1013904223);
                (s >> 8) as f32 / (1 << 24) as f32 - 0.5
            };
            let mut dirs: Vec<Vec3> = (0..5000).map(|_| Vec3::new(r(), r(), r())).collect();
            for a in [-1.0, 0.0, 0.5, 1.0] {
                for b in [-1.0, 0.0, 0.5, 1.0] {
                    for c in [-1.0, 0.0, 1.0] {
                        dirs.push(Vec3::new(a, b, c));
                    }
                }
            }
            for d in dirs {
                let o = Vec3::new(r(), r(), r()) * 10.0;
                let want = RayPrep::new(o, d);
                // SAFETY: the CPU supports AVX2.
                let got = unsafe { RayPrep::new_avx(o, d) };
                assert_eq!(got.axes, want.axes, "{d}");
                assert_eq!(got.origin.map(f32::to_bits), want.origin.map(f32::to_bits));
                assert_eq!(
                    got.shear.map(f32::to_bits),
                    want.shear.map(f32::to_bits),
                    "{d}"
                );
            }
        }
    }

    #[test]
    fn packed_lanes_match_single_triangles() {
        let mut s = 1u32;
        let mut r = || {
            s = s.wrapping_mul(1664525).wrapping_add(1013904223);
            (s >> 8) as f32 / (1 << 24) as f32 - 0.5
        };
        for _ in 0..2000 {
            let tris: Vec<[Vec3; 3]> = (0..4)
                .map(|_| [(); 3].map(|_| Vec3::new(r(), r(), r())))
                .collect();
            let ray = RayPrep::new(Vec3::new(r(), r(), r()) * 4.0, Vec3::new(r(), r(), r()));
            let packed = Tri4::new(&tris).closest(&ray, f32::INFINITY);
            let single = tris
                .iter()
                .enumerate()
                .filter_map(|(lane, v)| intersect(&ray, v, f32::INFINITY).map(|h| (lane, h)))
                .min_by(|a, b| a.1.0.total_cmp(&b.1.0));
            assert_eq!(packed.map(|h| (h.lane, (h.t, h.b1, h.b2))), single);
        }
    }

    #[test]
    fn hits_within_the_error_bound_of_zero_are_decided_exactly() {
        use crate::accel::offset::{offset_origin, triangle_point};
        // The floor y = 0 and the wall x = 1 of a box, meeting at an edge
        // (normals into the box). Rays leave the floor just next to the
        // edge, heading into the wall; they must hit it, and never the
        // floor they leave or its coplanar neighbour.
        let floor = [
            [
                Vec3::new(-1.0, 0.0, -1.0),
                Vec3::new(1.0, 0.0, 1.0),
                Vec3::new(1.0, 0.0, -1.0),
            ],
            [
                Vec3::new(-1.0, 0.0, -1.0),
                Vec3::new(-1.0, 0.0, 1.0),
                Vec3::new(1.0, 0.0, 1.0),
            ],
        ];
        let wall = [
            Vec3::new(1.0, 0.0, -1.0),
            Vec3::new(1.0, 1.0, 1.0),
            Vec3::new(1.0, 0.0, 1.0),
        ];
        let mut near_misses = 0;
        for i in 0..2000 {
            let gap = 10f32.powf(-10.0 + 4.0 * (i % 100) as f32 / 100.0);
            let z = (i / 100) as f32 / 20.0 - 0.5;
            let (b1, b2) = (0.5 + z * 0.5 - gap * 0.5, 0.5 - z * 0.5 - gap * 0.5);
            let tri = floor[0];
            let b0 = 1.0 - b1 - b2;
            let (p, err) = triangle_point(&tri, b0, b1, b2);
            let dir = Vec3::new(0.1 + (i % 7) as f32 * 0.1, 1.0, 0.3).normalize();
            let origin = offset_origin(p, err, Vec3::Y, dir);
            if origin.x >= 1.0 {
                continue; // rounded onto the wall: not inside the box
            }
            let ray = RayPrep::new(origin, dir);
            for f in &floor {
                assert!(intersect(&ray, f, f32::INFINITY).is_none(), "floor re-hit");
            }
            let (t, ..) = intersect(&ray, &wall, f32::INFINITY)
                .unwrap_or_else(|| panic!("the wall is missed {} from the edge", 1.0 - origin.x));
            // Hits this close are below pbrt-v4's bound on t.
            if t < 1e-6 {
                near_misses += 1;
            }
        }
        assert!(
            near_misses > 100,
            "only {near_misses} rays tested the near case"
        );
    }

    #[test]
    fn shared_edges_and_vertices_are_watertight() {
        // A fan of triangles around the origin; rays straight at the shared
        // vertex and along shared edges must hit at least one of them.
        let n = 7;
        let tris: Vec<[Vec3; 3]> = (0..n)
            .map(|i| {
                let a0 = i as f32 / n as f32 * std::f32::consts::TAU;
                let a1 = (i + 1) as f32 / n as f32 * std::f32::consts::TAU;
                [
                    Vec3::ZERO,
                    Vec3::new(a0.cos(), a0.sin(), 0.0),
                    Vec3::new(a1.cos(), a1.sin(), 0.0),
                ]
            })
            .collect();
        let mut targets = vec![Vec3::ZERO];
        targets.extend(tris.iter().map(|t| t[1] * 0.37));
        for target in targets {
            for o in [
                Vec3::new(0.3, -0.2, 2.0),
                Vec3::new(-1.0, 0.5, 0.7),
                Vec3::new(0.0, 0.0, 5.0),
            ] {
                let d = (target - o).normalize();
                let ray = RayPrep::new(o, d);
                let hits = tris
                    .iter()
                    .filter(|t| intersect(&ray, t, f32::INFINITY).is_some())
                    .count();
                assert!(hits >= 1, "ray through {target} leaked through the mesh");
            }
        }
    }
}
