//! Batch queries of one bottom level: the traversals of two rays
//! interleaved node visit by node visit.
//!
//! A traversal is a chain of dependent loads: a node's box test decides
//! which node to load next, so a ray whose next node is not cached waits
//! for it, and a batch loop's next ray starts only when it is done. The
//! batch queries here ([`Blas::closest_each`], [`Blas::any_each`]) keep
//! [`WALKS`] rays in lanes, each with its query and its [`Walk`], and
//! step them in turn ([`interleave`]): while one ray's node is on its way
//! the other's visit runs. Each ray gets the answer of its own traversal,
//! bit for bit what [`Blas::closest`] and [`Blas::any`] give it.
//!
//! Two lanes, measured: renders of the suite's scenes (meshes that mostly
//! stay cached) run 2–4 % faster than with one ray at a time, and three or
//! four lanes' bookkeeping costs what they gain; incoherent rays and
//! scenes far larger than the caches gain more (see
//! `engine/benches/ANIMATION.md`).

use super::{Blas, Query, Ray};
use crate::accel::wide::{Isa, RayBoxes, Walk};
use crate::accel::{Hit, ray_is_valid};
use glam::Vec3;
use std::marker::PhantomData;

/// Rays a batch query traces at once.
const WALKS: usize = 2;

/// One ray of a batch query: its query of the leaves, its box-test
/// constants and its traversal so far.
struct Lane<'a, const MOVING: bool, const SPHERES: bool> {
    query: Query<'a, MOVING, SPHERES>,
    boxes: RayBoxes,
    walk: Walk,
    /// Whether an any-hit walk found a hit.
    hit: bool,
}

/// What a batch query does with its lanes ([`interleave`]).
trait Walks<'a, const MOVING: bool, const SPHERES: bool> {
    /// A ray's answer.
    type Answer;

    /// An idle lane.
    fn lane(&self) -> Lane<'a, MOVING, SPHERES>;

    /// Sets `lane` up for ray `i`; or returns the ray's answer where it
    /// needs no traversal.
    fn start(&self, lane: &mut Lane<'a, MOVING, SPHERES>, i: usize) -> Option<Self::Answer>;

    /// One node visit of `lane`'s walk; whether it goes on.
    fn step(&self, lane: &mut Lane<'a, MOVING, SPHERES>) -> bool;

    /// The answer of `lane`, whose walk is over.
    fn finish(&self, lane: &Lane<'a, MOVING, SPHERES>) -> Self::Answer;
}

/// Answers the rays `rays` into `out` with `walks`, [`WALKS`] rays at a
/// time whose traversals go one node visit each in turn: a traversal is a
/// chain of dependent loads, and while one ray waits for its next node the
/// others' visits run. Each ray gets the answer of its own traversal,
/// whatever order the rays finish in.
#[inline(always)]
fn interleave<'a, W: Walks<'a, MOVING, SPHERES>, const MOVING: bool, const SPHERES: bool>(
    walks: &W,
    mut rays: impl Iterator<Item = usize>,
    out: &mut [W::Answer],
) {
    let mut lanes: [Lane<'a, MOVING, SPHERES>; WALKS] = std::array::from_fn(|_| walks.lane());
    let mut of: [Option<usize>; WALKS] = [None; WALKS];
    let mut busy = 0;
    loop {
        for (lane, ray) in lanes.iter_mut().zip(&mut of) {
            if let Some(i) = *ray {
                if walks.step(lane) {
                    continue;
                }
                out[i] = walks.finish(lane);
                *ray = None;
                busy -= 1;
            }
            for i in rays.by_ref() {
                match walks.start(lane, i) {
                    Some(answer) => out[i] = answer,
                    None => {
                        *ray = Some(i);
                        busy += 1;
                        break;
                    }
                }
            }
        }
        if busy == 0 {
            return;
        }
    }
}

/// Closest-hit walks of the rays `origins[i] + t·dirs[i]`, t > 0, at
/// shutter time 0.
struct ClosestWalks<'a, I> {
    blas: &'a Blas,
    origins: &'a [Vec3],
    dirs: &'a [Vec3],
    isa: PhantomData<I>,
}

impl<'a, I: Isa, const MOVING: bool, const SPHERES: bool> Walks<'a, MOVING, SPHERES>
    for ClosestWalks<'a, I>
{
    type Answer = Hit;

    #[inline(always)]
    fn lane(&self) -> Lane<'a, MOVING, SPHERES> {
        self.blas.lane::<I, MOVING, SPHERES>()
    }

    #[inline(always)]
    fn start(&self, lane: &mut Lane<'a, MOVING, SPHERES>, i: usize) -> Option<Hit> {
        let (origin, dir) = (self.origins[i], self.dirs[i]);
        if !ray_is_valid(origin, dir, f32::INFINITY) {
            return Some(Hit::MISS);
        }
        self.blas
            .restart::<I, MOVING, SPHERES>(lane, origin, dir, f32::INFINITY);
        None
    }

    #[inline(always)]
    fn step(&self, lane: &mut Lane<'a, MOVING, SPHERES>) -> bool {
        let wide = &self.blas.hierarchy.wide;
        wide.closest_step::<I>(&lane.boxes, &mut lane.walk, &mut lane.query)
    }

    #[inline(always)]
    fn finish(&self, lane: &Lane<'a, MOVING, SPHERES>) -> Hit {
        lane.query.best
    }
}

/// Any-hit walks of the rays `origins[j] + t·dirs[j]`, t in (0, `tmax`),
/// at shutter time 0.
struct AnyWalks<'a, I> {
    blas: &'a Blas,
    origins: &'a [Vec3],
    dirs: &'a [Vec3],
    tmax: f32,
    isa: PhantomData<I>,
}

