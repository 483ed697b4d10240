//! The path integrator's medium stages: volumetric path tracing in
//! homogeneous, height-fog and grid media, run only where the frame's effects contain
//! [`Effects::MEDIA`](radiant_core::Effects) or
//! [`Effects::NULL_INTERFACE`](radiant_core::Effects).
//!
//! The wavefront (`path.rs`) calls in at four points of a bounce:
//!
//! 1. after the closest hits, [`MediumState::sample_distances`] samples a
//!    free-flight distance for every path travelling in a medium, by the
//!    medium's [`Profile`]: in closed form for uniform media
//!    ([`free_flight`]: hero channel, one-sample MIS over the channels) and
//!    for height fog (the same flight in the density integral, mapped back
//!    to a distance), by delta tracking against the majorants for density
//!    fields ([`delta_track`], random numbers from a [`Stream`] keyed by
//!    the path's distance sample).
//!    Paths that scatter before the surface leave the live list for this
//!    bounce's surface stages and come back as *medium events*: an
//!    interaction whose normal and frame lie along the ray, so that the
//!    wavefront's side tests pass for every direction and the continuation
//!    starts exactly at the event;
//! 2. events are sorted after the materials, one group per medium, and
//!    [`MediumState::shade_events`] calls each medium's phase function on
//!    its group where the shaders are called on theirs: the phase sample
//!    continues the path, its value weights next-event estimation, and MIS
//!    between phase and light sampling is the surfaces' power heuristic;
//! 3. shadow rays return a transmittance ([`MediumState::transmittance`]):
//!    they pass `null` boundaries, multiplying by the transmittance of each
//!    medium segment (closed forms, or ratio tracking for density fields,
//!    [`ratio_track`]), and stop at anything else;
//! 4. after the continuation, [`MediumState::after_bounce`] moves paths
//!    into the medium on the side they left a medium interface towards
//!    (Mitsuba 3's rule: a surface without `interior`/`exterior` leaves the
//!    medium as it is), and keeps, across `null` crossings, the last real
//!    vertex and its direction density, which MIS of emitter hits needs.
//!
//! A `null` crossing does not use up a bounce (Mitsuba 3's `volpath`):
//! each path keeps its own depth, the number of its real scattering
//! vertices (surfaces other than `null`, medium events), which `max_depth`
//! and `rr_depth` compare against ([`MediumState::retire`],
//! [`MediumState::depth`]). So that paths end in degenerate scenes, a path
//! crosses at most [`MAX_CROSSINGS`] `null` boundaries, the bound shadow
//! rays have too; the next crossing ends it (its light is lost, as a shadow
//! ray's is).

use super::surface::{Interaction, interaction};
use crate::accel::Hit;
use crate::accel::offset::offset_origin;
use crate::extract::RenderScene;
use crate::scene::media::NO_MEDIUM;
use glam::{Vec2, Vec3};
use radiant_core::medium::{
    FreeFlight, Stream, delta_track, free_flight, ratio_track, transmittance,
};
use radiant_core::{BsdfEval, BsdfSample, Coefficients, Frame, Profile, Rgb, SampleId};

/// Sampler dimensions a bounce uses in scenes with media, after the
/// surface's own: the hero channel and the distance.
pub const MEDIUM_DIMS: u32 = 2;
/// `null` boundaries a path or a shadow ray may cross: a shadow ray
/// meeting one more counts as blocked, a path meeting one more ends.
pub const MAX_CROSSINGS: u32 = 256;

/// Per-slot medium state of a wavefront and its scratch buffers.
#[derive(Default)]
pub struct MediumState {
    /// The medium each path travels in ([`NO_MEDIUM`]: vacuum).
    medium: Vec<u32>,
    /// Whether this bounce's vertex is a scattering event in a medium.
    event: Vec<bool>,
    /// The last vertex that was not a `null` crossing (light densities
    /// of emitter hits are measured from it).
    scatter_origin: Vec<Vec3>,
    /// The direction density sampled there (0: a delta lobe).
    scatter_pdf: Vec<f32>,
    /// Real scattering vertices so far (`null` crossings left out).
    depth: Vec<u32>,
    /// `null` boundaries crossed so far.
    crossings: Vec<u32>,
    /// Slots that scattered in a medium this bounce.
    events: Vec<u32>,
    // Scratch per live path.
    ids: Vec<SampleId>,
    u_channel: Vec<f32>,
    u_distance: Vec<f32>,
    u2: Vec<Vec2>,
}

