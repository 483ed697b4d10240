//! Tests of the packet traversal of coherent rays
//! ([`Accel::intersect_coherent_slots`]) against the single-ray traversal:
//! every ray must get the hit it gets alone, bit for bit.

use super::tests::{lcg, object, placed, placements, swing, tiles, two_levels};
use super::*;

/// A random unit vector.
fn direction(s: &mut u64) -> Vec3 {
    (Vec3::new(lcg(s), lcg(s), lcg(s)) - 0.5).normalize()
}

/// The accelerator tests' random soup of triangles and spheres, scaled to
/// about [-6, 6]³.
fn soup(seed: u64, count: usize) -> Vec<Primitive> {
    placed(
        &object(seed, count),
        glam::DMat4::from_scale(glam::DVec3::splat(5.0)),
    )
}

/// Rays in groups of eight like a pixel's camera rays: one origin (or
/// eight close ones, as under a lens) and directions within `spread` of
/// one another; every fifth group eight unrelated rays.
fn pixel_rays(
    s: &mut u64,
    prims: &[Primitive],
    groups: usize,
    spread: f32,
) -> (Vec<Vec3>, Vec<Vec3>) {
    let (mut origins, mut dirs) = (Vec::new(), Vec::new());
    for g in 0..groups {
        let o = Vec3::new(lcg(s), lcg(s), lcg(s)) * 16.0 - 8.0;
        // Towards one of the primitives, so that most groups hit.
        let target = match prims[(lcg(s) * prims.len() as f32) as usize % prims.len()] {
            Primitive::Triangle([a, b, c]) => (a + b + c) / 3.0,
            Primitive::Sphere(c, _) => c,
        };
        let d = (target - o).normalize();
        for k in 0..8 {
            if g % 5 == 4 {
                origins.push(Vec3::new(lcg(s), lcg(s), lcg(s)) * 16.0 - 8.0);
                dirs.push(direction(s));
                continue;
            }
            let lens = if g % 2 == 1 {
                (Vec3::new(lcg(s), lcg(s), lcg(s)) - 0.5) * 0.1
            } else {
                Vec3::ZERO
            };
            origins.push(o + lens);
            // Unnormalised in odd lanes, as camera rays may be.
            let jitter = (Vec3::new(lcg(s), lcg(s), lcg(s)) - 0.5) * spread;
            dirs.push((d + jitter) * if k % 2 == 1 { 2.5 } else { 1.0 });
        }
    }
    (origins, dirs)
}

/// The coherent query's hits equal the single-ray query's, for every
/// instruction set, on all of `slots`; equal distances may name either
/// primitive.
fn assert_coherent_hits_match(
    accel: &mut Accel,
    slots: &[u32],
    origins: &[Vec3],
    dirs: &[Vec3],
    times: Option<&[f32]>,
) {
    for level in InstructionSet::supported() {
        accel.use_level(level);
        let mut single = vec![Hit::MISS; origins.len()];
        let mut coherent = vec![Hit::MISS; origins.len()];
        accel.intersect_slots(slots, origins, dirs, times, &mut single);
        accel.intersect_coherent_slots(slots, origins, dirs, times, &mut coherent);
        for &slot in slots {
            let (a, b) = (single[slot as usize], coherent[slot as usize]);
            if a != b {
                assert!(
                    a.t == b.t && a.prim != b.prim,
                    "{level:?}, ray {slot} ({} + t·{}): alone {a:?}, in a packet {b:?}",
                    origins[slot as usize],
                    dirs[slot as usize]
                );
            }
        }
        // Slots that were not asked for stay untouched.
        let asked: std::collections::HashSet<u32> = slots.iter().copied().collect();
        for (j, hit) in coherent.iter().enumerate() {
            if !asked.contains(&(j as u32)) {
                assert_eq!(*hit, Hit::MISS);
            }
        }
    }
}