impl<'a, I: Isa, const MOVING: bool, const SPHERES: bool> Walks<'a, MOVING, SPHERES>
    for AnyWalks<'a, I>
{
    type Answer = bool;

    #[inline(always)]
    fn lane(&self) -> Lane<'a, MOVING, SPHERES> {
        self.blas.lane::<I, MOVING, SPHERES>()
    }

    #[inline(always)]
    fn start(&self, lane: &mut Lane<'a, MOVING, SPHERES>, j: usize) -> Option<bool> {
        let (origin, dir) = (self.origins[j], self.dirs[j]);
        if !ray_is_valid(origin, dir, self.tmax) {
            return Some(false);
        }
        self.blas
            .restart::<I, MOVING, SPHERES>(lane, origin, dir, self.tmax);
        None
    }

    #[inline(always)]
    fn step(&self, lane: &mut Lane<'a, MOVING, SPHERES>) -> bool {
        let wide = &self.blas.hierarchy.wide;
        match wide.any_step::<I>(&lane.boxes, &mut lane.walk, &mut lane.query) {
            Some(hit) => {
                lane.hit = hit;
                false
            }
            None => true,
        }
    }

    #[inline(always)]
    fn finish(&self, lane: &Lane<'a, MOVING, SPHERES>) -> bool {
        lane.hit
    }
}

impl Blas {
    /// The closest hits of the rays `origins[i] + t·dirs[i]` (t > 0) of
    /// `slots` at shutter time 0, their primitives numbered from 0, into
    /// `hits[i]` ([`Hit::MISS`] where none): [`Blas::closest`] for each,
    /// [`WALKS`] rays at a time, their traversals interleaved node visit by
    /// node visit so that one ray's cache misses overlap the others' work.
    #[inline(always)]
    pub(in crate::accel) fn closest_each<I: Isa>(
        &self,
        slots: &[u32],
        origins: &[Vec3],
        dirs: &[Vec3],
        hits: &mut [Hit],
    ) {
        if self.packets.is_empty() {
            for &slot in slots {
                hits[slot as usize] = Hit::MISS;
            }
            return;
        }
        let rays = (origins, dirs);
        by_flags!(self, closest_each_in::<I>(slots, rays, hits));
    }

