//! `bdpt`: bidirectional path tracing (Veach's, with seed 001's recursive
//! MIS weights), a tile integrator that splats.
//!
//! Per camera sample the worker traces a light subpath — a light chosen in
//! proportion to power, an emitted ray ([`radiant_core::Emission`]), BSDF
//! sampling in importance transport — and a camera subpath — the camera
//! ray, BSDF sampling in radiance transport, as `path` does — and adds
//! every strategy (s light vertices, t camera vertices) that `max_depth`
//! allows:
//!
//! * s = 0: the camera subpath hits an emitter or leaves the scene
//!   towards an environment light;
//! * s = 1, t ≥ 2: next-event estimation at each camera vertex, the light
//!   point drawn by the light's own `sample`, as `path` does;
//! * s ≥ 2, t ≥ 2: each camera vertex connected to each light vertex of
//!   its sample's light subpath (`connections: all`), or to N vertices
//!   drawn from the light vertex cache of the chunk (`connections: N`,
//!   [`Connections`]), with a shadow ray;
//! * t = 1: each light vertex connected to the lens
//!   ([`radiant_core::Importance::sample_wi`]) and splatted where it lands
//!   on the film, anywhere in the image.
//!
//! The samples of a batch are walked together, in chunks (a wavefront, as
//! `path`): all light subpaths one vertex index at a time
//! (`light_walk.rs`, the t = 1 connections at each index), then all
//! camera subpaths (`camera_walk.rs`, s = 0 at each index, then
//! next-event estimation and the connections, `connect.rs`). Every step
//! is a batch: one closest-hit query for the step's rays, one module call
//! per light or per material on the step's requests (`by_light.rs`,
//! `shading.rs`), one shadow-ray query per connection stage
//! (`shadow.rs`). Subpaths are kept per sample as rows of a fixed length
//! (`vertex.rs`), so a connection finds its two vertices, their MIS state
//! and their predecessors by index. A sample's strategies are summed in
//! the order the one-path-at-a-time walk added them.
//!
//! Where a render asks for per-strategy images
//! ([`crate::integrators::strategies`]), each contribution, weighted, also
//! goes to its strategy's film: the camera-side ones through the chunk's
//! log (`strategy_log.rs`), splatted at their samples' film positions
//! after the chunk, the t = 1 ones where they land.
//!
//! Each contribution is weighted by the power heuristic over all the
//! strategies that could have made its path ([`mis`]). Vertices whose
//! scattering is a delta lobe are never connected; delta lights (point,
//! spot, directional) are never hit; light paths never hit the lens.
//! Light subpaths carry importance-transport throughput: refraction's 1/η²
//! is not applied, and shading normals are corrected as in pbrt
//! (|ωo·ns||ωi·ng| / (|ωo·ng||ωi·ns|)); a connection evaluates the light
//! vertex's BSDF with its directions swapped, which is the adjoint BSDF of
//! every built-in shader (so no shader knows the transport mode).
//!
//! `max_depth` counts segments as `path` does; `-1` is capped at
//! [`UNLIMITED_DEPTH_CAP`] vertices per subpath (connections cost the
//! product of the subpaths' lengths). Russian roulette starts at
//! `rr_depth` on each subpath, on its throughput (light subpaths: relative
//! to the emitted ray's), and is left out of the MIS densities (the weights
//! still sum to one; they are just not the optimal ones for paths that
//! roulette shortened).
//!
//! What the scene must offer: every light an emission side and the camera
//! an importance side ([`check`] names the module that lacks one), no
//! participating media, no motion blur.

mod by_light;
mod camera_walk;
mod connect;
mod light_walk;
mod mis;
mod shading;
mod shadow;
mod strategy_log;
mod vertex;
mod walk;