impl MediumState {
    /// Puts the batch's `n` camera paths, starting at `origins`, in the
    /// camera's medium.
    pub fn start(&mut self, scene: &RenderScene, origins: &[Vec3]) {
        let n = origins.len();
        self.medium.clear();
        self.medium.resize(n, scene.media.camera);
        self.event.clear();
        self.event.resize(n, false);
        self.scatter_origin.clear();
        self.scatter_origin.extend_from_slice(origins);
        self.scatter_pdf.clear();
        self.scatter_pdf.resize(n, 0.0);
        self.depth.clear();
        self.depth.resize(n, 0);
        self.crossings.clear();
        self.crossings.resize(n, 0);
    }

    /// Each slot's path depth: its real scattering vertices so far.
    #[inline]
    pub fn depth(&self) -> &[u32] {
        &self.depth
    }

    /// Ends the paths of `live` (after the surface hits are resolved and
    /// the events rejoined) that may not scatter again: a vertex of a path
    /// at depth d is its (d + 1)-th, allowed while d + 1 < `max_depth`; a
    /// `null` crossing is allowed while the path has crossed fewer than
    /// [`MAX_CROSSINGS`]. Returns whether it ended any.
    pub fn retire(
        &self,
        scene: &RenderScene,
        live: &mut Vec<u32>,
        hits: &[Hit],
        max_depth: u32,
    ) -> bool {
        let before = live.len();
        let null = &scene.media.null;
        live.retain(|&slot| {
            let i = slot as usize;
            if !self.event[i] && null[scene.material(&hits[i]) as usize] {
                self.crossings[i] < MAX_CROSSINGS
            } else {
                self.depth[i] + 1 < max_depth
            }
        });
        live.len() != before
    }

    /// Where the light densities of `slot`'s emitter hits are measured
    /// from: its last vertex that was not a `null` crossing.
    #[inline]
    pub fn scatter_origin(&self, slot: usize) -> Vec3 {
        self.scatter_origin[slot]
    }

    /// The paths that scattered in a medium this bounce (to rejoin the live
    /// list after the surface hits are resolved).
    pub fn events(&self) -> &[u32] {
        &self.events
    }

    /// The sort group of `slot` if it is a medium event: after the
    /// `materials` shader groups, one per medium.
    #[inline]
    pub fn event_group(&self, slot: u32, materials: usize) -> Option<u32> {
        let i = slot as usize;
        self.event[i].then(|| materials as u32 + self.medium[i])
    }