    /// [`Blas::closest_each`] with the query compiled for `MOVING` and
    /// `SPHERES`.
    #[inline(always)]
    fn closest_each_in<I: Isa, const MOVING: bool, const SPHERES: bool>(
        &self,
        slots: &[u32],
        (origins, dirs): (&[Vec3], &[Vec3]),
        hits: &mut [Hit],
    ) {
        let walks = ClosestWalks::<I> {
            blas: self,
            origins,
            dirs,
            isa: PhantomData,
        };
        let rays = slots.iter().map(|&slot| slot as usize);
        interleave::<_, MOVING, SPHERES>(&walks, rays, hits);
    }

    /// Whether anything blocks each ray `origins[j] + t·dirs[j]`, t in
    /// (0, `tmax`), at shutter time 0, into `blocked[j]`: [`Blas::any`] for
    /// each, interleaved as [`Blas::closest_each`].
    #[inline(always)]
    pub(in crate::accel) fn any_each<I: Isa>(
        &self,
        origins: &[Vec3],
        dirs: &[Vec3],
        tmax: f32,
        blocked: &mut [bool],
    ) {
        if self.packets.is_empty() {
            blocked.fill(false);
            return;
        }
        let rays = (origins, dirs);
        by_flags!(self, any_each_in::<I>(rays, tmax, blocked));
    }

    /// [`Blas::any_each`] with the query compiled for `MOVING` and
    /// `SPHERES`.
    #[inline(always)]
    fn any_each_in<I: Isa, const MOVING: bool, const SPHERES: bool>(
        &self,
        (origins, dirs): (&[Vec3], &[Vec3]),
        tmax: f32,
        blocked: &mut [bool],
    ) {
        let walks = AnyWalks::<I> {
            blas: self,
            origins,
            dirs,
            tmax,
            isa: PhantomData,
        };
        let n = blocked.len().min(origins.len()).min(dirs.len());
        interleave::<_, MOVING, SPHERES>(&walks, 0..n, blocked);
    }

    /// An idle lane of a batch query ([`interleave`]).
    #[inline(always)]
    fn lane<I: Isa, const MOVING: bool, const SPHERES: bool>(&self) -> Lane<'_, MOVING, SPHERES> {
        let ray = Ray::new::<I>(Vec3::X, Vec3::X, 0.0);
        Lane {
            query: self.query::<MOVING, SPHERES>(&ray),
            boxes: ray.boxes,
            walk: Walk::new(f32::INFINITY),
            hit: false,
        }
    }

    /// Sets `lane` up for the ray `origin + t·dir` at shutter time 0 with
    /// hits within `tmax`, in place (a new lane would copy its stack).
    #[inline(always)]
    fn restart<'a, I: Isa, const MOVING: bool, const SPHERES: bool>(
        &'a self,
        lane: &mut Lane<'a, MOVING, SPHERES>,
        origin: Vec3,
        dir: Vec3,
        tmax: f32,
    ) {
        let ray = Ray::new::<I>(origin, dir, 0.0);
        lane.query = self.query::<MOVING, SPHERES>(&ray);
        lane.boxes = ray.boxes;
        lane.walk.restart(tmax);
        lane.hit = false;
    }
}

#[cfg(test)]
mod tests {
    use crate::accel::tests::{lcg, object};
    use crate::accel::{Accel, Blas, BuildQuality, Hit, Instance, Level, Place, Primitive};
    use glam::Vec3;

    /// `prims` with every triangle's vertices moved (a deforming mesh's
    /// shape at shutter close).
    fn moved(prims: &[Primitive]) -> Vec<Primitive> {
        prims
            .iter()
            .map(|p| match *p {
                Primitive::Triangle(v) => {
                    Primitive::Triangle(v.map(|p| p + Vec3::new(p.y, p.z, p.x) * 0.3))
                }
                sphere => sphere,
            })
            .collect()
    }