use self::by_light::ByLight;
use self::shading::{Op, Queue};
use self::shadow::Shadows;
use self::strategy_log::strategy_index;
use self::strategy_log::{StrategyLog, strategy_names};
use self::vertex::Subpaths;
use super::module::{
    Batch, Family, Integrator, TileContext, TileIntegrator, TileOutput, TileWorker,
};
use crate::accel::Hit;
use crate::extract::RenderScene;
use crate::film::Reconstruction;
use crate::film::aov::FirstHit;
use crate::film::exact::BLOCK;
use glam::{Vec2, Vec3};
use radiant_core::{
    BsdfSample, BuildContext, CameraRayPdf, CameraRays, EmissionPdf, EmissionSample, EmittedRay,
    EmitterEval, EmitterHit, LensSample, LightSample, ModuleInfo, ParamDoc, ParamError, Params,
    Registry, Rgb, SampleId, ShadeContext,
};
use serde::Deserialize;

/// Vertices per subpath where `max_depth` is −1.
pub const UNLIMITED_DEPTH_CAP: u32 = 256;
/// Sampler dimensions of the camera ray (film position, lens).
const CAMERA_DIMS: u32 = 4;
/// The light subpath's start: light choice, origin (2), direction (2).
const LIGHT_DIMS: u32 = 5;
/// Dimensions per vertex index: camera lobe, direction (2), roulette;
/// next-event light choice, point (2); light lobe, direction (2),
/// roulette; lens (2).
const VERTEX_DIMS: u32 = 13;

/// The first sampler dimension of vertex index `d`.
#[inline]
fn dims(d: u32) -> u32 {
    CAMERA_DIMS + LIGHT_DIMS + d * VERTEX_DIMS
}

/// The sampler dimension of camera vertex `i`'s light vertex cache draws
/// under `max` vertices a subpath: past every vertex index's, so that
/// the other strategies' numbers do not depend on `connections`.
#[inline]
fn cache_dim(max: usize, i: usize) -> u32 {
    dims(max as u32) + i as u32
}

/// Why `scene` cannot be rendered by `bdpt`, naming the module or feature.
pub fn check(scene: &RenderScene) -> Result<(), String> {
    if scene.camera.importance().is_none() {
        let camera = scene
            .modules
            .iter()
            .find(|(k, _)| *k == radiant_core::ModuleKind::Camera)
            .map_or("?", |(_, n)| n.as_str());
        return Err(format!(
            "`bdpt` connects light paths to the camera, and the camera type `{camera}` has no \
             importance side (`Camera::importance`); use `perspective`, `thin_lens`, \
             `orthographic` or `spherical`, or the `path` integrator"
        ));
    }
    for (i, light) in scene.lights.lights().iter().enumerate() {
        if light.emission().is_none() {
            let name = scene.light_types.get(i).map_or("?", String::as_str);
            return Err(format!(
                "`bdpt` starts paths at lights, and the light type `{name}` has no emission \
                 side (`Light::emission`); use the `path` integrator"
            ));
        }
    }
    if super::medium::active(scene) {
        return Err("`bdpt` does not render participating media; use the `path` integrator".into());
    }
    if scene.motion_blur() {
        return Err("`bdpt` does not render motion blur; use the `path` integrator".into());
    }
    Ok(())
}

/// How the s ≥ 2 strategies join a camera vertex to light vertices.
///
/// `All` is Veach's: every light vertex of the sample's own light
/// subpath. `Drawn(N)` is the light vertex cache of Davidovič et al.
/// (2014, "Progressive light transport simulation on the GPU"): the
/// connectable light vertices of all the chunk's light subpaths (`n`
/// of them, from `m` vertices in all) form a cache, and each camera
/// vertex connects to `N` of them drawn uniformly (stratified), each
/// weighted `m / (N n)`. Every light subpath is independent of every
/// camera subpath, so the expected sum over the draws equals the mean
/// over the chunk's light subpaths of the full connection sum: the
/// estimator is unbiased and the MIS weights are unchanged.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Connections {
    /// Every vertex of the sample's own light subpath.
    All,
    /// This many vertices drawn from the chunk's light vertex cache.
    Drawn(u32),
}

impl Default for Connections {
    fn default() -> Self {
        DEFAULT_CONNECTIONS
    }
}