/// How many of the groups of eight consecutive rays the packet traversal
/// takes (the others are traced one by one).
#[cfg(target_arch = "x86_64")]
fn packets_taken(accel: &Accel, origins: &[Vec3], dirs: &[Vec3]) -> usize {
    if !Avx2::detected() {
        return 0;
    }
    origins
        .chunks_exact(8)
        .zip(dirs.chunks_exact(8))
        .filter(|(o, d)| {
            let (o, d) = (
                (*o).try_into().expect("eight"),
                (*d).try_into().expect("eight"),
            );
            // SAFETY: the CPU has AVX2 (checked above).
            unsafe { accel.closest_packet::<Avx2>(o, d) }.is_some()
        })
        .count()
}

/// Where the CPU has AVX2: at least half of the groups of eight
/// consecutive rays are traced as packets, so that comparisons test the
/// packet path.
fn assert_most_groups_are_packets(accel: &Accel, origins: &[Vec3], dirs: &[Vec3]) {
    #[cfg(target_arch = "x86_64")]
    if Avx2::detected() {
        let groups = origins.len() / 8;
        let taken = packets_taken(accel, origins, dirs);
        assert!(
            taken >= groups / 2,
            "{taken} of {groups} groups traced as packets"
        );
    }
}

#[test]
fn coherent_rays_get_their_single_ray_hits_on_random_soups() {
    for (seed, count) in [(11u64, 1usize), (12, 60), (13, 3000)] {
        let prims = soup(seed, count);
        let (mut accel, _) = Accel::build(&prims, BuildQuality::Medium);
        let mut s = seed * 7;
        for spread in [0.0, 1e-3, 0.05] {
            // 301 rays: 37 groups and a remainder of five.
            let (mut origins, mut dirs) = pixel_rays(&mut s, &prims, 38, spread);
            origins.truncate(301);
            dirs.truncate(301);
            let all: Vec<u32> = (0..301).collect();
            assert_coherent_hits_match(&mut accel, &all, &origins, &dirs, None);
            // Groups that are not consecutive slots (some rays of the
            // batch already terminated), in both orders.
            let sparse: Vec<u32> = (0..301).filter(|j| j % 7 != 3).collect();
            assert_coherent_hits_match(&mut accel, &sparse, &origins, &dirs, None);
            let reversed: Vec<u32> = all.iter().rev().copied().collect();
            assert_coherent_hits_match(&mut accel, &reversed, &origins, &dirs, None);
            // Groups whose ends are eight apart but whose middles are
            // permuted or repeated: not to be read in place.
            let mut shuffled = all.clone();
            for group in shuffled.chunks_exact_mut(8).step_by(2) {
                group.swap(1, 2);
            }
            for group in shuffled.chunks_exact_mut(8).skip(1).step_by(4) {
                group[5] = group[4];
            }
            assert_coherent_hits_match(&mut accel, &shuffled, &origins, &dirs, None);
            // Most coherent groups share a traversal (those whose
            // directions straddle an axis or a dominant-axis boundary
            // cannot), so the comparison above is the packet path's.
            assert_most_groups_are_packets(&accel, &origins[..296], &dirs[..296]);
            // And the rays hit things: a comparison of misses tests little.
            if count > 1 {
                let mut hits = vec![Hit::MISS; origins.len()];
                accel.intersect_slots(&all, &origins, &dirs, None, &mut hits);
                let hit = hits.iter().filter(|h| h.prim != Hit::MISS.prim).count();
                assert!(hit >= 150, "only {hit} of 301 rays hit");
            }
        }
    }
}

