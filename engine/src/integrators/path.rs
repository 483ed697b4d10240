//! The wavefront path tracer.
//!
//! Unidirectional path tracing with next-event estimation at every vertex
//! with a non-delta lobe, multiple importance sampling (power heuristic)
//! between BSDF and light sampling, lights chosen by `light_selection`
//! (by their bounds' importance at the shading point by default),
//! and Russian roulette driven by path throughput from `rr_depth` on —
//! the estimator of Mitsuba 3's `path` integrator, with the same
//! `max_depth` semantics (1 = emitters seen directly, 2 = direct light, …).
//! Unlike Mitsuba, whose survival probability is min(max β, 0.95), a path
//! survives with probability max β only while that is below 1 (pbrt-v4 and
//! Cycles): lossless chains through glass and mirrors are not cut at random
//! and carry no 1/0.95^k weights; unlimited paths stop at
//! [`UNLIMITED_DEPTH_CAP`] bounces.
//!
//! All paths of a batch advance together, one bounce per iteration, so the
//! bounce count is the same for every live path. Each stage is a loop over
//! the live paths' slots (structure of arrays); modules are called once per
//! group of paths that share a material or a light.

use super::buffer::Buffer;
use super::medium::{self, MEDIUM_DIMS, MediumState};
use super::shading_order::{ShadingOrder, reads_light_samples};
use super::sort::sort_by_key;
use super::surface::{
    self, Derivatives, Interaction, PREFETCH_AHEAD, interaction, interaction_with_derivatives,
};
use crate::accel::offset::{offset_origin, sampled_point_error};
use crate::accel::{Hit, Motion};
use crate::extract::{NO_EMITTER, RenderScene};
use crate::film::aov::{AovTile, FirstHit};
use crate::film::exact::BLOCK;
use crate::film::{Reconstruction, TileFilm};
use glam::{Vec2, Vec3};
use radiant_core::{
    BsdfEval, BsdfSample, CameraRays, Effects, EmitterEval, EmitterHit, LightSample, Rgb, SampleId,
    Sampler, ShadeContext, Shader, SurfaceBatch,
};

/// Sampler dimensions used by the camera (film jitter, lens); under motion
/// blur one more, the time (so a still scene's dimensions are as they were).
const CAMERA_DIMS: u32 = 4;
/// Sampler dimensions used per bounce: light choice, light point (2),
/// lobe choice, direction (2), Russian roulette, one spare.
const BOUNCE_DIMS: u32 = 8;
/// Depth at which unlimited paths (`max_depth: -1`) are cut: the end of
/// paths that lose no energy (a closed room of perfect mirrors) and of
/// scenes where Russian roulette is configured never to start.
pub const UNLIMITED_DEPTH_CAP: u32 = 16384;
/// Shadow rays stop this fraction short of the light (pbrt's ShadowEpsilon).
const SHADOW_EPSILON: f32 = 1e-4;

/// Pixels and samples one batch renders.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Batch {
    /// Pixel rectangle [x0, x1) × [y0, y1).
    pub x0: u32,
    /// See `x0`.
    pub y0: u32,
    /// See `x0`.
    pub x1: u32,
    /// See `x0`.
    pub y1: u32,
    /// First sample index.
    pub first_sample: u32,
    /// Number of samples per pixel in this batch.
    pub samples: u32,
}