/// `connections:` where a scene leaves it out (chosen by measurement,
/// `engine/benches/BDPT.md`).
pub const DEFAULT_CONNECTIONS: Connections = Connections::Drawn(1);

/// The `bdpt` integrator (see the module documentation).
#[derive(Debug, Clone, Copy, Default)]
pub struct Bdpt {
    /// The one strategy (s, t) to render, unweighted (`strategy: [s, t]`),
    /// or `None` for all of them, weighted.
    only: Option<(usize, usize)>,
    /// How camera vertices connect to light vertices (`connections:`).
    connections: Connections,
}

impl Integrator for Bdpt {
    fn family(&self) -> Family<'_> {
        Family::Tiles(self)
    }

    fn check(&self, scene: &RenderScene) -> Result<(), String> {
        check(scene)
    }
}

impl TileIntegrator for Bdpt {
    fn splats(&self) -> bool {
        true
    }

    /// Every (s, t) that `max_depth` allows, by path length (`s0_t2`,
    /// `s1_t1`, `s0_t3`, …): Veach's per-strategy images.
    fn strategies(&self, scene: &RenderScene) -> Vec<String> {
        strategy_names(depth_limit(scene) as usize)
    }

    fn worker(&self) -> Box<dyn TileWorker + '_> {
        Box::new(Worker {
            state: State {
                only: self.only,
                connections: self.connections,
                ..State::default()
            },
            ..Worker::default()
        })
    }
}

/// `bdpt`'s own keys (`max_depth`, `rr_depth` and `light_selection` are
/// the loader's).
#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct BdptParams {
    strategy: Option<[u32; 2]>,
    connections: Option<ConnectionsParam>,
}

/// `connections:` as written: `all` or a count.
#[derive(Deserialize)]
#[serde(untagged)]
enum ConnectionsParam {
    Count(u32),
    Word(String),
}

const DOCS: &[ParamDoc] = &[
    ParamDoc {
        name: "strategy",
        ty: "[s, t]",
        default: "none (all, weighted)",
        doc: "Render one strategy alone, unweighted: s light vertices, t ≥ 1 camera vertices — \
              its image is the contribution of paths of s + t − 1 segments that this \
              strategy can make. For validation; `radiant render --strategies DIR` writes \
              every strategy's weighted image in one render.",
    },
    ParamDoc {
        name: "connections",
        ty: "all | N ≥ 1",
        default: "1",
        doc: "The s ≥ 2 strategies: `all` connects each camera vertex to every vertex of its \
              own light subpath (Veach); N connects it to N vertices drawn from the light \
              vertices of all the tile's light subpaths (a light vertex cache), weighted by \
              the inverse of their probability: unbiased, fewer connections per sample.",
    },
];

impl ConnectionsParam {
    /// The connection rule `self` names.
    fn parse(self) -> Result<Connections, ParamError> {
        // Scalars may arrive as text, so a count may be a word.
        let count = match self {
            Self::Word(w) if w == "all" => return Ok(Connections::All),
            Self::Count(n) => n,
            Self::Word(w) => w.parse().map_err(|_| {
                ParamError::new(format!(
                    "`connections: {w}` is neither `all` nor a count of light vertices"
                ))
            })?,
        };
        if count == 0 {
            return Err(ParamError::new(
                "`connections` needs at least 1 light vertex (or `all`)",
            ));
        }
        Ok(Connections::Drawn(count))
    }
}

/// Registers `bdpt`.
pub fn register(registry: &mut Registry) {
    registry.register::<dyn Integrator>(
        ModuleInfo {
            type_name: "bdpt",
            summary: "Bidirectional path tracer: camera and light subpaths joined by every \
                      connection strategy (light paths reaching the camera splat anywhere in \
                      the image), power-heuristic MIS with recursive weights. CPU only.",
            params: DOCS,
        },
        |params: &Params, _: &mut BuildContext<'_>| -> Result<Box<dyn Integrator>, ParamError> {
            let p: BdptParams = params.parse()?;
            let only = match p.strategy {
                Some([_, 0]) => {
                    return Err(ParamError::new(
                        "`strategy: [s, t]` needs t ≥ 1: light paths never hit the lens",
                    ));
                }
                Some([s, t]) => Some((s as usize, t as usize)),
                None => None,
            };
            let connections = p
                .connections
                .map_or(Ok(DEFAULT_CONNECTIONS), ConnectionsParam::parse)?;
            Ok(Box::new(Bdpt { only, connections }))
        },
    );
}

