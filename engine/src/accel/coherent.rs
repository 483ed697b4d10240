//! Closest hits of coherent rays, eight at a time.
//!
//! [`Accel::intersect_coherent_slots`] takes rays in groups of eight that
//! start at about the same point and head in about the same direction (a
//! pixel's camera rays) and, where the CPU has AVX2, traces each group as
//! one packet (`wide::packet`): through the bottom level of a one-level
//! scene, or through the top level and then, instance by instance, through
//! the bottom levels of the lanes that enter each one (their rays moved to
//! the instance's space lane by lane, exactly as a single ray's are) where
//! the instance looks large enough from them to keep them together, else
//! one ray at a time (`packet_pays`). Each
//! ray gets the hit it gets alone, up to which of two primitives at
//! exactly the same distance is named. Groups that cannot share a
//! traversal, rays at shutter times, and CPUs without AVX2 take the
//! single-ray path.

use super::wide::Isa;
use super::{Accel, Hit};
use glam::Vec3;
#[cfg(target_arch = "x86_64")]
use {
    super::TopEntry,
    super::ray_is_valid,
    super::wide::{PACKET, PacketLeafVisitor, RayPacket, lanes_of},
    std::marker::PhantomData,
    std::ops::Range,
};

/// All eight lanes of a packet.
#[cfg(target_arch = "x86_64")]
const ALL_LANES: u32 = (1 << PACKET) - 1;

impl Accel {
    /// [`Self::intersect_coherent_slots`] with the instruction set `I`.
    #[inline(always)]
    pub(super) fn intersect_coherent_slots_with<I: Isa>(
        &self,
        slots: &[u32],
        origins: &[Vec3],
        dirs: &[Vec3],
        times: Option<&[f32]>,
        hits: &mut [Hit],
    ) {
        #[cfg(target_arch = "x86_64")]
        if I::AVX2 && times.is_none() {
            let mut groups = slots.chunks_exact(PACKET);
            for group in groups.by_ref() {
                let first = group[0] as usize;
                let (o, d): (&[Vec3; PACKET], &[Vec3; PACKET]);
                let copies: ([Vec3; PACKET], [Vec3; PACKET]);
                let consecutive = group
                    .iter()
                    .enumerate()
                    .all(|(k, &slot)| slot as usize == first + k);
                if consecutive {
                    // Consecutive slots (camera rays are) are read in place.
                    let eight = first..first + PACKET;
                    o = origins[eight.clone()].try_into().expect("eight rays");
                    d = dirs[eight].try_into().expect("eight rays");
                } else {
                    copies = (
                        std::array::from_fn(|k| origins[group[k] as usize]),
                        std::array::from_fn(|k| dirs[group[k] as usize]),
                    );
                    (o, d) = (&copies.0, &copies.1);
                }
                // SAFETY: `Avx2` traversals run only on CPUs with AVX2
                // (`Isa`).
                match unsafe { self.closest_packet::<I>(o, d) } {
                    Some(packet) => {
                        for (&slot, hit) in group.iter().zip(packet) {
                            hits[slot as usize] = hit;
                        }
                    }
                    None => self.intersect_slots_with::<I>(group, origins, dirs, None, hits),
                }
            }
            self.intersect_slots_with::<I>(groups.remainder(), origins, dirs, None, hits);
            return;
        }
        self.intersect_slots_with::<I>(slots, origins, dirs, times, hits);
    }

    /// The closest hits of eight rays at shutter time 0 in one traversal,
    /// or `None` where they cannot share one.
    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx2")]
    pub(super) fn closest_packet<I: Isa>(
        &self,
        origins: &[Vec3; PACKET],
        dirs: &[Vec3; PACKET],
    ) -> Option<[Hit; PACKET]> {
        let mut tmax = [f32::INFINITY; PACKET];
        if self.direct {
            // Instance 0 of bottom level 0, whose primitives start at 0.
            return self.blases[0].closest_packet(origins, dirs, ALL_LANES, &tmax, 0);
        }
        let valid = (0..PACKET).all(|i| ray_is_valid(origins[i], dirs[i], f32::INFINITY));
        if self.tlas.wide.is_empty() || !valid {
            return None;
        }
        let rays = RayPacket::new(lanes_of(origins), lanes_of(dirs))?;
        let mut query = TopPacketQuery::<I> {
            accel: self,
            origins,
            dirs,
            spread: spread(dirs),
            best: [Hit::MISS; PACKET],
            isa: PhantomData,
        };
        self.tlas
            .wide
            .closest_packet(&rays, &mut tmax, ALL_LANES, &mut query);
        Some(query.best)
    }
}

/// A packet's query of the top level: at each leaf, the lanes that reach
/// an instance enter its space and traverse its bottom level together
/// where the instance looks large from them (`packet_pays`) and they still
/// can, one by one where not.
#[cfg(target_arch = "x86_64")]
struct TopPacketQuery<'a, I> {
    accel: &'a Accel,
    origins: &'a [Vec3; PACKET],
    dirs: &'a [Vec3; PACKET],
    /// How far apart the rays head ([`spread`]).
    spread: f32,
    /// Each lane's closest hit so far.
    best: [Hit; PACKET],
    isa: PhantomData<I>,
}

