//! Ray–sphere intersection with the precision fix of Haines et al. (Ray
//! Tracing Gems, ch. 7): the discriminant is computed from the distance of
//! the centre to the ray, not from a difference of large squares.
//!
//! A leaf's spheres are tested four at a time ([`Sphere4`]), lane by lane
//! the same operations in the same order as [`intersect`], so a sphere
//! gives the same hit in a packet as alone.

use glam::{BVec4A, Vec3, Vec4};

/// Smallest t in (0, `tmax`) where `origin + t·dir` meets the sphere.
#[inline]
pub fn intersect(origin: Vec3, dir: Vec3, centre: Vec3, radius: f32, tmax: f32) -> Option<f32> {
    let f = origin - centre;
    let a = dir.length_squared();
    let b = -f.dot(dir);
    // |f + (b/a)·dir|² is the squared distance from the centre to the line.
    let l = f + dir * (b / a);
    let disc = radius * radius - l.length_squared();
    if disc < 0.0 {
        return None;
    }
    let c = f.length_squared() - radius * radius;
    let q = b + b.signum() * (a * disc).sqrt();
    if q == 0.0 {
        return None;
    }
    let (t0, t1) = (c / q, q / a);
    let (near, far) = if t0 < t1 { (t0, t1) } else { (t1, t0) };
    if near > 0.0 && near < tmax {
        Some(near)
    } else if far > 0.0 && far < tmax {
        Some(far)
    } else {
        None
    }
}

/// Up to four spheres, structure-of-arrays (unused lanes have a NaN
/// radius, which no ray hits).
#[derive(Debug, Clone, Copy)]
pub struct Sphere4 {
    centre: [Vec4; 3],
    radius: Vec4,
}

impl Sphere4 {
    /// Packs `spheres` (centre, radius; at most four).
    pub fn new(spheres: &[(Vec3, f32)]) -> Self {
        debug_assert!(spheres.len() <= 4);
        let mut centre = [Vec4::ZERO; 3];
        let mut radius = Vec4::NAN;
        for (lane, &(c, r)) in spheres.iter().take(4).enumerate() {
            for (v, x) in centre.iter_mut().zip(c.to_array()) {
                v[lane] = x;
            }
            radius[lane] = r;
        }
        Self { centre, radius }
    }

    /// Sphere `lane`'s centre and radius.
    pub fn get(&self, lane: usize) -> (Vec3, f32) {
        let c = Vec3::new(
            self.centre[0][lane],
            self.centre[1][lane],
            self.centre[2][lane],
        );
        (c, self.radius[lane])
    }

    /// The nearest hit with 0 < t < `tmax`: (lane, t), the lowest lane
    /// among equally near ones (as testing the spheres one after the other
    /// would find).
    #[inline(always)]
    pub fn closest(&self, origin: Vec3, dir: Vec3, tmax: f32) -> Option<(usize, f32)> {
        let (hit, t) = self.test(origin, dir, tmax);
        let mut mask = hit.bitmask();
        if mask == 0 {
            return None;
        }
        let t = t.to_array();
        let mut lane = mask.trailing_zeros() as usize;
        mask &= mask - 1;
        while mask != 0 {
            let other = mask.trailing_zeros() as usize;
            mask &= mask - 1;
            if t[other] < t[lane] {
                lane = other;
            }
        }
        Some((lane, t[lane]))
    }

    /// Whether any sphere is hit with 0 < t < `tmax`.
    #[inline(always)]
    pub fn any(&self, origin: Vec3, dir: Vec3, tmax: f32) -> bool {
        self.test(origin, dir, tmax).0.any()
    }