/// Vertices of both subpaths a chunk of samples holds at most: a batch's
/// samples are walked in chunks of `CHUNK_VERTICES / (max_depth + 1)`
/// (all of a 1024-path batch at `max_depth` 8, 63 at a time when
/// unlimited), so the rows stay small whatever the depth.
const CHUNK_VERTICES: usize = 1 << 14;

/// One thread's state: the batch's camera rays, and the chunk walks'
/// scratch ([`State`]).
#[derive(Default)]
pub struct Worker {
    ids: Vec<SampleId>,
    film: Vec<Vec2>,
    filter_weight: Vec<f32>,
    lens: Vec<Vec2>,
    origin: Vec<Vec3>,
    dir: Vec<Vec3>,
    weight: Vec<f32>,
    values: Vec<Rgb>,
    /// The camera rays' first hits, where the render records them.
    first_hits: Vec<FirstHit>,
    state: State,
}

/// What a chunk's walks and connection stages share (see the module
/// documentation), reused from chunk to chunk: per sample slot `j` of the
/// chunk its id, subpaths, walk state and radiance; per stage its request
/// lists and batched module calls' inputs and answers.
#[derive(Default)]
pub(super) struct State {
    /// The one strategy to render (`strategy: [s, t]`), if any.
    only: Option<(usize, usize)>,
    /// How camera vertices connect to light vertices.
    connections: Connections,
    /// The chunk's light vertex cache (`connections: N`): (slot, index)
    /// of every connectable light vertex past the light.
    cache: Vec<(u32, u32)>,
    /// The most vertices a camera subpath may have past the lens.
    max: usize,
    /// The chunk's sample ids, by slot.
    ids: Vec<SampleId>,
    light: Subpaths,
    camera: Subpaths,
    // Walk state, by slot.
    /// Slots whose subpath is still growing.
    live: Vec<u32>,
    next: Vec<u32>,
    origin: Vec<Vec3>,
    dir: Vec<Vec3>,
    beta: Vec<Rgb>,
    /// Solid-angle density of the ray `dir` (as sampled).
    pdf_dir: Vec<f32>,
    /// Light subpaths: throughput relative to the emitted ray's (Russian
    /// roulette); camera subpaths: product of η² over refractions.
    scale: Vec<f32>,
    /// Camera ray's lens density (an orthographic camera's first vertex).
    pdf_pos: Vec<f32>,
    hit: Vec<Hit>,
    /// Each light subpath's light and emitted ray.
    start: Vec<Start>,
    /// Camera strategies' sum, by slot.
    radiance: Vec<Rgb>,
    // Per request of the current stage.
    req: Vec<u32>,
    req_ids: Vec<SampleId>,
    u1: Vec<f32>,
    u2: Vec<Vec2>,
    u3: Vec<Vec2>,
    light_of: Vec<u32>,
    pmf: Vec<f32>,
    /// Index of a request's first shader call in `queue`.
    call: Vec<u32>,
    /// Per connection: the slot of its light vertex's subpath.
    from: Vec<u32>,
    dirs: Vec<Vec3>,
    values: Vec<Rgb>,
    /// Per request: the solid-angle density of the reverse scattering
    /// (walks), or a density a connection needs later.
    aux: Vec<f32>,
    /// Requests that passed a stage's checks.
    kept: Vec<u32>,
    /// Per kept request: its shadow ray.
    shadow_of: Vec<u32>,
    bsdf: Vec<BsdfSample>,
    // Batched module calls, in light order.
    by_light: ByLight,
    emitted: Vec<EmissionSample>,
    light_samples: Vec<LightSample>,
    emitter_hits: Vec<EmitterHit>,
    emitter_evals: Vec<EmitterEval>,
    emitted_rays: Vec<EmittedRay>,
    emission_pdfs: Vec<EmissionPdf>,
    refs: Vec<Vec3>,
    lens: Vec<LensSample>,
    camera_rays: Vec<(Vec3, Vec3)>,
    camera_pdfs: Vec<CameraRayPdf>,
    queue: Queue,
    shadows: Shadows,
    /// The camera-side contributions by strategy, where per-strategy
    /// images are asked for.
    log: StrategyLog,
    rays: u64,
}