#[cfg(target_arch = "x86_64")]
impl<I: Isa> TopPacketQuery<'_, I> {
    /// The rays of `lanes` against instance `entry`: lowers their `tmax`
    /// to the hits they find.
    #[target_feature(enable = "avx2")]
    fn instance(&mut self, entry: &TopEntry, lanes: u32, tmax: &mut [f32; PACKET]) {
        // Each lane's ray in the instance's space, as `TopQuery::enter`
        // moves a single ray there, with its remaining reach.
        let (mut origins, mut dirs) = (*self.origins, *self.dirs);
        let (mut shift, mut reach) = ([0.0; PACKET], [0.0; PACKET]);
        let mut entered = 0u32;
        let mut each = lanes;
        while each != 0 {
            let lane = each.trailing_zeros() as usize;
            each &= each - 1;
            let ray = self
                .accel
                .top_query::<I>(self.origins[lane], self.dirs[lane], 0.0);
            if let Some((o, d, dt)) = ray.enter(entry) {
                (origins[lane], dirs[lane]) = (o, d);
                (shift[lane], reach[lane]) = (dt, tmax[lane] - dt);
                entered |= 1 << lane;
            }
        }
        if entered == 0 {
            return;
        }
        // The other lanes ride along as copies of an entered one, so that
        // they do not keep the packet from forming.
        let first = entered.trailing_zeros() as usize;
        for lane in 0..PACKET {
            if entered & (1 << lane) == 0 {
                (origins[lane], dirs[lane]) = (origins[first], dirs[first]);
            }
        }
        let blas = &self.accel.blases[entry.blas() as usize];
        let packet = if packet_pays(blas.bounds(), origins[first], self.spread) {
            blas.closest_packet(&origins, &dirs, entered, &reach, entry.base())
        } else {
            None
        };
        let hits = packet.unwrap_or_else(|| {
            std::array::from_fn(|lane| match entered & (1 << lane) {
                0 => Hit::MISS,
                _ => blas.closest::<I>(origins[lane], dirs[lane], reach[lane], 0.0, entry.base()),
            })
        });
        let mut each = entered;
        while each != 0 {
            let lane = each.trailing_zeros() as usize;
            each &= each - 1;
            let hit = hits[lane];
            if hit.prim != Hit::MISS.prim {
                tmax[lane] = hit.t + shift[lane];
                self.best[lane] = Hit {
                    t: tmax[lane],
                    inst: entry.inst(),
                    ..hit
                };
            }
        }
    }
}

/// The largest angle (in radians, about) between the first ray's
/// direction and another's.
#[cfg(target_arch = "x86_64")]
fn spread(dirs: &[Vec3; PACKET]) -> f32 {
    let first = dirs[0].normalize_or_zero();
    dirs.iter()
        .map(|d| (d.normalize_or_zero() - first).length())
        .fold(0.0, f32::max)
}

/// An instance is entered by a packet where its bounding sphere's radius
/// is more than this many times the packet's width at the sphere's centre
/// (about its size on screen in pixels, for a pixel's camera rays).
/// Measured (`engine/benches/ANIMATION.md`, stop 28): 4 and 64 are each
/// worse on one of the field of bunnies and an instanced teapot.
#[cfg(target_arch = "x86_64")]
const PACKET_PIXELS: f32 = 16.0;

/// Whether rays leaving `origin` (in the instance's space) at most
/// `spread` apart stay together through a bottom level of bounds `bounds`:
/// where the instance looks small from the rays, they part at its first
/// nodes, and a packet visits the union of the nodes they visit apart.
/// (Rotations and uniform scales keep the ratio of size to distance and the
/// angles, so the test can run in the instance's space.)
#[cfg(target_arch = "x86_64")]
#[inline]
fn packet_pays(bounds: Option<obvhs::aabb::Aabb>, origin: Vec3, spread: f32) -> bool {
    let Some(b) = bounds else {
        return false;
    };
    let centre = Vec3::from((b.min + b.max) * 0.5);
    let radius = 0.5 * Vec3::from(b.max - b.min).length();
    radius > PACKET_PIXELS * spread * (centre - origin).length()
}

#[cfg(target_arch = "x86_64")]
impl<I: Isa> PacketLeafVisitor for TopPacketQuery<'_, I> {
    #[inline(always)]
    fn closest(&mut self, range: Range<usize>, lanes: u32, tmax: &mut [f32; PACKET]) {
        for entry in &self.accel.tlas_entries[range] {
            // SAFETY: packet traversals run only on CPUs with AVX2
            // (`Accel::closest_packet`).
            unsafe { self.instance(entry, lanes, tmax) };
        }
    }
}

#[cfg(all(test, target_arch = "x86_64"))]
mod tests {
    use super::*;
    use obvhs::aabb::Aabb;

    #[test]
    fn spread_is_the_widest_angle_from_the_first_ray() {
        let mut dirs = [Vec3::Z; PACKET];
        assert_eq!(spread(&dirs), 0.0);
        // Lengths do not count; 0.01 rad off, the chord is about 0.01.
        dirs[3] = Vec3::new(0.01f32.sin(), 0.0, 0.01f32.cos()) * 3.0;
        dirs[5] = Vec3::Z * 0.5;
        assert!((spread(&dirs) - 0.01).abs() < 1e-5, "{}", spread(&dirs));
    }

    #[test]
    fn packets_enter_instances_that_look_large_from_them() {
        let unit = Some(Aabb::new(Vec3::splat(-1.0).into(), Vec3::splat(1.0).into()));
        // Radius √3; a pixel's rays 1e-3 apart.
        let near = Vec3::new(0.0, 0.0, 10.0);
        assert!(packet_pays(unit, near, 1e-3));
        // A hundred times farther it spans about 1.7 packet widths.
        assert!(!packet_pays(unit, near * 100.0, 1e-3));
        // Identical rays always stay together; nothing to enter, never.
        assert!(packet_pays(unit, near * 1e4, 0.0));
        assert!(!packet_pays(None, near, 0.0));
    }
}
