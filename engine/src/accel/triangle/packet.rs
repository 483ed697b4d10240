//! The watertight test of one triangle against eight rays at once, the
//! rays in the lanes of an AVX register: the leaf test of a packet of
//! coherent rays (`wide::packet`).
//!
//! Each lane performs the operations of [`Tri4::test`] for its ray, in the
//! same order and without fused multiply–adds, so a lane's distance and
//! barycentrics are bitwise those of the single-ray test. The rays must
//! share their dominant axis ([`PacketPrep::new`]), which makes the axis
//! permutation the same for all lanes. The two rare cases that
//! [`Tri4::test`] decides in double precision (an edge function exactly
//! zero, a hit within the rounding error of t = 0) are not decided here:
//! such lanes are reported in [`PacketHits::redo`] for the caller to test
//! with the single-ray test.

use super::{AXES, RayPrep, Tri4, gamma};
use std::arch::x86_64::*;

/// Rays per packet.
const LANES: usize = 8;

/// Per-ray constants of the watertight test for eight rays with the same
/// dominant axis, structure-of-arrays: [`RayPrep`] lane by lane.
#[derive(Debug, Clone, Copy)]
pub struct PacketPrep {
    /// The axes that become x, y and z (the same for every lane).
    axes: [usize; 3],
    /// The origins' coordinates along the permuted axes.
    origin: [__m256; 3],
    /// The shear constants (sx, sy, sz).
    shear: [__m256; 3],
}

impl PacketPrep {
    /// Prepares the rays with origins `origin` and directions `dir`
    /// (structure-of-arrays: per axis, the eight rays' coordinates); `None`
    /// unless they have the same dominant axis (`axes_index`'s
    /// rule, ties included).
    ///
    /// # Safety
    ///
    /// The CPU must have AVX2.
    #[target_feature(enable = "avx2")]
    #[inline]
    pub fn new(origin: [__m256; 3], dir: [__m256; 3]) -> Option<Self> {
        let abs = dir.map(|d| _mm256_andnot_ps(_mm256_set1_ps(-0.0), d));
        let gt = |a: __m256, b: __m256| _mm256_movemask_ps(_mm256_cmp_ps::<_CMP_GT_OQ>(a, b));
        let (x_gt_y, y_gt_z, x_gt_z) = (gt(abs[0], abs[1]), gt(abs[1], abs[2]), gt(abs[0], abs[2]));
        // The rule of `AXES_BY_ORDER`, lane by lane: x dominates where it
        // beats both others, y where x does not beat it and it beats z.
        let is_x = x_gt_y & x_gt_z;
        let is_y = !x_gt_y & y_gt_z & 0xff;
        let dominant = match (is_x, is_y) {
            (0xff, _) => 0,
            (0, 0xff) => 1,
            (0, 0) => 2,
            _ => return None,
        };
        let axes = AXES[dominant];
        let [dx, dy, dz] = axes.map(|a| dir[a]);
        let negate = |v| _mm256_xor_ps(v, _mm256_set1_ps(-0.0));
        Some(Self {
            axes,
            origin: axes.map(|a| origin[a]),
            // The quotients of `RayPrep::new`: (−dx, −dy, 1) / dz.
            shear: [
                _mm256_div_ps(negate(dx), dz),
                _mm256_div_ps(negate(dy), dz),
                _mm256_div_ps(_mm256_set1_ps(1.0), dz),
            ],
        })
    }

    /// Lane `lane`'s [`RayPrep`], bit for bit what [`RayPrep::new`] makes
    /// of its ray.
    pub fn lane(&self, lane: usize) -> RayPrep {
        // SAFETY: an `__m256` is eight f32.
        let at = |v: &[__m256; 3]| {
            v.map(|v| unsafe { std::mem::transmute::<__m256, [f32; LANES]>(v) }[lane])
        };
        RayPrep {
            origin: at(&self.origin),
            shear: at(&self.shear),
            axes: self.axes,
        }
    }
}