/// How a light subpath started: which light, its choice probability, and
/// its emitted ray.
#[derive(Debug, Clone, Copy, Default)]
struct Start {
    light: u32,
    pmf: f32,
    sample: EmissionSample,
}

impl TileWorker for Worker {
    fn render(&mut self, ctx: &TileContext<'_>, batch: Batch, mut out: TileOutput<'_>) {
        let scene = ctx.scene;
        let n = self.generate(scene, batch, ctx.reconstruction);
        let count = batch.samples as usize;
        let mut shade = ShadeContext::new(&scene.textures);
        self.values.clear();
        self.values.resize(n, Rgb::ZERO);
        if out.aovs.is_some() {
            self.first_hits.clear();
            self.first_hits.resize(n, FirstHit::default());
        }
        let state = &mut self.state;
        state.max = depth_limit(scene) as usize;
        state.log.on = ctx.strategies.is_some();
        let chunk = (CHUNK_VERTICES / (state.max + 1)).max(16);
        for a in (0..n).step_by(chunk) {
            let b = n.min(a + chunk);
            state.ids.clear();
            state.ids.extend_from_slice(&self.ids[a..b]);
            state.trace_lights(scene, &mut shade, ctx.splats, ctx.strategies);
            state.fill_cache();
            let rays = (&self.origin[a..b], &self.dir[a..b], &self.weight[a..b]);
            state.log.entries.clear();
            state.trace_cameras(scene, &mut shade, rays);
            self.values[a..b].copy_from_slice(&state.radiance[..b - a]);
            if let Some(films) = ctx.strategies {
                for &(j, index, v) in &state.log.entries {
                    let i = a + j as usize;
                    // The film records a sample that is not finite as black.
                    if self.values[i].is_finite() {
                        films.splat(index as usize, self.film[i], v);
                    }
                }
            }
            if out.aovs.is_some() {
                let first = &mut self.first_hits[a..b];
                state.first_hits(scene, &mut shade, &self.origin[a..b], first);
            }
        }
        let values = &self.values;
        for (first, index) in (0..count).zip(batch.first_sample..) {
            for i in (first..n).step_by(count) {
                match ctx.reconstruction {
                    Reconstruction::Splat(table) => out.film.splat(self.film[i], values[i], table),
                    Reconstruction::Importance(_) => {
                        let width = scene.settings.width;
                        let pixel = self.ids[i].pixel;
                        out.film.add(
                            pixel % width,
                            pixel / width,
                            values[i],
                            self.filter_weight[i],
                        );
                    }
                }
            }
            if (index + 1) % BLOCK == 0 {
                out.film.end_block();
            }
        }
        if let Some(add) = out.samples.as_mut() {
            for (id, v) in self.ids[..n].iter().zip(values.iter()) {
                add(id.pixel, *v);
            }
        }
        if let Some(aovs) = out.aovs {
            aovs.add_samples(
                ctx.reconstruction,
                self.ids[..n].iter().map(|id| id.pixel),
                &self.film[..n],
                &self.filter_weight,
                &self.first_hits[..n],
            );
        }
    }

    fn rays(&self) -> u64 {
        self.state.rays
    }
}