#[test]
fn coherent_rays_at_shared_edges_and_from_surfaces_get_their_single_ray_hits() {
    // Rays straight down onto tile corners and edge midpoints make edge
    // functions exactly zero, and rays from points on the plane hit it
    // within rounding of t = 0: the lanes the packet test hands to the
    // single-ray test.
    let n = 12;
    let (mut accel, _) = Accel::build(&tiles(n), BuildQuality::Medium);
    let (mut origins, mut dirs) = (Vec::new(), Vec::new());
    for i in 0..=2 * n {
        for j in 0..=2 * n {
            let p = Vec3::new(i as f32, j as f32, 0.0) * 0.25;
            for k in 0..8 {
                let (o, d) = match (i + j) % 3 {
                    // Straight down, a lane or two tilted along an axis.
                    0 => (
                        p + Vec3::Z * 4.0,
                        match k {
                            1 => Vec3::new(0.0, 1e-3, -1.0),
                            2 => Vec3::new(1e-3, 0.0, -1.0),
                            // (+0, not −0: the signs of a packet agree.)
                            _ => Vec3::new(0.0, 0.0, -1.0),
                        },
                    ),
                    // From the plane itself, away from and into it.
                    1 => (
                        p + Vec3::new(0.01, 0.02, 0.0) * k as f32,
                        Vec3::new(0.1, 0.2, if i % 2 == 0 { 1.0 } else { -1.0 }),
                    ),
                    // Just above it, grazing down.
                    _ => (
                        p + Vec3::new(0.0, 0.0, 1e-6 * k as f32),
                        Vec3::new(1.0, 0.5 + 0.01 * k as f32, -1e-3),
                    ),
                };
                origins.push(o);
                dirs.push(d);
            }
        }
    }
    let all: Vec<u32> = (0..origins.len() as u32).collect();
    assert_coherent_hits_match(&mut accel, &all, &origins, &dirs, None);
    assert_most_groups_are_packets(&accel, &origins, &dirs);
    // The straight-down rays hit wherever they land inside the plane.
    let mut hits = vec![Hit::MISS; origins.len()];
    accel.intersect_coherent_slots(&all, &origins, &dirs, None, &mut hits);
    for (j, hit) in hits.iter().enumerate() {
        let (o, d) = (origins[j], dirs[j]);
        if o.z == 4.0 {
            let at = o + d * (4.0 / -d.z);
            let inside = at.x >= 0.0 && at.y >= 0.0 && at.x <= 6.0 && at.y <= 6.0;
            assert_eq!(hit.prim != Hit::MISS.prim, inside, "{o} + t·{d}");
        }
    }
}

#[test]
fn rays_that_cannot_share_a_traversal_are_traced_one_by_one() {
    let prims = soup(5, 200);
    let (mut accel, _) = Accel::build(&prims, BuildQuality::Medium);
    let base = Vec3::new(0.3, -0.4, 0.8);
    let mut s = 3;
    let mut groups: Vec<[(Vec3, Vec3); 8]> = Vec::new();
    let o = Vec3::new(-7.0, 6.0, -7.5);
    // Signs that differ in one lane, dominant axes that differ in one
    // lane, a non-finite or zero direction, a non-finite origin.
    let mut coherent = [(o, base); 8];
    coherent[3].1.x = -1e-4;
    groups.push(coherent);
    let mut coherent = [(o, base); 8];
    coherent[5].1 = Vec3::new(0.3, -0.9, 0.8);
    groups.push(coherent);
    for bad in [Vec3::NAN, Vec3::ZERO, Vec3::INFINITY] {
        let mut coherent = [(o, base); 8];
        coherent[2].1 = bad;
        groups.push(coherent);
    }
    let mut coherent = [(o, base); 8];
    coherent[7].0 = Vec3::new(f32::NAN, 0.0, 0.0);
    groups.push(coherent);
    let (mut origins, mut dirs) = (Vec::new(), Vec::new());
    for group in &groups {
        for (k, &(o, d)) in group.iter().enumerate() {
            origins.push(o);
            // The good lanes a little apart.
            dirs.push(if d.is_finite() && d != Vec3::ZERO {
                d + direction(&mut s) * 1e-4 * k as f32
            } else {
                d
            });
        }
    }
    let all: Vec<u32> = (0..origins.len() as u32).collect();
    assert_coherent_hits_match(&mut accel, &all, &origins, &dirs, None);
    #[cfg(target_arch = "x86_64")]
    if Avx2::detected() {
        for g in 0..groups.len() {
            let range = g * 8..g * 8 + 8;
            assert_eq!(
                packets_taken(&accel, &origins[range.clone()], &dirs[range]),
                0,
                "group {g}"
            );
        }
        // Without the odd lane, the same group is a packet.
        let same = [(o, base); 8];
        let (o8, d8): (Vec<Vec3>, Vec<Vec3>) = same.iter().copied().unzip();
        assert_eq!(packets_taken(&accel, &o8, &d8), 1);
    }
    // A bad ray hits nothing in a packet's company either.
    let mut hits = vec![Hit::MISS; origins.len()];
    accel.intersect_coherent_slots(&all, &origins, &dirs, None, &mut hits);
    for j in [2 * 8 + 2, 3 * 8 + 2, 4 * 8 + 2, 5 * 8 + 7] {
        assert_eq!(hits[j], Hit::MISS, "ray {j}");
    }
}

