//! Acceleration: the BVH over all primitives and robust ray queries.
//!
//! obvhs builds a binary BVH over the primitives' boxes, which [`bvh4`]
//! collapses into the 4-wide BVH that rays traverse. Primitives (triangles
//! and analytic spheres) are numbered in its leaf order, so a leaf's
//! primitives are contiguous and a hit's primitive index addresses the
//! shading arrays directly. A leaf's triangles are stored as packets of
//! four ([`triangle::Tri4`]) and tested together with SIMD.
//!
//! Triangles use the watertight test of Woop et al. 2013. Spawned rays
//! start at origins offset by a conservative bound on the hit point's
//! floating-point error ([`offset`]), which keeps self-intersection away at
//! every scene scale without a fixed epsilon.

mod bvh4;
pub mod offset;
pub mod sphere;
pub mod triangle;

use bvh4::{Bvh4, RayBoxes};
use glam::{Vec3, Vec3A};
use obvhs::BvhBuildParams;
use obvhs::aabb::Aabb;
use std::time::Duration;
use triangle::{RayPrep, Tri4};

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

impl BuildQuality {
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
    bvh: Bvh4,
    packets: Vec<Packet>,
    prims: Vec<Primitive>,
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
            Bvh4::default()
        } else {
            let mut core_time = Duration::default();
            let bvh2 = obvhs::bvh2::builder::build_bvh2(&boxes, quality.params(), &mut core_time);
            Bvh4::build(&bvh2, |leaf| {
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
        if self.bvh.is_empty() || tmax.is_nan() || tmax <= 0.0 {
            return None;
        }
        // The triangle test's constants are made at the first leaf: many
        // rays (misses, short shadow rays) never reach one.
        let mut prep = None;
        let mut best = None;
        self.bvh
            .closest(&RayBoxes::new(origin, dir), tmax, |range, mut tmax| {
                let prep = prep.get_or_insert_with(|| RayPrep::new(origin, dir));
                for packet in &self.packets[range] {
                    match *packet {
                        Packet::Triangles { ref tris, first } => {
                            if let Some(h) = tris.closest(prep, tmax) {
                                tmax = h.t;
                                best = Some(Hit {
                                    t: h.t,
                                    prim: first + h.lane as u32,
                                    b1: h.b1,
                                    b2: h.b2,
                                });
                            }
                        }
                        Packet::Sphere {
                            centre,
                            radius,
                            prim,
                        } => {
                            if let Some(t) = hit_sphere(origin, dir, centre, radius, tmax) {
                                tmax = t;
                                best = Some(Hit {
                                    t,
                                    prim,
                                    b1: 0.0,
                                    b2: 0.0,
                                });
                            }
                        }
                    }
                }
                tmax
            });
        best
    }

    /// Whether anything blocks `origin + t·dir` for `t` in (0, `tmax`).
    #[inline]
    pub fn occluded(&self, origin: Vec3, dir: Vec3, tmax: f32) -> bool {
        if self.bvh.is_empty() || tmax.is_nan() || tmax <= 0.0 {
            return false;
        }
        let mut prep = None;
        self.bvh.any(&RayBoxes::new(origin, dir), tmax, |range| {
            let prep = prep.get_or_insert_with(|| RayPrep::new(origin, dir));
            self.packets[range].iter().any(|packet| match *packet {
                Packet::Triangles { ref tris, .. } => tris.any(prep, tmax),
                Packet::Sphere { centre, radius, .. } => {
                    hit_sphere(origin, dir, centre, radius, tmax).is_some()
                }
            })
        })
    }
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
#[cfg(test)]
mod tmp_timing {
    use super::*;
    #[test]
    fn tmp_timing() {
        let mut s = 7u64;
        let mut r = || {
            s = s
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            (s >> 40) as f32 / (1u64 << 24) as f32
        };
        let mut prims = Vec::new();
        for _ in 0..36 {
            let c = Vec3::new(r(), r(), r()) * 2.0 - 1.0;
            let mut v = || c + (Vec3::new(r(), r(), r()) - 0.5) * 0.8;
            prims.push(Primitive::Triangle([v(), v(), v()]));
        }
        let (accel, _) = Accel::build(&prims, BuildQuality::Medium);
        let rays: Vec<(Vec3, Vec3)> = (0..1_000_000)
            .map(|_| {
                (
                    Vec3::new(r(), r(), r()) * 1.8 - 0.9,
                    (Vec3::new(r(), r(), r()) - 0.5).normalize(),
                )
            })
            .collect();
        for _ in 0..3 {
            let t = std::time::Instant::now();
            let mut acc = 0.0f32;
            for (o, d) in &rays {
                let p = RayPrep::new(*o, *d);
                let b = RayBoxes::new(*o, *d);
                std::hint::black_box((p, b));
                acc += 1.0;
            }
            println!("prep: {:.1} ns {acc}", t.elapsed().as_secs_f64() * 1e3);
            let t = std::time::Instant::now();
            let mut n = 0u64;
            for (o, d) in &rays {
                let b = RayBoxes::new(*o, *d);
                accel.bvh.closest(&b, f32::INFINITY, |rg, tm| {
                    n += rg.len() as u64;
                    tm
                });
            }
            println!(
                "traverse only: {:.1} ns ({n})",
                t.elapsed().as_secs_f64() * 1e3
            );
            let t = std::time::Instant::now();
            let mut n = 0u64;
            for (o, d) in &rays {
                if accel.intersect(*o, *d, f32::INFINITY).is_some() {
                    n += 1;
                }
            }
            println!("full: {:.1} ns ({n})", t.elapsed().as_secs_f64() * 1e3);
        }
    }
}
#[cfg(test)]
mod tmp_micro {
    use super::*;
    #[test]
    fn tmp_micro() {
        let mut s = 7u64;
        let mut r = || {
            s = s
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            (s >> 40) as f32 / (1u64 << 24) as f32
        };
        let tris: Vec<[Vec3; 3]> = (0..4)
            .map(|_| {
                let c = Vec3::new(r(), r(), r()) * 2.0 - 1.0;
                let mut v = || c + (Vec3::new(r(), r(), r()) - 0.5) * 1.5;
                [v(), v(), v()]
            })
            .collect();
        let packet = Tri4::new(&tris);
        let rays: Vec<(Vec3, Vec3)> = (0..1000)
            .map(|_| {
                (
                    Vec3::new(r(), r(), r()) * 4.0 - 2.0,
                    (Vec3::new(r(), r(), r()) - 0.5).normalize(),
                )
            })
            .collect();
        let preps: Vec<RayPrep> = rays.iter().map(|(o, d)| RayPrep::new(*o, *d)).collect();
        let preps: Vec<RayPrep> = (0..1000).flat_map(|_| preps.iter().copied()).collect();
        let rays: Vec<(Vec3, Vec3)> = (0..1000).flat_map(|_| rays.iter().copied()).collect();
        for _ in 0..3 {
            let t = std::time::Instant::now();
            let mut n = 0;
            for p in preps.iter().take(1000).cycle().take(1_000_000) {
                if packet.closest(p, f32::INFINITY).is_some() {
                    n += 1;
                }
            }
            println!(
                "packet closest (independent rays): {:.1} ns ({n})",
                t.elapsed().as_secs_f64() * 1e3
            );
            let t = std::time::Instant::now();
            let mut n = 0;
            for p in preps.iter().take(1000).cycle().take(1_000_000) {
                if packet.any(p, f32::INFINITY) {
                    n += 1;
                }
            }
            println!(
                "packet any (independent rays): {:.1} ns ({n})",
                t.elapsed().as_secs_f64() * 1e3
            );
            let t = std::time::Instant::now();
            let mut tm = 0.0f32;
            for p in preps.iter().take(1000).cycle().take(1_000_000) {
                tm += packet.closest(p, f32::INFINITY).map_or(0.0, |h| h.t);
            }
            println!(
                "packet closest sum: {:.1} ns ({tm})",
                t.elapsed().as_secs_f64() * 1e3
            );
            let t = std::time::Instant::now();
            let mut n = 0;
            for (o, d) in rays.iter().take(1000).cycle().take(1_000_000) {
                let p = RayPrep::new(*o, *d);
                if packet.any(&p, f32::INFINITY) {
                    n += 1;
                }
            }
            println!(
                "prep+packet any: {:.1} ns ({n})",
                t.elapsed().as_secs_f64() * 1e3
            );
        }
    }
}
#[cfg(test)]
mod tmp_stage {
    use super::*;
    #[test]
    fn tmp_stage() {
        let scene = crate::scene::load(concat!(
            env!("CARGO_MANIFEST_DIR"),
            "/../scenes/cornell-box.yaml"
        ))
        .unwrap();
        let r = crate::extract::extract(&scene, &crate::builtin_registry(), &Default::default())
            .unwrap();
        let a = &r.accel;
        let mut s = 12345u64;
        let mut rnd = || {
            s = s
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            (s >> 40) as f32 / (1u64 << 24) as f32
        };
        let rays: Vec<(Vec3, Vec3)> = (0..1_000_000)
            .map(|_| {
                let o = Vec3::new(rnd() * 1.8 - 0.9, rnd() * 1.8 - 0.9, rnd() * 1.8 - 0.9)
                    - Vec3::new(0.0, 0.0, 3.9);
                let d = (Vec3::new(rnd() - 0.5, rnd() - 0.5, rnd() - 0.5)).normalize();
                (o, d)
            })
            .collect();
        for _ in 0..3 {
            let t = std::time::Instant::now();
            for (o, d) in &rays {
                std::hint::black_box((RayPrep::new(*o, *d), RayBoxes::new(*o, *d)));
            }
            let e0 = t.elapsed().as_secs_f64() * 1e3;
            let t = std::time::Instant::now();
            let mut n = 0u64;
            for (o, d) in &rays {
                let b = RayBoxes::new(*o, *d);
                a.bvh.closest(&b, f32::INFINITY, |rg, tm| {
                    n += rg.len() as u64;
                    tm
                });
            }
            let e1 = t.elapsed().as_secs_f64() * 1e3;
            let t = std::time::Instant::now();
            let mut n2 = 0u64;
            for (o, d) in &rays {
                let b = RayBoxes::new(*o, *d);
                a.bvh.any(&b, f32::INFINITY, |rg| {
                    n2 += rg.len() as u64;
                    false
                });
            }
            let e2 = t.elapsed().as_secs_f64() * 1e3;
            let t = std::time::Instant::now();
            let mut h = 0u64;
            for (o, d) in &rays {
                if a.intersect(*o, *d, f32::INFINITY).is_some() {
                    h += 1;
                }
            }
            let e3 = t.elapsed().as_secs_f64() * 1e3;
            let t = std::time::Instant::now();
            let mut h2 = 0u64;
            for (o, d) in &rays {
                if a.occluded(*o, *d, 0.5) {
                    h2 += 1;
                }
            }
            let e4 = t.elapsed().as_secs_f64() * 1e3;
            let same: Vec<(Vec3, Vec3)> = vec![rays[7]; 1_000_000];
            let t = std::time::Instant::now();
            let mut h3 = 0u64;
            for (o, d) in &same {
                if a.intersect(std::hint::black_box(*o), *d, f32::INFINITY)
                    .is_some()
                {
                    h3 += 1;
                }
            }
            let e5 = t.elapsed().as_secs_f64() * 1e3;
            let mut sorted = rays.clone();
            sorted.sort_by_key(|(_, d)| {
                (d.x > 0.0) as u8 * 4
                    + (d.y > 0.0) as u8 * 2
                    + (d.z > 0.0) as u8
                    + if d.x.abs() > d.y.abs() && d.x.abs() > d.z.abs() {
                        8
                    } else if d.y.abs() > d.z.abs() {
                        16
                    } else {
                        0
                    }
            });
            let t = std::time::Instant::now();
            let mut h4 = 0u64;
            for (o, d) in &sorted {
                if a.intersect(*o, *d, f32::INFINITY).is_some() {
                    h4 += 1;
                }
            }
            let e6 = t.elapsed().as_secs_f64() * 1e3;
            println!("same ray {e5:.1} ({h3}) | octant+axis sorted {e6:.1} ({h4})");
            println!(
                "prep {e0:.1} | trav-closest-noleaf {e1:.1} ({:.2} leaves) | trav-any-noleaf {e2:.1} ({:.2}) | full closest {e3:.1} ({h}) | occluded {e4:.1} ({h2})",
                n as f64 / 1e6,
                n2 as f64 / 1e6
            );
        }
    }
}
#[cfg(test)]
mod tmp_count {
    use super::*;
    #[test]
    fn tmp_count() {
        let env = |k: &str| {
            std::env::var(k)
                .ok()
                .and_then(|s| s.parse::<usize>().ok())
                .unwrap_or(0)
        };
        let (n, q, sc) = (env("TMP_N"), env("TMP_Q"), env("TMP_S"));
        let mut s = 12345u64;
        let mut rnd = || {
            s = s
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            (s >> 40) as f32 / (1u64 << 24) as f32
        };
        let owned;
        let (a, rays): (&Accel, Vec<(Vec3, Vec3, f32)>) = if sc == 0 {
            let scene = crate::scene::load(concat!(
                env!("CARGO_MANIFEST_DIR"),
                "/../scenes/cornell-box.yaml"
            ))
            .unwrap();
            owned =
                crate::extract::extract(&scene, &crate::builtin_registry(), &Default::default())
                    .unwrap()
                    .accel;
            (
                &owned,
                (0..20_000)
                    .map(|_| {
                        let o = Vec3::new(rnd() * 1.8 - 0.9, rnd() * 1.8 - 0.9, rnd() * 1.8 - 0.9)
                            - Vec3::new(0.0, 0.0, 3.9);
                        let d = (Vec3::new(rnd() - 0.5, rnd() - 0.5, rnd() - 0.5)).normalize();
                        (o, d, 0.5)
                    })
                    .collect(),
            )
        } else {
            let mesh = crate::scene::obj::load_obj(std::path::Path::new(
                "/work/shared/data/models/stanford-bunny.obj",
            ))
            .unwrap();
            let prims: Vec<Primitive> = mesh
                .triangles
                .iter()
                .map(|t| Primitive::Triangle(t.map(|i| mesh.positions[i as usize])))
                .collect();
            owned = Accel::build(&prims, BuildQuality::Medium).0;
            let (lo, hi) = mesh
                .positions
                .iter()
                .fold((Vec3::INFINITY, Vec3::NEG_INFINITY), |(lo, hi), &p| {
                    (lo.min(p), hi.max(p))
                });
            let c = (lo + hi) * 0.5;
            let r = (hi - lo).length();
            (
                &owned,
                (0..20_000)
                    .map(|_| {
                        let o = c + (Vec3::new(rnd(), rnd(), rnd()) - 0.5).normalize() * r;
                        let tg = lo + Vec3::new(rnd(), rnd(), rnd()) * (hi - lo);
                        ((o), (tg - o).normalize(), (tg - o).length())
                    })
                    .collect(),
            )
        };
        let mut h = 0;
        for &(o, d, tm) in &rays[..n] {
            match q {
                0 => {
                    if a.intersect(o, d, f32::INFINITY).is_some() {
                        h += 1
                    }
                }
                _ => {
                    if a.occluded(o, d, tm) {
                        h += 1
                    }
                }
            }
        }
        println!("{h}");
    }
}
#[cfg(test)]
mod tmp_leafstats {
    use super::*;
    #[test]
    fn tmp_leafstats() {
        let scene = crate::scene::load(concat!(
            env!("CARGO_MANIFEST_DIR"),
            "/../scenes/cornell-box.yaml"
        ))
        .unwrap();
        let a = crate::extract::extract(&scene, &crate::builtin_registry(), &Default::default())
            .unwrap()
            .accel;
        let mut s = 12345u64;
        let mut rnd = || {
            s = s
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            (s >> 40) as f32 / (1u64 << 24) as f32
        };
        let mut hist = std::collections::BTreeMap::new();
        let (mut tests, mut hits, mut leafcalls) = (0, 0, 0);
        let n = 100000;
        for _ in 0..n {
            let o = Vec3::new(rnd() * 1.8 - 0.9, rnd() * 1.8 - 0.9, rnd() * 1.8 - 0.9)
                - Vec3::new(0.0, 0.0, 3.9);
            let d = (Vec3::new(rnd() - 0.5, rnd() - 0.5, rnd() - 0.5)).normalize();
            let prep = RayPrep::new(o, d);
            let mut seq = Vec::new();
            a.bvh
                .closest(&RayBoxes::new(o, d), f32::INFINITY, |range, mut tmax| {
                    leafcalls += 1;
                    for (k, p) in a.packets[range.clone()].iter().enumerate() {
                        tests += 1;
                        if let Packet::Triangles { tris, .. } = p {
                            if let Some(h) = tris.closest(&prep, tmax) {
                                tmax = h.t;
                                hits += 1;
                                seq.push(format!("{}H", range.start + k));
                            } else {
                                seq.push(format!("{}", range.start + k));
                            }
                        }
                    }
                    tmax
                });
            *hist.entry(seq.join(",")).or_insert(0) += 1;
        }
        a.bvh.dump();
        for (i, p) in a.packets.iter().enumerate() {
            if let Packet::Triangles { first, tris } = p {
                println!("packet {i}: first prim {first} {:?}", tris);
            }
        }
        println!(
            "tests/ray {:.2} hits/ray {:.2} leafcalls/ray {:.2}",
            tests as f64 / n as f64,
            hits as f64 / n as f64,
            leafcalls as f64 / n as f64
        );
        let mut v: Vec<_> = hist.into_iter().collect();
        v.sort_by_key(|x| -x.1);
        for (k, c) in v.iter().take(25) {
            println!("{c:6} {k}");
        }
        for (i, p) in a.packets.iter().enumerate() {
            if let Packet::Triangles { first, .. } = p {
                println!("packet {i}: first prim {first}");
            }
        }
        println!("{:?}", &a.prims[..]);
    }
}