/// One triangle against the eight rays of a packet.
#[derive(Debug, Clone, Copy)]
pub struct PacketHits {
    /// The lanes that hit the triangle with 0 < t < their `tmax`.
    pub hit: u32,
    /// The lanes that the single-ray test must decide (see the module).
    pub redo: u32,
    /// Each lane's distance (meaningful where it hits).
    pub t: __m256,
    /// Each lane's barycentric coordinates of vertices 1 and 2.
    pub b1: __m256,
    /// See `b1`.
    pub b2: __m256,
}

impl Tri4 {
    /// Triangle `lane` of this packet against the `active` lanes (an AVX
    /// mask) of `rays`, each within its `tmax`.
    ///
    /// # Safety
    ///
    /// The CPU must have AVX2.
    #[target_feature(enable = "avx2")]
    #[inline]
    pub fn test_rays(
        &self,
        lane: usize,
        rays: &PacketPrep,
        tmax: __m256,
        active: __m256,
    ) -> PacketHits {
        let zero = _mm256_setzero_ps();
        let splat = _mm256_set1_ps;
        let [ox, oy, oz] = rays.origin;
        let [sx, sy, sz] = rays.shear;
        // Vertex `i` translated to the rays' origins, permuted so that the
        // rays run along +z, and sheared (`Tri4::test`).
        let transform = |i: usize| {
            let p = &self.v[i];
            let [x, y, z] = rays.axes.map(|k| splat(p[k][lane]));
            let z = _mm256_sub_ps(z, oz);
            (
                _mm256_add_ps(_mm256_sub_ps(x, ox), _mm256_mul_ps(sx, z)),
                _mm256_add_ps(_mm256_sub_ps(y, oy), _mm256_mul_ps(sy, z)),
                z,
            )
        };
        let (x0, y0, z0) = transform(0);
        let (x1, y1, z1) = transform(1);
        let (x2, y2, z2) = transform(2);
        let cross = |a, b, c, d| _mm256_sub_ps(_mm256_mul_ps(a, b), _mm256_mul_ps(c, d));
        let e0 = cross(x1, y2, y1, x2);
        let e1 = cross(x2, y0, y2, x0);
        let e2 = cross(x0, y1, y0, x1);
        let eq0 = |e| _mm256_cmp_ps::<_CMP_EQ_OQ>(e, zero);
        let on_edge = _mm256_and_ps(
            _mm256_or_ps(_mm256_or_ps(eq0(e0), eq0(e1)), eq0(e2)),
            active,
        );
        let inside = _mm256_or_ps(
            _mm256_cmp_ps::<_CMP_GE_OQ>(_mm256_min_ps(_mm256_min_ps(e0, e1), e2), zero),
            _mm256_cmp_ps::<_CMP_LE_OQ>(_mm256_max_ps(_mm256_max_ps(e0, e1), e2), zero),
        );
        let det = _mm256_add_ps(_mm256_add_ps(e0, e1), e2);
        let (z0, z1, z2) = (
            _mm256_mul_ps(z0, sz),
            _mm256_mul_ps(z1, sz),
            _mm256_mul_ps(z2, sz),
        );
        let t_scaled = _mm256_add_ps(
            _mm256_add_ps(_mm256_mul_ps(e0, z0), _mm256_mul_ps(e1, z1)),
            _mm256_mul_ps(e2, z2),
        );
        let sign = _mm256_set1_ps(-0.0);
        let abs = |v| _mm256_andnot_ps(sign, v);
        let abs_det = abs(det);
        // t_scaled · copysign(1, det).
        let t_signed = _mm256_mul_ps(t_scaled, _mm256_or_ps(splat(1.0), _mm256_and_ps(det, sign)));
        let in_range = _mm256_and_ps(
            _mm256_cmp_ps::<_CMP_GT_OQ>(t_signed, zero),
            _mm256_cmp_ps::<_CMP_LE_OQ>(t_signed, _mm256_mul_ps(tmax, abs_det)),
        );
        let candidates = _mm256_andnot_ps(
            on_edge,
            _mm256_and_ps(_mm256_and_ps(inside, in_range), active),
        );
        let mut hits = PacketHits {
            hit: 0,
            redo: _mm256_movemask_ps(on_edge) as u32,
            t: zero,
            b1: zero,
            b2: zero,
        };
        if _mm256_movemask_ps(candidates) == 0 {
            return hits;
        }
        let inv_det = _mm256_div_ps(splat(1.0), det);
        let t = _mm256_mul_ps(t_scaled, inv_det);
        // Hits within the rounding error of t = 0 (`Tri4::test`).
        let g = |n| splat(gamma(n));
        let max3 = |a, b, c| _mm256_max_ps(_mm256_max_ps(abs(a), abs(b)), abs(c));
        let max_zt = max3(z0, z1, z2);
        let delta_z = _mm256_mul_ps(g(3), max_zt);
        let max_xt = max3(x0, x1, x2);
        let max_yt = max3(y0, y1, y2);
        let delta_x = _mm256_mul_ps(g(5), _mm256_add_ps(max_xt, max_zt));
        let delta_y = _mm256_mul_ps(g(5), _mm256_add_ps(max_yt, max_zt));
        let delta_e = _mm256_mul_ps(
            splat(2.0),
            _mm256_add_ps(
                _mm256_add_ps(
                    _mm256_mul_ps(_mm256_mul_ps(g(2), max_xt), max_yt),
                    _mm256_mul_ps(delta_y, max_xt),
                ),
                _mm256_mul_ps(delta_x, max_yt),
            ),
        );
        let max_e = max3(e0, e1, e2);
        let delta_t = _mm256_mul_ps(
            _mm256_mul_ps(
                splat(3.0),
                _mm256_add_ps(
                    _mm256_add_ps(
                        _mm256_mul_ps(_mm256_mul_ps(g(3), max_e), max_zt),
                        _mm256_mul_ps(delta_e, max_zt),
                    ),
                    _mm256_mul_ps(delta_z, max_e),
                ),
            ),
            abs(inv_det),
        );
        let below_tmax = _mm256_and_ps(candidates, _mm256_cmp_ps::<_CMP_LT_OQ>(t, tmax));
        let near = _mm256_and_ps(below_tmax, _mm256_cmp_ps::<_CMP_LE_OQ>(t, delta_t));
        let hit = _mm256_and_ps(below_tmax, _mm256_cmp_ps::<_CMP_GT_OQ>(t, delta_t));
        hits.hit = _mm256_movemask_ps(hit) as u32;
        hits.redo |= _mm256_movemask_ps(near) as u32;
        hits.t = t;
        hits.b1 = _mm256_mul_ps(e1, inv_det);
        hits.b2 = _mm256_mul_ps(e2, inv_det);
        hits
    }
}