#[test]
fn coherent_rays_through_a_top_level_get_their_single_ray_hits() {
    // A shape in render space, another placed eight times (rotated and
    // scaled: a packet's rays may part ways in an instance's space) and
    // once moving (at shutter time 0 without times).
    let statics = soup(41, 300);
    let shape = object(42, 200);
    let places = placements(43, 8);
    let (mut blases, mut instances) = two_levels(&statics, &shape, &places);
    blases.push(Blas::build(&shape, None, BuildQuality::Medium));
    instances.push(Instance {
        blas: 2,
        place: Place::Moving(Box::new(swing())),
    });
    let mut two = Accel::new(blases, instances, BuildQuality::Medium);
    assert!(!two.direct);
    // Aimed at the primitives as placed.
    let mut targets = statics.clone();
    for m in &places {
        targets.extend(placed(&shape, *m));
    }
    let mut s = 31;
    for spread in [0.0, 1e-3, 0.05] {
        let (origins, dirs) = pixel_rays(&mut s, &targets, 60, spread);
        let all: Vec<u32> = (0..origins.len() as u32).collect();
        assert_coherent_hits_match(&mut two, &all, &origins, &dirs, None);
        let sparse: Vec<u32> = all.iter().copied().filter(|j| j % 5 != 1).collect();
        assert_coherent_hits_match(&mut two, &sparse, &origins, &dirs, None);
        assert_most_groups_are_packets(&two, &origins, &dirs);
        let mut hits = vec![Hit::MISS; origins.len()];
        two.intersect_coherent_slots(&all, &origins, &dirs, None, &mut hits);
        let instanced = hits
            .iter()
            .filter(|h| h.prim != Hit::MISS.prim && h.inst > 0)
            .count();
        assert!(instanced >= 50, "only {instanced} rays hit an instance");
    }
    // With shutter times, one and two levels take the single-ray path.
    let (origins, dirs) = pixel_rays(&mut s, &targets, 20, 1e-3);
    let all: Vec<u32> = (0..origins.len() as u32).collect();
    let times: Vec<f32> = (0..origins.len()).map(|_| lcg(&mut s)).collect();
    assert_coherent_hits_match(&mut two, &all, &origins, &dirs, Some(&times));
    let (mut one, _) = Accel::build(&statics, BuildQuality::Medium);
    assert_coherent_hits_match(&mut one, &all, &origins, &dirs, Some(&times));
}