/// Per-thread state of the wavefront: structure-of-arrays path state and
/// scratch buffers, reused from batch to batch (no per-ray allocation).
#[derive(Default)]
pub struct Wavefront {
    // Path state, indexed by slot.
    ids: Buffer<SampleId>,
    /// Raster positions of the camera samples.
    film: Buffer<Vec2>,
    /// Filter weights f/pdf of the samples (filter importance sampling).
    filter_weight: Buffer<f32>,
    origin: Buffer<Vec3>,
    dir: Buffer<Vec3>,
    /// Shutter time τ in [0, 1) of each path (only under motion blur).
    time: Buffer<f32>,
    beta: Buffer<Rgb>,
    /// Product of η² over the refractions so far (see [`BsdfSample::eta`]).
    eta_scale: Buffer<f32>,
    radiance: Buffer<Rgb>,
    prev_pdf: Buffer<f32>,
    hit: Buffer<Hit>,
    its: Buffer<Interaction>,
    /// Surface derivatives of the hits (only where a shader needs
    /// [`Effects::TANGENT_FRAMES`]).
    derivs: Buffer<Derivatives>,
    // Live slots, and sort scratch.
    live: Vec<u32>,
    next_live: Vec<u32>,
    scratch: Vec<u32>,
    cursor: Vec<u32>,
    offsets: Vec<u32>,
    /// The order of the material groups `offsets` delimits: those that
    /// take light samples first.
    shading: ShadingOrder,
    // Per live path in material order (index k).
    ids_k: Buffer<SampleId>,
    wo: Buffer<Vec3>,
    uv: Buffer<Vec2>,
    /// ∂p/∂u and ∂p/∂v in the local frames (only under
    /// [`Effects::TANGENT_FRAMES`]).
    dp_du: Buffer<Vec3>,
    dp_dv: Buffer<Vec3>,
    u1: Buffer<f32>,
    u2: Buffer<Vec2>,
    u3: Buffer<Vec3>,
    bsdf: Buffer<BsdfSample>,
    nee_wi: Buffer<Vec3>,
    /// `nee_wi` in world space.
    nee_wi_world: Buffer<Vec3>,
    nee_eval: Buffer<BsdfEval>,
    light: Buffer<u32>,
    light_prob: Buffer<f32>,
    light_sample: Buffer<LightSample>,
    /// Points handed to the light table: the live paths' shading points
    /// (in `live`'s order) when choosing lights, the emitter hits' ray
    /// origins when weighing those hits.
    points: Buffer<Vec3>,
    // Grouping by light.
    by_light: Vec<u32>,
    light_offsets: Vec<u32>,
    refs: Buffer<Vec3>,
    light_u: Buffer<Vec2>,
    light_out: Buffer<LightSample>,
    // Emitter hits.
    em_slots: Vec<u32>,
    em_hits: Buffer<EmitterHit>,
    em_evals: Buffer<EmitterEval>,
    /// The light of each emitter hit, and its selection probability from
    /// the hit's ray origin.
    em_light: Buffer<u32>,
    em_pmf: Buffer<f32>,
    // Rays that left the scene (environment lights).
    esc_slots: Buffer<u32>,
    esc_dirs: Buffer<Vec3>,
    esc_evals: Buffer<EmitterEval>,
    // Shadow rays.
    shadow_slot: Buffer<u32>,
    shadow_origin: Buffer<Vec3>,
    shadow_dir: Buffer<Vec3>,
    shadow_value: Buffer<Rgb>,
    /// Shutter time of each shadow ray (only under motion blur).
    shadow_time: Vec<f32>,
    /// Per shadow ray: whether something blocks it.
    shadow_blocked: Buffer<bool>,
    // Output variables (only while a batch collects them).
    /// Whether this batch records its camera rays' first hits.
    collect_aovs: bool,
    /// What each camera path's first segment found, by slot.
    first_hits: Buffer<FirstHit>,
    /// The first hits' albedos, per live path in material order.
    albedo_k: Buffer<Rgb>,
    /// Medium state (only in frames with media; see `integrators/medium.rs`).
    media: MediumState,
    /// Rays traced so far (camera, continuation and shadow rays).
    pub rays: u64,
}

/// Moves camera rays to where the camera is at each path's shutter time:
/// `motion` maps the camera's pose at the frame to its pose at τ.
fn move_camera_rays(motion: &Motion, time: &[f32], origin: &mut [Vec3], dir: &mut [Vec3]) {
    for ((o, d), &tau) in origin.iter_mut().zip(dir.iter_mut()).zip(time) {
        let m = motion.matrix(f64::from(tau));
        *o = m.transform_point3(o.as_dvec3()).as_vec3();
        *d = m.transform_vector3(d.as_dvec3()).as_vec3().normalize();
    }
}

#[inline]
fn power_heuristic(a: f32, b: f32) -> f32 {
    let (a2, b2) = (a * a, b * b);
    if a2 + b2 > 0.0 { a2 / (a2 + b2) } else { 0.0 }
}

/// MIS weight of emission found by a BSDF-sampled ray (density `bsdf_pdf`,
/// 0 for delta lobes) against light sampling with density `light_pdf`
/// (selection probability included). Camera rays (depth 0) take it whole.
#[inline]
fn bsdf_hit_weight(depth: u32, bsdf_pdf: f32, light_pdf: f32) -> f32 {
    if depth == 0 || bsdf_pdf == 0.0 {
        1.0
    } else {
        power_heuristic(bsdf_pdf, light_pdf)
    }
}

/// The shading inputs `wo`, `dp_du`, `dp_dv` (`vectors`) and `uv` of the
/// live paths `k` (material order) for `shader`: with surface derivatives
/// only where it needs tangent frames.
fn surface_batch<'a>(
    shader: &dyn Shader,
    [wo, dp_du, dp_dv]: [&'a [Vec3]; 3],
    uv: &'a [Vec2],
    k: std::ops::Range<usize>,
) -> SurfaceBatch<'a> {
    let batch = SurfaceBatch::new(wo, uv);
    if shader.effects().contains(Effects::TANGENT_FRAMES) {
        SurfaceBatch {
            dp_du,
            dp_dv,
            ..batch
        }
        .slice(k)
    } else {
        batch.slice(k)
    }
}