#[cfg(test)]
mod tests {
    use super::super::intersect;
    use super::*;
    use crate::accel::tests::lcg;
    use glam::Vec3;

    /// Eight vectors, structure-of-arrays.
    fn soa(v: &[Vec3; LANES]) -> [__m256; 3] {
        // SAFETY: eight f32 per axis.
        [0, 1, 2].map(|a| unsafe { std::mem::transmute(v.map(|p| p[a])) })
    }

    fn lanes(v: __m256) -> [f32; LANES] {
        // SAFETY: an `__m256` is eight f32.
        unsafe { std::mem::transmute(v) }
    }

    #[test]
    fn a_packets_lanes_are_single_ray_preparations() {
        if !is_x86_feature_detected!("avx2") {
            eprintln!("no AVX2: packets are never traced on this CPU");
            return;
        }
        let mut s = 5;
        for dominant in 0..3 {
            let origins: [Vec3; LANES] =
                std::array::from_fn(|_| Vec3::new(lcg(&mut s), lcg(&mut s), lcg(&mut s)) - 0.5);
            let dirs: [Vec3; LANES] = std::array::from_fn(|_| {
                let mut d = Vec3::new(lcg(&mut s), lcg(&mut s), -lcg(&mut s)) - 0.25;
                d[dominant] = 3.0;
                d
            });
            // SAFETY: the CPU has AVX2 (checked above).
            let prep = unsafe { PacketPrep::new(soa(&origins), soa(&dirs)) }.expect("one axis");
            for lane in 0..LANES {
                let (a, b) = (prep.lane(lane), RayPrep::new(origins[lane], dirs[lane]));
                assert_eq!((a.origin, a.shear, a.axes), (b.origin, b.shear, b.axes));
            }
            let mut other = dirs;
            other[4][(dominant + 1) % 3] = 4.0;
            // SAFETY: as above.
            assert!(unsafe { PacketPrep::new(soa(&origins), soa(&other)) }.is_none());
        }
    }

