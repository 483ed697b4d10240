//! Acceleration: the BVH over all primitives and robust ray queries.
//!
//! Primitives (triangles and analytic spheres) are stored for intersection
//! in the BVH's leaf order, so a leaf's primitives are contiguous in memory
//! and a hit's primitive index addresses the shading arrays directly.
//! Triangles use the watertight test of Woop et al. 2013; spawned rays
//! start at origins offset by a conservative bound on the hit point's
//! floating-point error ([`offset`]), which keeps self-intersection away at
//! every scene scale without a fixed epsilon.

pub mod offset;
pub mod sphere;
pub mod triangle;

use glam::{Vec3, Vec3A};
use obvhs::BvhBuildParams;
use obvhs::aabb::Aabb;
use obvhs::cwbvh::CwBvh;
use obvhs::ray::{Ray, RayHit};
use std::time::Duration;
use triangle::RayPrep;

/// A primitive as the intersector sees it.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Primitive {
    /// A triangle by its vertices.
    Triangle([Vec3; 3]),
    /// A sphere by centre and radius.
    Sphere(Vec3, f32),
}

impl Primitive {
    fn aabb(&self) -> Aabb {
        match *self {
            Primitive::Triangle([a, b, c]) => {
                let a = Vec3A::from(a);
                let b = Vec3A::from(b);
                let c = Vec3A::from(c);
                Aabb::new(a.min(b).min(c), a.max(b).max(c))
            }
            Primitive::Sphere(c, r) => {
                let c = Vec3A::from(c);
                Aabb::new(c - Vec3A::splat(r), c + Vec3A::splat(r))
            }
        }
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

/// BVH quality preset.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum BuildQuality {
    /// Fast build, slower traversal.
    Fast,
    /// The default trade-off.
    #[default]
    Medium,
    /// Slow build, best traversal.
    High,
}

/// A built BVH with its primitives in leaf order.
pub struct Accel {
    bvh: CwBvh,
    prims: Vec<Primitive>,
    /// Time the build took.
    pub build_time: Duration,
}

impl Accel {
    /// Builds the BVH over `prims`; returns it and, for each BVH-order
    /// index, the index of the primitive in `prims`.
    pub fn build(prims: &[Primitive], quality: BuildQuality) -> (Self, Vec<u32>) {
        let start = std::time::Instant::now();
        let aabbs: Vec<Aabb> = prims.iter().map(Primitive::aabb).collect();
        let params = match quality {
            BuildQuality::Fast => BvhBuildParams::fast_build(),
            BuildQuality::Medium => BvhBuildParams::medium_build(),
            BuildQuality::High => BvhBuildParams::slow_build(),
        };
        let (bvh, order) = if prims.is_empty() {
            (CwBvh::default(), Vec::new())
        } else {
            let mut core = Duration::default();
            let bvh = obvhs::cwbvh::builder::build_cwbvh(&aabbs, params, &mut core);
            let order = bvh.primitive_indices.clone();
            (bvh, order)
        };
        let ordered = order.iter().map(|&i| prims[i as usize]).collect();
        (
            Self {
                bvh,
                prims: ordered,
                build_time: start.elapsed(),
            },
            order,
        )
    }

    /// The primitives, in BVH order.
    pub fn primitives(&self) -> &[Primitive] {
        &self.prims
    }

    /// Finds the closest hit along `origin + t·dir` for `t` in (0, `tmax`).
    #[inline]
    pub fn intersect(&self, origin: Vec3, dir: Vec3, tmax: f32) -> Option<Hit> {
        if self.prims.is_empty() {
            return None;
        }
        let prep = RayPrep::new(origin, dir);
        let ray = Ray::new(origin.into(), dir.into(), 0.0, tmax);
        let mut hit = RayHit::none();
        let mut best = Hit {
            t: tmax,
            prim: u32::MAX,
            b1: 0.0,
            b2: 0.0,
        };
        self.bvh.ray_traverse(ray, &mut hit, |r, id| {
            match self.prims[id] {
                Primitive::Triangle(v) => {
                    if let Some((t, b1, b2)) = triangle::intersect(&prep, &v, r.tmax) {
                        if t < best.t {
                            best = Hit {
                                t,
                                prim: id as u32,
                                b1,
                                b2,
                            };
                        }
                        return t;
                    }
                }
                Primitive::Sphere(c, radius) => {
                    if let Some(t) = sphere::intersect(origin, dir, c, radius, r.tmax) {
                        if t < best.t {
                            best = Hit {
                                t,
                                prim: id as u32,
                                b1: 0.0,
                                b2: 0.0,
                            };
                        }
                        return t;
                    }
                }
            }
            f32::INFINITY
        });
        (best.prim != u32::MAX).then_some(best)
    }

    /// Whether anything blocks `origin + t·dir` for `t` in (0, `tmax`).
    #[inline]
    pub fn occluded(&self, origin: Vec3, dir: Vec3, tmax: f32) -> bool {
        if self.prims.is_empty() {
            return false;
        }
        let prep = RayPrep::new(origin, dir);
        let ray = Ray::new(origin.into(), dir.into(), 0.0, tmax);
        !self.bvh.ray_traverse_miss(ray, |r, id| {
            let t = match self.prims[id] {
                Primitive::Triangle(v) => triangle::intersect(&prep, &v, r.tmax).map(|h| h.0),
                Primitive::Sphere(c, radius) => sphere::intersect(origin, dir, c, radius, r.tmax),
            };
            t.unwrap_or(f32::INFINITY)
        })
    }
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
}