    /// Samples a free-flight distance for each live path in a medium
    /// (sampler dimensions `dim`, `dim + 1`); paths that scatter before
    /// their hit get a medium interaction in `its`, leave `live` and are
    /// listed in [`MediumState::events`]. Throughputs take the free-flight
    /// weights (σs·T/pdf for events, T/P(pass) for the rest); events add
    /// the medium's emission, β·σa·Le·T/pdf, to `radiance`.
    #[allow(clippy::too_many_arguments)]
    pub fn sample_distances(
        &mut self,
        scene: &RenderScene,
        dim: u32,
        live: &mut Vec<u32>,
        ids: &[SampleId],
        ray: (&[Vec3], &[Vec3]),
        hits: &[Hit],
        (beta, radiance): (&mut [Rgb], &mut [Rgb]),
        its: &mut [Interaction],
    ) {
        let (origin, dir) = ray;
        let n = live.len();
        self.ids.clear();
        self.ids.extend(live.iter().map(|&s| ids[s as usize]));
        self.u_channel.resize(n, 0.0);
        self.u_distance.resize(n, 0.0);
        scene.sampler.fill_1d(&self.ids, dim, &mut self.u_channel);
        scene
            .sampler
            .fill_1d(&self.ids, dim + 1, &mut self.u_distance);
        self.events.clear();
        let media = &scene.media;
        let mut m = 0;
        for k in 0..n {
            let slot = live[k];
            let i = slot as usize;
            self.event[i] = false;
            let medium = self.medium[i];
            if medium == NO_MEDIUM {
                live[m] = slot;
                m += 1;
                continue;
            }
            let c = &media.coefficients[medium as usize];
            let len = dir[i].length();
            let d = dir[i] / len;
            let t_max = if hits[i].prim == Hit::MISS.prim {
                f32::INFINITY
            } else {
                hits[i].t * len
            };
            let (u_channel, u) = (self.u_channel[k], self.u_distance[k]);
            let interaction = match media.media[medium as usize].profile() {
                Profile::Uniform => {
                    let flight = free_flight(c.sigma_t(), u_channel, u, t_max);
                    flight_weights(&flight, c, &mut beta[i], &mut radiance[i]);
                    flight.scattered.then_some(flight.t)
                }
                Profile::Height(h) => {
                    // A homogeneous flight in the density integral D: the
                    // density at the event cancels out of T/pdf·σs.
                    let depth = h.integral(origin[i], d, t_max) as f32;
                    let flight = free_flight(c.sigma_t(), u_channel, u, depth);
                    flight_weights(&flight, c, &mut beta[i], &mut radiance[i]);
                    flight
                        .scattered
                        .then(|| h.inverse(origin[i], d, f64::from(flight.t)).min(t_max))
                }
                Profile::Field(field) => {
                    let id = ids[i];
                    let mut rng = Stream::new(id.pixel, id.index, dim, u.to_bits());
                    let tracked = delta_track(field, c, (origin[i], d, t_max), beta[i], &mut rng);
                    radiance[i] += tracked.emitted;
                    beta[i] = tracked.beta;
                    tracked.scattered.then_some(tracked.t)
                }
            };
            if beta[i].max_element() <= 0.0 {
                // Absorbed (or a zero weight): the path ends here.
                continue;
            }
            match interaction {
                Some(t) => {
                    its[i] = Interaction {
                        p: origin[i] + d * t,
                        err: Vec3::ZERO,
                        ng: d,
                        frame: Frame::from_normal(d),
                        uv: Vec2::ZERO,
                    };
                    self.event[i] = true;
                    self.events.push(slot);
                }
                None => {
                    live[m] = slot;
                    m += 1;
                }
            }
        }
        live.truncate(m);
    }

    /// Calls each medium's phase function on its group of events (groups
    /// after the `materials` shader groups in `offsets`): samples from
    /// `u[k].yz` into `bsdf`, evaluations towards the light samples
    /// `nee_wi` into `nee_eval` (all in the events' local frames).
    #[allow(clippy::too_many_arguments)]
    pub fn shade_events(
        &mut self,
        scene: &RenderScene,
        offsets: &[u32],
        wo: &[Vec3],
        u: &[Vec3],
        nee_wi: &[Vec3],
        bsdf: &mut [BsdfSample],
        nee_eval: &mut [BsdfEval],
    ) {
        let materials = scene.shaders.len();
        for (m, phase) in scene.media.phases.iter().enumerate() {
            let (a, b) = (
                offsets[materials + m] as usize,
                offsets[materials + m + 1] as usize,
            );
            if a == b {
                continue;
            }
            self.u2.clear();
            self.u2.extend(u[a..b].iter().map(|u| Vec2::new(u.y, u.z)));
            phase.sample(&wo[a..b], &self.u2, &mut bsdf[a..b]);
            phase.eval(&wo[a..b], &nee_wi[a..b], &mut nee_eval[a..b]);
        }
    }

    /// Multiplies each shadow ray's `values[j]` by its transmittance: the
    /// ray from `origins[j]` along `dirs[j]` (to 1 − `epsilon` of its
    /// length) of path `slots[j]`, passing `null` boundaries; zero where
    /// anything else blocks it.
    #[allow(clippy::too_many_arguments)]
    pub fn transmittance(
        &self,
        scene: &RenderScene,
        slots: &[u32],
        rays: (&[Vec3], &[Vec3]),
        times: Option<&[f32]>,
        epsilon: f32,
        surface: (&[Hit], &[Interaction]),
        values: &mut [Rgb],
    ) {
        let (origins, dirs) = rays;
        let (hits, its) = surface;
        let media = &scene.media;
        for (j, &slot) in slots.iter().enumerate() {
            let i = slot as usize;
            let start = if self.event[i] {
                self.medium[i]
            } else {
                let material = scene.material(&hits[i]);
                media.after_crossing(material, self.medium[i], dirs[j].dot(its[i].ng))
            };
            let tau = times.map_or(0.0, |t| t[j]);
            let end = origins[j] + dirs[j] * (1.0 - epsilon);
            // Ratio tracking's random numbers, keyed by the ray.
            let key = origins[j].to_array().map(f32::to_bits);
            let mut rng = Stream::new(key[0], key[1], key[2], end.x.to_bits() ^ slot);
            values[j] *= self.segment(scene, (origins[j], end), start, tau, &mut rng);
        }
    }