    #[test]
    fn each_lane_hits_as_the_single_ray_test_does() {
        if !is_x86_feature_detected!("avx2") {
            eprintln!("no AVX2: packets are never traced on this CPU");
            return;
        }
        let mut s = 17;
        let (mut hits, mut redone) = (0, 0);
        for _ in 0..4000 {
            let tri: [Vec3; 3] = std::array::from_fn(|_| {
                Vec3::new(lcg(&mut s), lcg(&mut s), lcg(&mut s)) * 2.0 - 1.0
            });
            let tris = Tri4::new(&[tri, [Vec3::NAN; 3], [Vec3::NAN; 3], tri.map(|v| v * 2.0)]);
            let o = Vec3::new(lcg(&mut s), lcg(&mut s), 3.0 + lcg(&mut s));
            let base =
                (Vec3::new(lcg(&mut s), lcg(&mut s), 0.0) - 0.5 - o * Vec3::new(0.3, 0.3, 0.3))
                    .normalize();
            let origins = [o; LANES];
            let dirs: [Vec3; LANES] = std::array::from_fn(|_| {
                base + (Vec3::new(lcg(&mut s), lcg(&mut s), lcg(&mut s)) - 0.5) * 0.2
            });
            // SAFETY: the CPU has AVX2 (checked above).
            let Some(prep) = (unsafe { PacketPrep::new(soa(&origins), soa(&dirs)) }) else {
                continue;
            };
            let tmax: [f32; LANES] =
                std::array::from_fn(|k| if k == 5 { 2.0 } else { f32::INFINITY });
            let active = 0b1011_1111u32;
            for lane in [0, 3] {
                // SAFETY: as above; `tmax` holds eight f32.
                let got = unsafe {
                    let mask = crate::accel::wide::lane_mask(active);
                    tris.test_rays(lane, &prep, _mm256_loadu_ps(tmax.as_ptr()), mask)
                };
                for k in 0..LANES {
                    let ray = RayPrep::new(origins[k], dirs[k]);
                    let v = if lane == 0 { tri } else { tri.map(|v| v * 2.0) };
                    let expected = intersect(&ray, &v, tmax[k]);
                    let bit = 1 << k;
                    if active & bit == 0 {
                        assert_eq!(got.hit & bit, 0, "inactive lane {k} hit");
                        continue;
                    }
                    if got.redo & bit != 0 {
                        redone += 1;
                        continue;
                    }
                    match expected {
                        Some((t, b1, b2)) => {
                            hits += 1;
                            assert_ne!(got.hit & bit, 0, "lane {k} missed a hit at {t}");
                            let at = |v: __m256| lanes(v)[k];
                            assert_eq!((at(got.t), at(got.b1), at(got.b2)), (t, b1, b2));
                        }
                        None => assert_eq!(got.hit & bit, 0, "lane {k} hit nothing there"),
                    }
                }
            }
        }
        assert!(hits > 2000, "only {hits} hits");
        assert!(redone < hits / 100, "{redone} lanes redone");
    }
}
