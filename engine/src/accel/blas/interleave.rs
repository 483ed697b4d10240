//! Batch queries of one bottom level (a one-level scene): the rays'
//! traversals interleaved node visit by node visit ([`interleave`]). Each
//! ray gets the answer of its own traversal, bit for bit what
//! [`Blas::closest`] and [`Blas::any`] give it.

use super::{Blas, Query, Ray};
use crate::accel::interleave::{Walks, interleave};
use crate::accel::wide::{Isa, RayBoxes, Walk};
use crate::accel::{Hit, ray_is_valid};
use glam::Vec3;
use std::marker::PhantomData;

/// One ray of a one-level batch query: its query of the leaves, its
/// box-test constants and its traversal so far. A two-level query keeps
/// one for the instance a ray is in.
pub(in crate::accel) struct Lane<'a, const MOVING: bool, const SPHERES: bool> {
    pub(in crate::accel) query: Query<'a, MOVING, SPHERES>,
    pub(in crate::accel) boxes: RayBoxes,
    pub(in crate::accel) walk: Walk,
    /// Whether an any-hit walk found a hit.
    hit: bool,
}

/// Closest-hit walks of the rays `origins[i] + t·dirs[i]`, t > 0, at
/// shutter time 0.
struct ClosestWalks<'a, I, const MOVING: bool, const SPHERES: bool> {
    blas: &'a Blas,
    origins: &'a [Vec3],
    dirs: &'a [Vec3],
    isa: PhantomData<I>,
}

impl<'a, I: Isa, const MOVING: bool, const SPHERES: bool> Walks
    for ClosestWalks<'a, I, MOVING, SPHERES>
{
    type Lane = Lane<'a, MOVING, SPHERES>;
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
struct AnyWalks<'a, I, const MOVING: bool, const SPHERES: bool> {
    blas: &'a Blas,
    origins: &'a [Vec3],
    dirs: &'a [Vec3],
    tmax: f32,
    isa: PhantomData<I>,
}

impl<'a, I: Isa, const MOVING: bool, const SPHERES: bool> Walks
    for AnyWalks<'a, I, MOVING, SPHERES>
{
    type Lane = Lane<'a, MOVING, SPHERES>;
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
    /// [`WALKS`](crate::accel::interleave) rays at a time, their traversals interleaved node visit by
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
        by_flags!(self.flags(), self.closest_each_in::<I>(slots, rays, hits));
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
        let walks = ClosestWalks::<I, MOVING, SPHERES> {
            blas: self,
            origins,
            dirs,
            isa: PhantomData,
        };
        let rays = slots.iter().map(|&slot| slot as usize);
        interleave(&walks, rays, hits);
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
        by_flags!(self.flags(), self.any_each_in::<I>(rays, tmax, blocked));
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
        let walks = AnyWalks::<I, MOVING, SPHERES> {
            blas: self,
            origins,
            dirs,
            tmax,
            isa: PhantomData,
        };
        let n = blocked.len().min(origins.len()).min(dirs.len());
        interleave(&walks, 0..n, blocked);
    }

    /// An idle lane of a batch query ([`interleave`]).
    #[inline(always)]
    pub(in crate::accel) fn lane<I: Isa, const MOVING: bool, const SPHERES: bool>(
        &self,
    ) -> Lane<'_, MOVING, SPHERES> {
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
    pub(in crate::accel) fn restart<'a, I: Isa, const MOVING: bool, const SPHERES: bool>(
        &'a self,
        lane: &mut Lane<'a, MOVING, SPHERES>,
        origin: Vec3,
        dir: Vec3,
        tmax: f32,
    ) {
        let ray = Ray::new::<I>(origin, dir, 0.0);
        lane.query.restart(self, &ray);
        lane.boxes = ray.boxes;
        lane.walk.restart(tmax);
        lane.hit = false;
    }
}

#[cfg(test)]
mod tests {
    use crate::accel::tests::{lcg, object, placements, swing, two_levels};
    use crate::accel::{
        Accel, Blas, BuildQuality, Hit, Instance, InstructionSet, Place, Primitive,
    };
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

    /// Accelerators of every kind the batch queries compile for. One
    /// level: triangles alone, triangles and spheres, a deforming level
    /// (queried at shutter open), and nothing. Two levels: turned
    /// instances of triangles over static shapes, the same with a moving
    /// instance (at shutter open), and levels of which only some hold
    /// spheres (which the batches trace ray by ray).
    fn accels() -> Vec<(&'static str, Accel)> {
        let mut all = levels();
        let shape = object(9, 300);
        let tris: Vec<Primitive> = shape
            .iter()
            .filter(|p| matches!(p, Primitive::Triangle(_)))
            .copied()
            .collect();
        let statics = object(11, 200);
        let statics_tris: Vec<Primitive> = statics
            .iter()
            .filter(|p| matches!(p, Primitive::Triangle(_)))
            .copied()
            .collect();
        let places = placements(13, 40);
        let scaled: Vec<glam::DMat4> = places
            .iter()
            .map(|m| glam::DMat4::from_scale(glam::DVec3::splat(0.25)) * *m)
            .collect();
        let (blases, instances) = two_levels(&statics_tris, &tris, &scaled);
        all.push((
            "turned instances",
            Accel::new(blases, instances, BuildQuality::High),
        ));
        let (blases, mut instances) = two_levels(&statics, &shape, &scaled);
        instances.push(Instance {
            blas: 1,
            place: Place::Moving(Box::new(swing())),
        });
        all.push((
            "spheres and a moving instance",
            Accel::new(blases, instances, BuildQuality::Medium),
        ));
        let (blases, instances) = two_levels(&statics_tris, &shape, &scaled);
        all.push((
            "mixed levels",
            Accel::new(blases, instances, BuildQuality::Medium),
        ));
        all
    }

    /// The one-level accelerators of [`accels`].
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
        for (name, mut accel) in accels() {
            let mut hit_count = 0;
            for level in InstructionSet::supported() {
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