    /// [`intersect`] on all four lanes: which are hit, and where.
    #[inline(always)]
    fn test(&self, origin: Vec3, dir: Vec3, tmax: f32) -> (BVec4A, Vec4) {
        let [cx, cy, cz] = self.centre;
        let (fx, fy, fz) = (
            Vec4::splat(origin.x) - cx,
            Vec4::splat(origin.y) - cy,
            Vec4::splat(origin.z) - cz,
        );
        let (dx, dy, dz) = (Vec4::splat(dir.x), Vec4::splat(dir.y), Vec4::splat(dir.z));
        let a = Vec4::splat(dir.length_squared());
        let b = -((fx * dx) + (fy * dy) + (fz * dz));
        let s = b / a;
        let (lx, ly, lz) = (fx + dx * s, fy + dy * s, fz + dz * s);
        let r2 = self.radius * self.radius;
        let disc = r2 - ((lx * lx) + (ly * ly) + (lz * lz));
        let c = ((fx * fx) + (fy * fy) + (fz * fz)) - r2;
        let q = b + b.signum() * (a * disc).sqrt();
        let (t0, t1) = (c / q, q / a);
        let order = t0.cmplt(t1);
        let near = Vec4::select(order, t0, t1);
        let far = Vec4::select(order, t1, t0);
        let (zero, tmax) = (Vec4::ZERO, Vec4::splat(tmax));
        let near_hit = near.cmpgt(zero) & near.cmplt(tmax);
        let far_hit = far.cmpgt(zero) & far.cmplt(tmax);
        let valid = !disc.cmplt(zero) & q.cmpne(zero);
        let t = Vec4::select(near_hit, near, far);
        (valid & (near_hit | far_hit), t)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn near_and_far_roots() {
        let t = intersect(
            Vec3::new(0.0, 0.0, -5.0),
            Vec3::Z,
            Vec3::ZERO,
            1.0,
            f32::INFINITY,
        );
        assert!((t.unwrap() - 4.0).abs() < 1e-6);
        let inside = intersect(Vec3::ZERO, Vec3::Z, Vec3::ZERO, 1.0, f32::INFINITY);
        assert!((inside.unwrap() - 1.0).abs() < 1e-6);
        assert!(
            intersect(
                Vec3::new(0.0, 2.0, -5.0),
                Vec3::Z,
                Vec3::ZERO,
                1.0,
                f32::INFINITY
            )
            .is_none()
        );
    }

    #[test]
    fn small_sphere_far_away_is_precise() {
        let centre = Vec3::new(0.0, 0.0, 1.0e4);
        let t = intersect(Vec3::ZERO, Vec3::Z, centre, 1e-2, f32::INFINITY).unwrap();
        assert!((t - (1.0e4 - 1e-2)).abs() < 2e-3, "{t}");
    }

    #[test]
    fn packed_lanes_match_single_spheres_bit_for_bit() {
        let mut s = 7u64;
        let mut r = || crate::accel::tests::lcg(&mut s) * 2.0 - 1.0;
        let mut hits = 0;
        for i in 0..20_000 {
            let n = 1 + i % 4;
            let spheres: Vec<(Vec3, f32)> = (0..n)
                .map(|_| (Vec3::new(r(), r(), r()) * 3.0, 0.05 + r().abs()))
                .collect();
            let o = Vec3::new(r(), r(), r()) * 6.0;
            // Random, axis-aligned (two zero components) and grazing rays
            // (aimed at a point on a sphere's silhouette).
            let d = match i % 3 {
                0 => Vec3::new(r(), r(), r()),
                1 => [Vec3::X, -Vec3::Y, Vec3::Z][i % 9 / 3] * (r() + 1.5),
                _ => {
                    let (c, radius) = spheres[0];
                    let to = c - o;
                    let side = to.any_orthonormal_vector() * radius;
                    to + side
                }
            };
            let tmax = if i % 5 == 0 {
                r().abs() * 4.0
            } else {
                f32::INFINITY
            };
            let packed = Sphere4::new(&spheres);
            let single = spheres
                .iter()
                .enumerate()
                .filter_map(|(lane, &(c, radius))| {
                    intersect(o, d, c, radius, tmax).map(|t| (lane, t))
                })
                .fold(None, |best: Option<(usize, f32)>, h| match best {
                    Some(b) if b.1 <= h.1 => Some(b),
                    _ => Some(h),
                });
            let got = packed.closest(o, d, tmax);
            assert_eq!(
                got.map(|(l, t)| (l, t.to_bits())),
                single.map(|(l, t)| (l, t.to_bits())),
                "ray {o} {d}, spheres {spheres:?}"
            );
            assert_eq!(packed.any(o, d, tmax), single.is_some());
            hits += usize::from(single.is_some());
        }
        assert!(hits > 2000, "only {hits} rays hit");
    }
}