    /// The transmittance from `origin` to `end` starting in `medium`
    /// (ratio tracking in heterogeneous media draws from `rng`).
    fn segment(
        &self,
        scene: &RenderScene,
        (mut origin, end): (Vec3, Vec3),
        mut medium: u32,
        tau: f32,
        rng: &mut Stream,
    ) -> Rgb {
        let media = &scene.media;
        let mut tr = Rgb::ONE;
        for _ in 0..MAX_CROSSINGS {
            let d = end - origin;
            let hit = scene.accel.intersect_at(origin, d, 1.0, tau);
            if medium != NO_MEDIUM {
                let len = d.length();
                let ray = (origin, d / len, hit.map_or(1.0, |h| h.t) * len);
                let sigma_t = media.coefficients[medium as usize].sigma_t();
                tr *= match media.media[medium as usize].profile() {
                    Profile::Uniform => transmittance(sigma_t, ray.2),
                    Profile::Height(h) => {
                        transmittance(sigma_t, h.integral(ray.0, ray.1, ray.2) as f32)
                    }
                    Profile::Field(field) => ratio_track(field, sigma_t, ray, rng),
                };
                if tr.max_element() <= 0.0 {
                    return Rgb::ZERO;
                }
            }
            let Some(hit) = hit else {
                return tr;
            };
            let material = scene.material(&hit);
            if !media.null[material as usize] {
                return Rgb::ZERO;
            }
            let it = interaction(scene, &hit, origin, d, tau);
            medium = media.after_crossing(material, medium, d.dot(it.ng));
            origin = offset_origin(it.p, it.err, it.ng, d);
        }
        Rgb::ZERO
    }

    /// After the continuation of the surviving paths `live` (new directions
    /// in `dir`): paths leaving a medium interface enter the medium on the
    /// side they head to; across `null` crossings the last real vertex and
    /// its direction density (`prev_pdf`) are kept for MIS, and the path's
    /// depth stays (its crossings grow).
    pub fn after_bounce(
        &mut self,
        scene: &RenderScene,
        live: &[u32],
        surface: (&[Hit], &[Interaction]),
        dir: &[Vec3],
        prev_pdf: &mut [f32],
    ) {
        let (hits, its) = surface;
        let media = &scene.media;
        for &slot in live {
            let i = slot as usize;
            if !self.event[i] {
                let material = scene.material(&hits[i]);
                self.medium[i] =
                    media.after_crossing(material, self.medium[i], dir[i].dot(its[i].ng));
                if media.null[material as usize] {
                    prev_pdf[i] = self.scatter_pdf[i];
                    self.crossings[i] += 1;
                    continue;
                }
            }
            self.depth[i] += 1;
            self.scatter_origin[i] = its[i].p;
            self.scatter_pdf[i] = prev_pdf[i];
        }
    }
}

/// Applies a closed-form free flight's weights: σs·T/pdf (and the
/// emission β·σa·Le·T/pdf) at an event, T/P(pass) where the ray passes.
#[inline]
fn flight_weights(flight: &FreeFlight, c: &Coefficients, beta: &mut Rgb, radiance: &mut Rgb) {
    if flight.scattered {
        *radiance += *beta * flight.weight * c.sigma_a * c.emission;
        *beta *= flight.weight * c.sigma_s;
    } else {
        *beta *= flight.weight;
    }
}

/// Whether the frame runs the medium stages: it has media or `null`
/// boundaries (which shadow rays must pass even without media).
#[inline]
pub fn active(scene: &RenderScene) -> bool {
    scene
        .effects
        .intersects(radiant_core::Effects::MEDIA | radiant_core::Effects::NULL_INTERFACE)
}