impl Worker {
    /// The batch's sample ids (pixel-major) and camera rays; returns their
    /// number.
    fn generate(
        &mut self,
        scene: &RenderScene,
        b: Batch,
        reconstruction: &Reconstruction,
    ) -> usize {
        let width = scene.settings.width;
        self.ids.clear();
        for y in b.y0..b.y1 {
            for x in b.x0..b.x1 {
                for index in b.first_sample..b.first_sample + b.samples {
                    self.ids.push(SampleId {
                        pixel: y * width + x,
                        index,
                    });
                }
            }
        }
        let n = self.ids.len();
        for v in [&mut self.film, &mut self.lens] {
            v.resize(n, Vec2::ZERO);
        }
        scene.sampler.fill_2d(&self.ids, 0, &mut self.film);
        scene.sampler.fill_2d(&self.ids, 2, &mut self.lens);
        self.filter_weight.resize(n, 1.0);
        if let Reconstruction::Importance(filter) = reconstruction {
            for (f, w) in self.film.iter_mut().zip(&mut self.filter_weight) {
                let (offset, weight) = filter.sample(*f);
                *f = Vec2::splat(0.5) + offset;
                *w = weight;
            }
        }
        for (f, id) in self.film.iter_mut().zip(&self.ids) {
            *f += Vec2::new((id.pixel % width) as f32, (id.pixel / width) as f32);
        }
        self.origin.resize(n, Vec3::ZERO);
        self.dir.resize(n, Vec3::ZERO);
        self.weight.resize(n, 0.0);
        scene.camera.generate(
            &self.film,
            &self.lens,
            CameraRays {
                origins: &mut self.origin,
                directions: &mut self.dir,
                weights: &mut self.weight,
            },
        );
        n
    }
}

/// The most vertices a subpath may have under `max_depth`.
fn depth_limit(scene: &RenderScene) -> u32 {
    match scene.settings.max_depth {
        d if d < 0 => UNLIMITED_DEPTH_CAP,
        d => d as u32,
    }
}

impl State {
    /// The weight of strategy (s, t) given its MIS weight `w`: `w`, or
    /// with `strategy:` set 1 for that strategy and 0 for the others.
    fn strategy(&self, s: usize, t: usize, w: f32) -> f32 {
        match self.only {
            None => w,
            Some(only) => f32::from(u8::from(only == (s, t))),
        }
    }

    /// What each camera ray of the chunk (from `origin`) found first (the
    /// output variables'), into `out`: one `Shader::albedo` call per
    /// material.
    fn first_hits(
        &mut self,
        scene: &RenderScene,
        shade: &mut ShadeContext<'_>,
        origin: &[Vec3],
        out: &mut [FirstHit],
    ) {
        self.queue.clear();
        self.req.clear();
        for j in 0..out.len() {
            if self.camera.len(j) >= 2 {
                self.queue.push_albedo(scene, self.camera.at(j, 1));
                self.req.push(j as u32);
            }
        }
        self.queue.run(scene, shade, Op::Albedo);
        for (&j, &albedo) in self.req.iter().zip(&self.queue.albedos) {
            let j = j as usize;
            let v = self.camera.at(j, 1);
            out[j] = FirstHit {
                alpha: 1.0,
                albedo,
                normal: v.it.frame.n,
                depth: (v.it.p - origin[j]).length(),
                position: (v.it.p.as_dvec3() + scene.render_origin).as_vec3(),
            };
        }
    }
}

#[cfg(test)]
mod tests {
    // `unwrap` in this test code is the assertion: the inputs are the test's
    // own, so a failure is a bug, and the panic reports it with the error.
    use super::*;
    use radiant_core::params::check_param_docs;

    #[test]
    fn documented_parameters_match() {
        check_param_docs::<BdptParams>(DOCS).unwrap();
    }

    #[test]
    fn dimensions_of_vertices_do_not_overlap() {
        // Each vertex index owns VERTEX_DIMS dimensions after the camera's
        // and the light subpath's start; the last one used is the lens
        // pair at +11..+12. The cache draws follow the last index's.
        assert_eq!(dims(0), CAMERA_DIMS + LIGHT_DIMS);
        assert_eq!(dims(1) - dims(0), VERTEX_DIMS);
        const { assert!(11 + 2 <= VERTEX_DIMS) };
        assert!(cache_dim(8, 1) >= dims(8));
    }
}