    /// One-level accelerators of every kind the batch queries compile
    /// for: triangles alone, triangles and spheres, a deforming level
    /// (queried at shutter open), and nothing.
    fn levels() -> Vec<(&'static str, Accel)> {
        let mixed = object(5, 3000);
        let triangles: Vec<Primitive> = mixed
            .iter()
            .filter(|p| matches!(p, Primitive::Triangle(_)))
            .copied()
            .collect();
        let one = |blas: Blas| {
            let instance = Instance {
                blas: 0,
                place: Place::Identity,
            };
            Accel::new(vec![blas], vec![instance], BuildQuality::Medium)
        };
        vec![
            (
                "triangles",
                Accel::build(&triangles, BuildQuality::Medium).0,
            ),
            (
                "triangles and spheres",
                Accel::build(&mixed, BuildQuality::High).0,
            ),
            (
                "deforming",
                one(Blas::build(
                    &mixed,
                    Some(&moved(&mixed)),
                    BuildQuality::Medium,
                )),
            ),
            ("empty", Accel::build(&[], BuildQuality::Fast).0),
        ]
    }

    /// Rays from around the objects through them, and rays no query may
    /// hit anything with (not finite, or without a direction).
    fn rays(n: usize) -> (Vec<Vec3>, Vec<Vec3>) {
        let mut s = 17;
        let (mut origins, mut dirs): (Vec<Vec3>, Vec<Vec3>) = (0..n)
            .map(|_| {
                let o = Vec3::new(lcg(&mut s), lcg(&mut s), lcg(&mut s)) * 4.0 - 2.0;
                let target = Vec3::new(lcg(&mut s), lcg(&mut s), lcg(&mut s)) * 2.0 - 1.0;
                (o, target - o)
            })
            .unzip();
        for (k, (o, d)) in [
            (Vec3::NAN, Vec3::X),
            (Vec3::ZERO, Vec3::ZERO),
            (Vec3::ZERO, Vec3::new(f32::INFINITY, 0.0, 0.0)),
            (Vec3::splat(f32::INFINITY), Vec3::Y),
        ]
        .into_iter()
        .enumerate()
        {
            origins[7 * k + 3] = o;
            dirs[7 * k + 3] = d;
        }
        (origins, dirs)
    }

    /// Each ray of a batch gets the answer it gets alone, whatever order
    /// the slots come in, and slots the batch does not name keep what they
    /// held: at every instruction set the CPU has, for closest hits and
    /// for blocked rays at several reaches.
    #[test]
    fn batched_rays_get_the_answers_of_single_rays() {
        let (origins, dirs) = rays(4000);
        // Every third ray left out; the rest backwards.
        let slots: Vec<u32> = (0..origins.len() as u32)
            .rev()
            .filter(|i| i % 3 != 1)
            .collect();
        let untouched = Hit {
            t: -1.0,
            prim: 7,
            inst: 7,
            b1: 0.5,
            b2: 0.5,
        };
        for (name, mut accel) in levels() {
            let mut hit_count = 0;
            for level in Level::supported() {
                accel.use_level(level);
                let mut hits = vec![untouched; origins.len()];
                accel.intersect_slots(&slots, &origins, &dirs, None, &mut hits);
                for (i, hit) in hits.iter().enumerate() {
                    if i % 3 == 1 {
                        assert_eq!(
                            *hit, untouched,
                            "{name}, {level:?}: ray {i} not in the batch"
                        );
                        continue;
                    }
                    let alone = accel.intersect(origins[i], dirs[i], f32::INFINITY);
                    assert_eq!(
                        *hit,
                        alone.unwrap_or(Hit::MISS),
                        "{name}, {level:?}: ray {i}"
                    );
                    hit_count += usize::from(alone.is_some());
                }
                for tmax in [f32::INFINITY, 1.0, 0.25, 0.0, f32::NAN] {
                    let mut blocked = vec![true; origins.len()];
                    accel.occluded_each(&origins, &dirs, None, tmax, &mut blocked);
                    for (i, &b) in blocked.iter().enumerate() {
                        let alone = accel.occluded(origins[i], dirs[i], tmax);
                        assert_eq!(b, alone, "{name}, {level:?}: ray {i} within {tmax}");
                    }
                }
            }
            // The batches found hits to compare (but in the empty scene).
            assert_eq!(
                hit_count > 1000,
                name != "empty",
                "{name}: {hit_count} hits"
            );
        }
    }
}