/// Each shader with the range of live paths (in `order`, as
/// [`sort_by_key`] leaves them with `offsets`) that it shades, where that
/// range is not empty.
fn material_ranges<'a>(
    shaders: &'a [Box<dyn Shader>],
    order: &'a ShadingOrder,
    offsets: &'a [u32],
) -> impl Iterator<Item = (&'a dyn Shader, std::ops::Range<usize>)> + 'a {
    (0..shaders.len()).filter_map(move |r| {
        let (a, b) = (offsets[r] as usize, offsets[r + 1] as usize);
        (a < b).then(|| (shaders[order.material(r)].as_ref(), a..b))
    })
}

impl Wavefront {
    /// Renders `batch` and adds its samples to `tile`.
    pub fn render(
        &mut self,
        scene: &RenderScene,
        batch: Batch,
        reconstruction: &Reconstruction,
        tile: &mut TileFilm,
    ) {
        self.render_batch(scene, batch, reconstruction, tile, None);
    }

    /// Renders `batch` as [`Wavefront::render`] does (the same samples)
    /// and also adds its camera rays' first hits to `aovs`.
    pub fn render_with_aovs(
        &mut self,
        scene: &RenderScene,
        batch: Batch,
        reconstruction: &Reconstruction,
        tile: &mut TileFilm,
        aovs: &mut AovTile,
    ) {
        self.render_batch(scene, batch, reconstruction, tile, Some(aovs));
    }

    /// The last batch's camera samples: (pixel index, value) per path.
    pub fn samples(&self) -> impl Iterator<Item = (u32, Rgb)> + '_ {
        let n = self.ids.len().min(self.radiance.len());
        self.ids[..n]
            .iter()
            .zip(&self.radiance[..n])
            .map(|(id, value)| (id.pixel, *value))
    }

    fn render_batch(
        &mut self,
        scene: &RenderScene,
        batch: Batch,
        reconstruction: &Reconstruction,
        tile: &mut TileFilm,
        aovs: Option<&mut AovTile>,
    ) {
        let n = ((batch.x1 - batch.x0) * (batch.y1 - batch.y0) * batch.samples) as usize;
        self.generate(scene, batch, n, reconstruction);
        self.collect_aovs = aovs.is_some();
        if self.collect_aovs {
            self.first_hits.zeroed(n);
        }
        if scene.settings.max_depth != 0 {
            self.trace_paths(scene, scene.sampler.as_ref());
        }
        // One sample index at a time over the batch's pixels (slots are
        // pixel-major), each block of sample indices ended into the tile's
        // exact sums: the tile's sums then do not depend on which sample
        // indices a batch holds.
        let count = batch.samples as usize;
        for (first, index) in (0..count).zip(batch.first_sample..) {
            let slots = (first..n).step_by(count);
            match reconstruction {
                Reconstruction::Splat(table) => {
                    for i in slots {
                        tile.splat(self.film[i], self.radiance[i], table);
                    }
                }
                Reconstruction::Importance(_) => {
                    let width = scene.settings.width;
                    for i in slots {
                        let pixel = self.ids[i].pixel;
                        tile.add(
                            pixel % width,
                            pixel / width,
                            self.radiance[i],
                            self.filter_weight[i],
                        );
                    }
                }
            }
            if (index + 1) % BLOCK == 0 {
                tile.end_block();
            }
        }
        if let Some(aovs) = aovs {
            aovs.add_samples(
                reconstruction,
                self.ids[..n].iter().map(|id| id.pixel),
                &self.film[..n],
                &self.filter_weight,
                &self.first_hits[..n],
            );
        }
    }

    fn generate(
        &mut self,
        scene: &RenderScene,
        b: Batch,
        n: usize,
        reconstruction: &Reconstruction,
    ) {
        let width = scene.settings.width;
        self.ids.fit(n);
        let mut ids = self.ids.iter_mut();
        for y in b.y0..b.y1 {
            for x in b.x0..b.x1 {
                let samples = b.first_sample..b.first_sample + b.samples;
                for (id, index) in ids.by_ref().take(b.samples as usize).zip(samples) {
                    *id = SampleId {
                        pixel: y * width + x,
                        index,
                    };
                }
            }
        }
        self.film.fit(n);
        scene.sampler.fill_2d(&self.ids, 0, &mut self.film);
        if let Reconstruction::Importance(filter) = reconstruction {
            // The sample's offset from its pixel's centre, drawn from the
            // filter, and its weight f/pdf.
            self.filter_weight.fit(n);
            for (f, w) in self.film.iter_mut().zip(&mut self.filter_weight) {
                let (offset, weight) = filter.sample(*f);
                *f = Vec2::splat(0.5) + offset;
                *w = weight;
            }
        }
        // Raster positions: each pixel's corner plus its samples' offsets,
        // in the order the ids were made above (no division per sample).
        let mut film = self.film.iter_mut();
        for y in b.y0..b.y1 {
            for x in b.x0..b.x1 {
                let corner = Vec2::new(x as f32, y as f32);
                for f in film.by_ref().take(b.samples as usize) {
                    *f += corner;
                }
            }
        }
        self.start_paths(scene, scene.sampler.as_ref(), n);
    }

    /// Traces one camera path per raster position `raster[i]` (pixels from
    /// the image's top left corner) as sample `ids[i]` of `sampler` — the
    /// lens, the shutter time and every bounce draw from it, from
    /// dimension 2 on — and returns each path's radiance. The Metropolis
    /// integrators trace their chains' proposals with it (their sampler
    /// serves the chains' primary samples; `ids[i].pixel` is the chain).
    pub fn trace_raster(
        &mut self,
        scene: &RenderScene,
        sampler: &dyn Sampler,
        ids: &[SampleId],
        raster: &[Vec2],
    ) -> &[Rgb] {
        let n = ids.len().min(raster.len());
        self.ids.fit(n);
        self.ids.copy_from_slice(&ids[..n]);
        self.film.fit(n);
        self.film.copy_from_slice(&raster[..n]);
        self.collect_aovs = false;
        self.start_paths(scene, sampler, n);
        if scene.settings.max_depth != 0 {
            self.trace_paths(scene, sampler);
        }
        &self.radiance[..n]
    }

    /// Starts the camera paths of `self.ids` at the raster positions
    /// `self.film`: lens samples, rays, shutter times, path state.
    fn start_paths(&mut self, scene: &RenderScene, sampler: &dyn Sampler, n: usize) {
        self.u2.fit(n);
        if scene.camera.uses_lens_samples() {
            sampler.fill_2d(&self.ids, 2, &mut self.u2);
        }
        self.origin.fit(n);
        self.dir.fit(n);
        self.u1.fit(n);
        scene.camera.generate(
            &self.film,
            &self.u2,
            CameraRays {
                origins: &mut self.origin,
                directions: &mut self.dir,
                weights: &mut self.u1,
            },
        );
        if scene.motion_blur() {
            // Each path lives at one time of the shutter (a box shutter).
            self.time.fit(n);
            sampler.fill_1d(&self.ids, CAMERA_DIMS, &mut self.time);
            if let Some(motion) = &scene.camera_motion {
                move_camera_rays(motion, &self.time, &mut self.origin, &mut self.dir);
            }
        }
        self.beta.fit(n);
        for (b, w) in self.beta.iter_mut().zip(&self.u1) {
            *b = Rgb::splat(*w);
        }
        self.eta_scale.fit(n);
        self.eta_scale.fill(1.0);
        self.radiance.zeroed(n);
        self.prev_pdf.fit(n);
        self.hit.fit(n);
        self.its.fit(n);
        if scene.effects.contains(Effects::TANGENT_FRAMES) {
            self.derivs.fit(n);
        }
        self.live.clear();
        self.live.extend(0..n as u32);
    }

    fn trace_paths(&mut self, scene: &RenderScene, sampler: &dyn Sampler) {
        let s = &scene.settings;
        let max_depth = if s.max_depth < 0 {
            UNLIMITED_DEPTH_CAP
        } else {
            s.max_depth as u32
        };
        let has_lights = !scene.lights.is_empty();
        let has_area = scene.effects.contains(Effects::AREA_LIGHTS);
        let has_env = !scene.lights.environment().is_empty();
        let camera_dims = CAMERA_DIMS + u32::from(scene.motion_blur());
        let has_media = medium::active(scene);
        let bounce_dims = BOUNCE_DIMS + if has_media { MEDIUM_DIMS } else { 0 };
        if has_media {
            self.media.start(scene, &self.origin[..self.live.len()]);
        }
        self.shading.update(&scene.shaders);
        // Segments traced so far: every path's depth where there are no
        // `null` boundaries; with them each path keeps its own depth
        // (`MediumState::depth`).
        let mut depth = 0u32;
        while !self.live.is_empty() {
            let base = camera_dims + depth * bounce_dims;
            self.trace_closest(scene, depth);
            if has_media {
                self.media.sample_distances(
                    scene,
                    base + BOUNCE_DIMS,
                    &mut self.live,
                    &self.ids,
                    (&self.origin, &self.dir),
                    &self.hit,
                    (&mut self.beta, &mut self.radiance),
                    &mut self.its,
                );
            }
            self.resolve_hits(scene, depth, has_area, has_env);
            if has_media {
                self.live.extend_from_slice(self.media.events());
            }
            if has_env {
                self.add_escaped(scene, depth);
            }
            let Some(n) = self.select_vertices(scene, depth, max_depth, has_media) else {
                break;
            };
            // The paths that take light samples: a prefix of the `n` sorted
            // ones (all of them where media add their phase groups last).
            let lit = if has_media {
                n
            } else {
                self.shading.lit_paths(&self.offsets)
            };
            if has_lights {
                self.sample_lights(scene, sampler, lit, base);
            }
            self.shade(scene, sampler, base);
            if has_media {
                self.media.shade_events(
                    scene,
                    &self.offsets,
                    &self.wo,
                    &self.u3,
                    &self.nee_wi,
                    &mut self.bsdf,
                    &mut self.nee_eval,
                );
            }
            if has_lights {
                self.next_event(scene, lit);
            }
            self.continue_paths(scene, sampler, depth, has_media, base);
            if has_media {
                self.media.after_bounce(
                    scene,
                    &self.live,
                    (&self.hit, &self.its),
                    &self.dir,
                    &mut self.prev_pdf,
                );
            }
            depth += 1;
        }
    }

    /// Ends the paths whose hit may not scatter (`max_depth`; per path
    /// where `null` boundaries may be crossed, see `integrators/medium.rs`)
    /// and sorts the rest by material — after recording the camera rays'
    /// first hits when the batch collects them, `segment` 0. `None` when no
    /// path goes on.
    fn select_vertices(
        &mut self,
        scene: &RenderScene,
        segment: u32,
        max_depth: u32,
        has_media: bool,
    ) -> Option<usize> {
        let mut sorted = None;
        if segment == 0 && self.collect_aovs {
            let n = self.sort_by_material(scene);
            self.record_first_hits(scene, n);
            sorted = Some(n);
        }
        if has_media {
            if self
                .media
                .retire(scene, &mut self.live, &self.hit, max_depth)
            {
                sorted = None;
            }
        } else if segment + 1 >= max_depth {
            return None;
        }
        if self.live.is_empty() {
            return None;
        }
        Some(sorted.unwrap_or_else(|| self.sort_by_material(scene)))
    }

    fn trace_closest(&mut self, scene: &RenderScene, depth: u32) {
        let times = scene.motion_blur().then_some(&self.time[..]);
        let (live, origin, dir) = (&self.live[..], &self.origin[..], &self.dir[..]);
        if depth == 0 {
            // Camera rays: a pixel's samples one after the other.
            scene
                .accel
                .intersect_coherent_slots(live, origin, dir, times, &mut self.hit);
        } else {
            scene
                .accel
                .intersect_slots(live, origin, dir, times, &mut self.hit);
        }
        self.rays += self.live.len() as u64;
    }

    /// Drops paths that escaped (keeping them in `esc_slots` if `has_env`),
    /// resolves hits, adds emission.
    fn resolve_hits(&mut self, scene: &RenderScene, depth: u32, has_area: bool, has_env: bool) {
        let n = self.live.len();
        self.next_live.resize(n, 0);
        self.em_slots.resize(n, 0);
        self.esc_slots.fit(if has_env { n } else { 0 });
        // Slices taken once (bounds in registers); slots written by count.
        let (live, hits) = (&self.live[..], &self.hit[..]);
        let (origin, dir, its) = (&self.origin[..], &self.dir[..], &mut self.its[..]);
        let derivs = &mut self.derivs[..];
        let tangents = scene.effects.contains(Effects::TANGENT_FRAMES);
        let (next, emitting) = (&mut self.next_live[..], &mut self.em_slots[..]);
        let escaped = &mut self.esc_slots[..];
        let emitter = &scene.surfaces.emitter[..];
        let time = &self.time[..];
        let blur = scene.motion_blur();
        let (mut m, mut em, mut esc) = (0, 0, 0);
        let ahead = |k: usize| live.get(k).map(|&s| &hits[s as usize]);
        let prefetching = surface::prefetch_pays(scene);
        for (k, &slot) in live.iter().enumerate() {
            if prefetching {
                surface::prefetch(
                    scene,
                    ahead(k + 2 * PREFETCH_AHEAD),
                    ahead(k + PREFETCH_AHEAD),
                );
            }
            let i = slot as usize;
            let hit = hits[i];
            if hit.prim == Hit::MISS.prim {
                if has_env {
                    escaped[esc] = slot;
                    esc += 1;
                }
                continue;
            }
            let tau = if blur { time[i] } else { 0.0 };
            if tangents {
                (its[i], derivs[i]) =
                    interaction_with_derivatives(scene, &hit, origin[i], dir[i], tau);
            } else {
                its[i] = interaction(scene, &hit, origin[i], dir[i], tau);
            }
            if has_area && emitter[hit.prim as usize] != NO_EMITTER {
                emitting[em] = slot;
                em += 1;
            }
            next[m] = slot;
            m += 1;
        }
        self.next_live.truncate(m);
        self.em_slots.truncate(em);
        self.esc_slots.truncate(esc);
        std::mem::swap(&mut self.live, &mut self.next_live);
        if self.em_slots.is_empty() {
            return;
        }
        let surfaces = &scene.surfaces;
        let hits = &self.hit;
        let nlights = scene.lights.len();
        sort_by_key(
            &mut self.em_slots,
            &mut self.scratch,
            &mut self.cursor,
            &mut self.offsets,
            nlights,
            |slot| surfaces.emitter[hits[slot as usize].prim as usize],
        );
        self.em_hits.fit(self.em_slots.len());
        self.em_evals.fit(self.em_slots.len());
        let has_media = medium::active(scene);
        for (k, &slot) in self.em_slots.iter().enumerate() {
            let i = slot as usize;
            self.em_hits[k] = EmitterHit {
                origin: if has_media {
                    self.media.scatter_origin(i)
                } else {
                    self.origin[i]
                },
                p: self.its[i].p,
                n: self.its[i].ng,
                primitive: surfaces.emitter_prim[self.hit[i].prim as usize],
            };
        }
        for light in 0..nlights {
            let (a, b) = (
                self.offsets[light] as usize,
                self.offsets[light + 1] as usize,
            );
            if a < b {
                scene.lights.lights()[light]
                    .eval_hits(&self.em_hits[a..b], &mut self.em_evals[a..b]);
            }
        }
        let m = self.em_slots.len();
        self.points.fit(m);
        self.em_light.fit(m);
        self.em_pmf.fit(m);
        for light in 0..nlights {
            let (a, b) = (self.offsets[light], self.offsets[light + 1]);
            self.em_light[a as usize..b as usize].fill(light as u32);
        }
        for (p, h) in self.points.iter_mut().zip(&self.em_hits) {
            *p = h.origin;
        }
        let lights = &scene.lights;
        lights.pmf_many(&self.points, &self.em_light, &mut self.em_pmf);
        let em = self.em_slots.iter().zip(&self.em_evals).zip(&self.em_pmf);
        for ((&slot, e), &pmf) in em {
            let i = slot as usize;
            let w = bsdf_hit_weight(depth, self.prev_pdf[i], pmf * e.pdf);
            self.radiance[i] += self.beta[i] * e.radiance * w;
        }
    }

    /// Adds the emission of environment lights to the paths that left the
    /// scene this bounce, one `Light::eval_escaped` call per such light.
    fn add_escaped(&mut self, scene: &RenderScene, depth: u32) {
        let n = self.esc_slots.len();
        if n == 0 {
            return;
        }
        self.esc_dirs.fit(n);
        self.esc_evals.fit(n);
        for (d, &slot) in self.esc_dirs.iter_mut().zip(&self.esc_slots) {
            *d = self.dir[slot as usize].normalize();
        }
        for &light in scene.lights.environment() {
            scene.lights.lights()[light].eval_escaped(&self.esc_dirs, &mut self.esc_evals);
            for (&slot, e) in self.esc_slots.iter().zip(&self.esc_evals) {
                let i = slot as usize;
                let pmf = scene.lights.pmf_at(self.origin[i], light);
                let w = bsdf_hit_weight(depth, self.prev_pdf[i], pmf * e.pdf);
                self.radiance[i] += self.beta[i] * e.radiance * w;
            }
        }
    }

    /// Sorts live paths by material and gathers their shading inputs.
    fn sort_by_material(&mut self, scene: &RenderScene) -> usize {
        let (hits, order) = (&self.hit, &self.shading);
        let materials = scene.shaders.len();
        let material = |slot: u32| scene.material(&hits[slot as usize]);
        let (live, scratch) = (&mut self.live, &mut self.scratch);
        let (cursor, offsets) = (&mut self.cursor, &mut self.offsets);
        if medium::active(scene) {
            // Medium events after the materials, one group per medium.
            let media = &self.media;
            let groups = materials + scene.media.phases.len();
            sort_by_key(live, scratch, cursor, offsets, groups, |slot| {
                media
                    .event_group(slot, materials)
                    .unwrap_or_else(|| order.rank(material(slot)))
            });
        } else if order.is_identity() {
            // No purely specular material before one with smooth lobes:
            // the materials are their own ranks, unlooked-up.
            sort_by_key(live, scratch, cursor, offsets, materials, material);
        } else {
            let rank = |slot| order.rank(material(slot));
            sort_by_key(live, scratch, cursor, offsets, materials, rank);
        }
        let n = self.live.len();
        self.ids_k.fit(n);
        self.wo.fit(n);
        self.uv.fit(n);
        let (ids, its, dir) = (&self.ids[..], &self.its[..], &self.dir[..]);
        let outputs = self.ids_k.iter_mut().zip(&mut self.wo).zip(&mut self.uv);
        for (((id, wo), uv), &slot) in outputs.zip(&self.live) {
            let i = slot as usize;
            *id = ids[i];
            *wo = its[i].frame.to_local(-dir[i]);
            *uv = its[i].uv;
        }
        if scene.effects.contains(Effects::TANGENT_FRAMES) {
            self.dp_du.fit(n);
            self.dp_dv.fit(n);
            let derivs = &self.derivs[..];
            let outputs = self.dp_du.iter_mut().zip(&mut self.dp_dv);
            for ((du, dv), &slot) in outputs.zip(&self.live) {
                let i = slot as usize;
                let frame = &its[i].frame;
                *du = frame.to_local(derivs[i].dp_du);
                *dv = frame.to_local(derivs[i].dp_dv);
            }
        }
        n
    }

    /// Records what the camera rays that hit a surface found (the live
    /// paths after [`Wavefront::sort_by_material`] at depth 0): one
    /// `Shader::albedo` call per material.
    fn record_first_hits(&mut self, scene: &RenderScene, n: usize) {
        self.albedo_k.fit(n);
        let mut ctx = ShadeContext::new(&scene.textures);
        for (shader, k) in material_ranges(&scene.shaders, &self.shading, &self.offsets) {
            let (a, b) = (k.start, k.end);
            let surface = surface_batch(shader, [&self.wo, &self.dp_du, &self.dp_dv], &self.uv, k);
            shader.albedo(&mut ctx, surface, &mut self.albedo_k[a..b]);
        }
        let (its, origin) = (&self.its[..], &self.origin[..]);
        let to_world = scene.render_origin;
        for (&slot, &albedo) in self.live[..n].iter().zip(&self.albedo_k) {
            let i = slot as usize;
            let it = &its[i];
            self.first_hits[i] = FirstHit {
                alpha: 1.0,
                albedo,
                normal: it.frame.n,
                depth: (it.p - origin[i]).length(),
                position: (it.p.as_dvec3() + to_world).as_vec3(),
            };
        }
    }

    /// Chooses a light for each of the first `n` sorted paths and samples a
    /// point on it, one module call per light.
    fn sample_lights(&mut self, scene: &RenderScene, sampler: &dyn Sampler, n: usize, base: u32) {
        self.u2.fit(n);
        // Points on lights, where a light reads them: a point or spot
        // light has nothing to choose.
        if scene.lights.uses_point_samples() {
            sampler.fill_2d(&self.ids_k[..n], base + 1, &mut self.u2);
        }
        self.light.fit(n);
        self.light_prob.fit(n);
        self.light_sample.fit(n);
        if let [light] = scene.lights.lights() {
            // One light: no choice to make and no grouping.
            self.light.fill(0);
            self.light_prob.fill(1.0);
            self.refs.fit(n);
            let its = &self.its[..];
            for (r, &slot) in self.refs.iter_mut().zip(&self.live) {
                *r = its[slot as usize].p;
            }
            light.sample(&self.refs, &self.u2, &mut self.light_sample);
        } else {
            self.sample_chosen_lights(scene, sampler, n, base);
        }
        // Directions towards the light samples, in the local frames.
        self.nee_wi.fit(n);
        self.nee_wi_world.fit(n);
        let its = &self.its[..];
        let outputs = self.nee_wi_world.iter_mut().zip(&mut self.nee_wi);
        for ((world, local), (&slot, ls)) in outputs.zip(self.live.iter().zip(&self.light_sample)) {
            let it = &its[slot as usize];
            let wi = (ls.p - it.p).normalize_or_zero();
            *world = wi;
            *local = it.frame.to_local(wi);
        }
    }

    /// Chooses a light per path (`LightTable::select_at`) and samples the
    /// chosen lights, one module call per light.
    fn sample_chosen_lights(
        &mut self,
        scene: &RenderScene,
        sampler: &dyn Sampler,
        n: usize,
        base: u32,
    ) {
        self.u1.fit(n);
        sampler.fill_1d(&self.ids_k[..n], base, &mut self.u1);
        self.points.fit(n);
        let its = &self.its[..];
        for (p, &slot) in self.points.iter_mut().zip(&self.live) {
            *p = its[slot as usize].p;
        }
        let (points, u) = (&self.points[..n], &self.u1[..n]);
        scene
            .lights
            .select_many(points, u, &mut self.light, &mut self.light_prob);
        self.by_light.clear();
        self.by_light.extend(0..n as u32);
        let lights = &self.light;
        let offsets = &mut self.light_offsets;
        sort_by_key(
            &mut self.by_light,
            &mut self.scratch,
            &mut self.cursor,
            offsets,
            scene.lights.len(),
            |k| lights[k as usize],
        );
        self.refs.fit(n);
        self.light_u.fit(n);
        self.light_out.fit(n);
        for (j, &k) in self.by_light.iter().enumerate() {
            let k = k as usize;
            self.refs[j] = self.points[k];
            self.light_u[j] = self.u2[k];
        }
        for l in 0..scene.lights.len() {
            let (a, b) = (offsets[l] as usize, offsets[l + 1] as usize);
            if a < b {
                scene.lights.lights()[l].sample(
                    &self.refs[a..b],
                    &self.light_u[a..b],
                    &mut self.light_out[a..b],
                );
            }
        }
        for (j, &k) in self.by_light.iter().enumerate() {
            self.light_sample[k as usize] = self.light_out[j];
        }
    }

    /// Calls each material's shader on its slice: BSDF samples for the
    /// continuation, and evaluations towards the light samples.
    fn shade(&mut self, scene: &RenderScene, sampler: &dyn Sampler, base: u32) {
        let n = self.live.len();
        self.u3.fit(n);
        self.u1.fit(n);
        self.u2.fit(n);
        sampler.fill_2d(&self.ids_k, base + 4, &mut self.u2);
        // Lobe choices only for the materials that have lobes to choose.
        for (shader, k) in material_ranges(&scene.shaders, &self.shading, &self.offsets) {
            if shader.uses_lobe_samples() {
                sampler.fill_1d(&self.ids_k[k.clone()], base + 3, &mut self.u1[k]);
            }
        }
        for ((u3, &u1), u2) in self.u3.iter_mut().zip(&self.u1).zip(&self.u2) {
            *u3 = Vec3::new(u1, u2.x, u2.y);
        }
        self.bsdf.fit(n);
        self.nee_eval.fit(n);
        // A material's `sample` and `eval` look up its textures at the same
        // coordinates: the second lookup reuses the first's values.
        let mut ctx = ShadeContext::new(&scene.textures).with_stable_uv(&self.uv);
        let has_lights = !scene.lights.is_empty();
        for (shader, k) in material_ranges(&scene.shaders, &self.shading, &self.offsets) {
            let (a, b) = (k.start, k.end);
            let surface = surface_batch(shader, [&self.wo, &self.dp_du, &self.dp_dv], &self.uv, k);
            shader.sample(&mut ctx, surface, &self.u3[a..b], &mut self.bsdf[a..b]);
            if has_lights && reads_light_samples(shader) {
                shader.eval(
                    &mut ctx,
                    surface,
                    &self.nee_wi[a..b],
                    &mut self.nee_eval[a..b],
                );
            } else {
                self.nee_eval[a..b].fill(BsdfEval::default());
            }
        }
    }

    /// Weights the light samples of the first `n` sorted paths and traces
    /// their shadow rays.
    fn next_event(&mut self, scene: &RenderScene, n: usize) {
        self.shadow_slot.fit(n);
        self.shadow_origin.fit(n);
        self.shadow_dir.fit(n);
        self.shadow_value.fit(n);
        // Slices taken once, so that the loop keeps their bounds in
        // registers, and shadow rays written by count rather than pushed.
        let (light_sample, nee_eval, live) = (
            &self.light_sample[..n],
            &self.nee_eval[..n],
            &self.live[..n],
        );
        let (wi_world, wi_local) = (&self.nee_wi_world[..n], &self.nee_wi[..n]);
        let (light, light_prob) = (&self.light[..n], &self.light_prob[..n]);
        let (its, beta) = (&self.its[..], &self.beta[..]);
        let (slots, origins) = (&mut self.shadow_slot[..], &mut self.shadow_origin[..]);
        let (dirs, values) = (&mut self.shadow_dir[..], &mut self.shadow_value[..]);
        let mut m = 0;
        for k in 0..n {
            let ls = light_sample[k];
            let e = nee_eval[k];
            if ls.pdf <= 0.0 || e.value == Rgb::ZERO {
                continue;
            }
            let slot = live[k];
            let i = slot as usize;
            let it = &its[i];
            let wi = wi_world[k];
            // Shading and geometric normals must agree on the side.
            if wi.dot(it.ng) * wi_local[k].z <= 0.0 {
                continue;
            }
            let light_pdf = light_prob[k] * ls.pdf;
            // The MIS weight over the density, w / light_pdf, in one
            // division: 1/p for delta lights, p/(p² + bsdf²) otherwise.
            let weight = if scene.lights.is_delta(light[k] as usize) {
                1.0 / light_pdf
            } else {
                light_pdf / (light_pdf * light_pdf + e.pdf * e.pdf)
            };
            let value = beta[i] * e.value * ls.radiance * weight;
            if value == Rgb::ZERO || !value.is_finite() {
                continue;
            }
            let origin = offset_origin(it.p, it.err, it.ng, wi);
            let target = if ls.n == Vec3::ZERO {
                ls.p
            } else {
                offset_origin(ls.p, sampled_point_error(ls.p), ls.n, -wi)
            };
            slots[m] = slot;
            origins[m] = origin;
            dirs[m] = target - origin;
            values[m] = value;
            m += 1;
        }
        self.shadow_slot.truncate(m);
        self.shadow_origin.truncate(m);
        self.shadow_dir.truncate(m);
        self.shadow_value.truncate(m);
        self.shadow_blocked.fit(self.shadow_slot.len());
        let times = if scene.motion_blur() {
            self.shadow_time.clear();
            let time = &self.time;
            self.shadow_time
                .extend(self.shadow_slot.iter().map(|&s| time[s as usize]));
            Some(&self.shadow_time[..])
        } else {
            None
        };
        if medium::active(scene) {
            // Transmittance through media and `null` boundaries; blocked
            // rays carry zero.
            self.media.transmittance(
                scene,
                &self.shadow_slot,
                (&self.shadow_origin, &self.shadow_dir),
                times,
                SHADOW_EPSILON,
                (&self.hit, &self.its),
                &mut self.shadow_value,
            );
            self.shadow_blocked.fill(false);
        } else {
            scene.accel.occluded_each(
                &self.shadow_origin,
                &self.shadow_dir,
                times,
                1.0 - SHADOW_EPSILON,
                &mut self.shadow_blocked,
            );
        }
        let radiance = &mut self.radiance[..];
        let rays = self.shadow_slot.iter().zip(&self.shadow_blocked);
        for ((&slot, &blocked), &value) in rays.zip(&self.shadow_value) {
            if !blocked {
                radiance[slot as usize] += value;
            }
        }
        self.rays += self.shadow_slot.len() as u64;
    }

    /// Follows the BSDF samples, applies Russian roulette (from
    /// `rr_depth` on: the batch's `depth`, or each path's own where
    /// `null` boundaries may be crossed, `per_path`) and compacts.
    fn continue_paths(
        &mut self,
        scene: &RenderScene,
        sampler: &dyn Sampler,
        depth: u32,
        per_path: bool,
        base: u32,
    ) {
        let n = self.live.len();
        let rr_depth = scene.settings.rr_depth;
        let rr_all = depth + 1 >= rr_depth;
        self.u1.fit(n);
        if rr_all || per_path {
            // Russian roulette's samples; before `rr_depth` nothing reads
            // them.
            sampler.fill_1d(&self.ids_k, base + 6, &mut self.u1);
        }
        let depths = per_path.then(|| self.media.depth());
        self.next_live.resize(n, 0);
        // Slices taken once (bounds in registers); survivors written by
        // count.
        let (bsdf, live, u) = (&self.bsdf[..n], &self.live[..n], &self.u1[..n]);
        let its = &self.its[..];
        let (beta_of, eta_of) = (&mut self.beta[..], &mut self.eta_scale[..]);
        let (prev_pdf, origin, dir) = (
            &mut self.prev_pdf[..],
            &mut self.origin[..],
            &mut self.dir[..],
        );
        let next = &mut self.next_live[..];
        let mut m = 0;
        for k in 0..n {
            let s = bsdf[k];
            if s.pdf <= 0.0 || s.weight == Rgb::ZERO {
                continue;
            }
            let slot = live[k];
            let i = slot as usize;
            let it = &its[i];
            let wi = it.frame.to_world(s.wi);
            if wi.dot(it.ng) * s.wi.z <= 0.0 {
                continue;
            }
            let mut beta = beta_of[i] * s.weight;
            let beta_max = beta.max_element();
            if beta_max <= 0.0 || !beta.is_finite() {
                continue;
            }
            // Survival in proportion to throughput without the 1/η² of
            // refraction (pbrt-v4, Cycles, Mitsuba's η² tracking): a path
            // whose throughput is still 1 (mirrors, glass) is never killed
            // at random, so it gathers no 1/q^k weight.
            let eta_scale = eta_of[i] * s.eta * s.eta;
            let survival = beta_max * eta_scale;
            let rr = depths.map_or(rr_all, |d| d[i] + 1 >= rr_depth);
            if rr && survival < 1.0 {
                if u[k] >= survival {
                    continue;
                }
                beta /= survival;
            }
            beta_of[i] = beta;
            eta_of[i] = eta_scale;
            prev_pdf[i] = if s.delta { 0.0 } else { s.pdf };
            origin[i] = offset_origin(it.p, it.err, it.ng, wi);
            dir[i] = wi;
            next[m] = slot;
            m += 1;
        }
        self.next_live.truncate(m);
        std::mem::swap(&mut self.live, &mut self.next_live);
    }
}