#[test]
fn coherent_rays_leaving_a_tilted_surface_get_their_single_ray_hits() {
    // Rays from points on tilted triangles (rounded to f32, so a hair off
    // the plane either way), some leaving into each side: the triangle
    // they start on is hit within rounding of t = 0, which the packet test
    // leaves to the single-ray test's exact decision.
    let tilt = glam::Mat3::from_quat(glam::Quat::from_euler(glam::EulerRot::XYZ, 0.7, -0.4, 0.3));
    let prims: Vec<Primitive> = tiles(10)
        .into_iter()
        .map(|p| match p {
            Primitive::Triangle(v) => Primitive::Triangle(v.map(|v| tilt * v)),
            sphere => sphere,
        })
        .collect();
    let normal = tilt * Vec3::Z;
    let (mut accel, _) = Accel::build(&prims, BuildQuality::Medium);
    let (mut origins, mut dirs) = (Vec::new(), Vec::new());
    let mut s = 77;
    for (i, prim) in prims.iter().enumerate() {
        let Primitive::Triangle([a, b, c]) = *prim else {
            continue;
        };
        let (u, v) = (0.1 + 0.4 * lcg(&mut s), 0.1 + 0.4 * lcg(&mut s));
        let o = a + (b - a) * u + (c - a) * v;
        // A direction along the surface, and eight tilts off it, across.
        let along = (b - a).normalize();
        for k in 0..8 {
            let off = (k as f32 - 3.5) * 1e-3 * if i % 2 == 0 { 1.0 } else { 30.0 };
            origins.push(o);
            dirs.push(along + normal * off);
        }
    }
    let all: Vec<u32> = (0..origins.len() as u32).collect();
    assert_coherent_hits_match(&mut accel, &all, &origins, &dirs, None);
    assert_most_groups_are_packets(&accel, &origins, &dirs);
}

#[cfg(target_arch = "x86_64")]
#[test]
fn a_bottom_level_packet_with_some_lanes_and_reaches_gets_single_ray_hits() {
    // What an instance's bottom level gets from a top-level packet: only
    // the lanes that entered it, the others copies, each lane with its
    // own reach (some used up, one NaN).
    if !Avx2::detected() {
        eprintln!("no AVX2: packets are never traced on this CPU");
        return;
    }
    let shape = object(51, 400);
    let blas = Blas::build(&shape, None, BuildQuality::Medium);
    let mut s = 52;
    let (origins, dirs) = pixel_rays(&mut s, &shape, 80, 1e-3);
    let (mut formed, mut hit) = (0, 0);
    for (g, (o, d)) in origins
        .chunks_exact(8)
        .zip(dirs.chunks_exact(8))
        .enumerate()
    {
        let lanes: u32 = match g % 4 {
            0 => 0xff,
            1 => 0b1010_0110,
            2 => 0b0001_0000,
            _ => 0b0111_1110,
        };
        let reach: [f32; 8] = std::array::from_fn(|k| match (g + k) % 7 {
            0 => 0.0,
            1 => -1.0,
            2 => f32::NAN,
            3 => 0.5 + 4.0 * lcg(&mut s),
            _ => f32::INFINITY,
        });
        let first = lanes.trailing_zeros() as usize;
        let o: [Vec3; 8] = std::array::from_fn(|k| {
            if lanes & (1 << k) != 0 {
                o[k]
            } else {
                o[first]
            }
        });
        let d: [Vec3; 8] = std::array::from_fn(|k| {
            if lanes & (1 << k) != 0 {
                d[k]
            } else {
                d[first]
            }
        });
        // SAFETY: the CPU has AVX2 (checked above).
        let Some(hits) = (unsafe { blas.closest_packet(&o, &d, lanes, &reach, 7) }) else {
            continue;
        };
        formed += 1;
        for k in 0..8 {
            let alone = match lanes & (1 << k) {
                0 => Hit::MISS,
                _ => blas.closest::<Avx2>(o[k], d[k], reach[k], 0.0, 7),
            };
            if hits[k] != alone {
                assert!(
                    hits[k].t == alone.t && hits[k].prim != alone.prim,
                    "group {g}, lane {k}: alone {alone:?}, in a packet {:?}",
                    hits[k]
                );
            }
            hit += usize::from(alone.prim != Hit::MISS.prim);
        }
    }
    assert!(formed >= 40, "only {formed} of 80 groups formed packets");
    assert!(hit >= 60, "only {hit} lanes hit");
}
