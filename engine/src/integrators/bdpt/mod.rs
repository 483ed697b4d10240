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
//! * s ≥ 2, t ≥ 2: each camera vertex connected to each light vertex, with
//!   a shadow ray;
//! * t = 1: each light vertex connected to the lens
//!   ([`radiant_core::Importance::sample_wi`]) and splatted where it lands
//!   on the film, anywhere in the image.
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

mod mis;
mod vertex;

use self::mis::{Mis, Side, ratio2, side_sum, weight};
use self::vertex::{Kind, Shading, Subpath, Vertex};
use super::module::{
    Batch, Family, Integrator, TileContext, TileIntegrator, TileOutput, TileWorker,
};
use super::splat::SplatFilm;
use super::surface::{Derivatives, interaction, interaction_with_derivatives};
use crate::accel::offset::{offset_origin, sampled_point_error};
use crate::extract::{NO_EMITTER, RenderScene};
use crate::film::Reconstruction;
use crate::film::aov::FirstHit;
use crate::film::exact::BLOCK;
use glam::{Vec2, Vec3};
use radiant_core::{
    BuildContext, CameraRayPdf, CameraRays, Effects, EmissionKind, EmissionPdf, EmissionSample,
    EmittedRay, EmitterEval, EmitterHit, LensSample, LightSample, ModuleInfo, ParamDoc, ParamError,
    Params, Registry, Rgb, SampleId,
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
/// Shadow rays stop this fraction short of their end (as `path`'s).
const SHADOW_EPSILON: f32 = 1e-4;

/// The first sampler dimension of vertex index `d`.
#[inline]
fn dims(d: u32) -> u32 {
    CAMERA_DIMS + LIGHT_DIMS + d * VERTEX_DIMS
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
             importance side (`Camera::importance`); use `perspective`, `thin_lens` or \
             `orthographic`, or the `path` integrator"
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

/// The `bdpt` integrator (see the module documentation).
#[derive(Debug, Clone, Copy, Default)]
pub struct Bdpt {
    /// The one strategy (s, t) to render, unweighted (`strategy: [s, t]`),
    /// or `None` for all of them, weighted.
    only: Option<(usize, usize)>,
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

    fn worker(&self) -> Box<dyn TileWorker + '_> {
        Box::new(Worker {
            only: self.only,
            ..Worker::default()
        })
    }
}

/// `bdpt`'s own key (`max_depth`, `rr_depth` and `light_selection` are
/// the loader's).
#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct BdptParams {
    strategy: Option<[u32; 2]>,
}

const DOCS: &[ParamDoc] = &[ParamDoc {
    name: "strategy",
    ty: "[s, t]",
    default: "none (all, weighted)",
    doc: "Render one strategy alone, unweighted: s light vertices, t ≥ 1 camera vertices — \
          its image is the contribution of paths of s + t − 1 segments that this strategy \
          can make (Veach's per-strategy images). For validation.",
}];

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
            Ok(Box::new(Bdpt { only }))
        },
    );
}

/// How a light subpath started: which light, and its emitted ray.
#[derive(Debug, Clone, Copy)]
struct Start {
    light: usize,
    sample: EmissionSample,
}

/// One thread's state: the batch's camera rays and both subpaths.
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
    only: Option<(usize, usize)>,
    camera: Subpath,
    light: Subpath,
    rays: u64,
}

impl TileWorker for Worker {
    fn render(&mut self, ctx: &TileContext<'_>, batch: Batch, mut out: TileOutput<'_>) {
        let scene = ctx.scene;
        let n = self.generate(scene, batch, ctx.reconstruction);
        let count = batch.samples as usize;
        let mut shading = Shading::new(scene);
        self.values.clear();
        self.values.resize(n, Rgb::ZERO);
        if out.aovs.is_some() {
            self.first_hits.clear();
            self.first_hits.resize(n, FirstHit::default());
        }
        let values = &mut self.values;
        for (i, value) in values.iter_mut().enumerate() {
            let mut sample = Sample {
                scene,
                id: self.ids[i],
                shading: &mut shading,
                camera: &mut self.camera,
                light: &mut self.light,
                splats: ctx.splats,
                rays: 0,
                only: self.only,
            };
            *value = sample.run(self.origin[i], self.dir[i], self.weight[i]);
            self.rays += sample.rays;
            if out.aovs.is_some() {
                self.first_hits[i] = first_hit(scene, &mut shading, &self.camera, self.origin[i]);
            }
        }
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
        self.rays
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

/// What the camera ray of a sample whose camera subpath is `camera`
/// found first (the output variables'), from the ray's `origin`.
fn first_hit(
    scene: &RenderScene,
    shading: &mut Shading<'_>,
    camera: &Subpath,
    origin: Vec3,
) -> FirstHit {
    match camera.v.get(1) {
        Some(v) => FirstHit {
            alpha: 1.0,
            albedo: shading.albedo(v),
            normal: v.it.frame.n,
            depth: (v.it.p - origin).length(),
            position: (v.it.p.as_dvec3() + scene.render_origin).as_vec3(),
        },
        None => FirstHit::default(),
    }
}

/// Everything one camera sample's strategies share.
struct Sample<'s, 'a> {
    scene: &'a RenderScene,
    id: SampleId,
    shading: &'s mut Shading<'a>,
    camera: &'s mut Subpath,
    light: &'s mut Subpath,
    splats: Option<&'a SplatFilm>,
    rays: u64,
    only: Option<(usize, usize)>,
}

/// The most vertices a subpath may have under `max_depth`.
fn depth_limit(scene: &RenderScene) -> u32 {
    match scene.settings.max_depth {
        d if d < 0 => UNLIMITED_DEPTH_CAP,
        d => d as u32,
    }
}

impl Sample<'_, '_> {
    /// The weight of strategy (s, t) given its MIS weight `w`: `w`, or
    /// with `strategy:` set 1 for that strategy and 0 for the others.
    fn mis(&self, s: usize, t: usize, w: f32) -> f32 {
        match self.only {
            None => w,
            Some(only) => f32::from(u8::from(only == (s, t))),
        }
    }

    fn u1(&self, dim: u32) -> f32 {
        let mut out = [0.0];
        self.scene
            .sampler
            .fill_1d(std::slice::from_ref(&self.id), dim, &mut out);
        out[0]
    }

    fn u2(&self, dim: u32) -> Vec2 {
        let mut out = [Vec2::ZERO];
        self.scene
            .sampler
            .fill_2d(std::slice::from_ref(&self.id), dim, &mut out);
        out[0]
    }

    /// Samples the direction leaving `v` with the sampler dimensions from
    /// `d` (lobe, direction): the sample, and the solid-angle density of
    /// the reverse direction (`v.wo` given the sampled one; for a delta
    /// lobe its own choice probability). `None` where sampling failed or
    /// the direction leaves on the wrong side of the geometric surface.
    fn scatter(&mut self, v: &Vertex, d: u32) -> Option<(radiant_core::BsdfSample, f32)> {
        let u = self.u2(d + 1);
        let s = self.shading.sample(v, v.wo, [self.u1(d), u.x, u.y]);
        if s.pdf <= 0.0 || s.weight == Rgb::ZERO || !v.consistent(s.wi) {
            return None;
        }
        let rev = if s.delta {
            s.pdf
        } else {
            self.shading.eval(v, s.wi, v.wo).pdf
        };
        Some((s, rev))
    }

    /// Whether the segment from `a` to `b` (surface or light points) is
    /// unblocked.
    fn visible(&mut self, a: &Vertex, b: &Vertex) -> bool {
        self.rays += 1;
        let w = (b.it.p - a.it.p).normalize_or_zero();
        let end = |v: &Vertex, w: Vec3| match v.kind {
            Kind::Surface => offset_origin(v.it.p, v.it.err, v.it.ng, w),
            _ if v.it.ng != Vec3::ZERO => {
                offset_origin(v.it.p, sampled_point_error(v.it.p), v.it.ng, w)
            }
            _ => v.it.p,
        };
        let from = end(a, w);
        let to = end(b, -w);
        !self
            .scene
            .accel
            .occluded(from, to - from, 1.0 - SHADOW_EPSILON)
    }

    /// Renders the sample: returns the camera strategies' radiance and
    /// splats the light strategies'.
    fn run(&mut self, origin: Vec3, dir: Vec3, weight: f32) -> Rgb {
        let max = depth_limit(self.scene);
        self.light.clear();
        if max >= 1 && !self.scene.lights.is_empty() {
            self.trace_light(max);
        }
        self.camera.clear();
        if weight <= 0.0 || max == 0 {
            return Rgb::ZERO;
        }
        self.trace_camera(origin, dir, weight, max)
    }

    /// Resolves the hit of the ray (`origin`, `dir`), if any, as a surface
    /// vertex with throughput `beta`.
    fn hit(&mut self, origin: Vec3, dir: Vec3, beta: Rgb) -> Option<(Vertex, u32)> {
        self.rays += 1;
        let scene = self.scene;
        let hit = scene.accel.intersect(origin, dir, f32::INFINITY)?;
        let (it, derivs) = if scene.effects.contains(Effects::TANGENT_FRAMES) {
            interaction_with_derivatives(scene, &hit, origin, dir, 0.0)
        } else {
            (
                interaction(scene, &hit, origin, dir, 0.0),
                Derivatives::default(),
            )
        };
        let v = Vertex {
            kind: Kind::Surface,
            it,
            derivs,
            material: scene.material(&hit),
            wo: -dir,
            beta,
        };
        Some((v, hit.prim))
    }

    /// Traces the light subpath, connecting each vertex to the lens (t = 1).
    fn trace_light(&mut self, max: u32) {
        let scene = self.scene;
        let (l, pmf, _) = scene.lights.select(self.u1(CAMERA_DIMS));
        let Some(emission) = scene.lights.lights()[l].emission() else {
            return;
        };
        let mut es = [EmissionSample::default()];
        emission.sample_emission(
            &[self.u2(CAMERA_DIMS + 1)],
            &[self.u2(CAMERA_DIMS + 3)],
            &mut es,
        );
        let es = es[0];
        if !(es.pdf_pos > 0.0 && es.pdf_dir > 0.0 && pmf > 0.0) || es.radiance == Rgb::ZERO {
            return;
        }
        let start = Start {
            light: l,
            sample: es,
        };
        let kind = es.kind;
        // The light vertex: L₁ in the measure of its kind, its throughput
        // before the direction (a surface light's, for t = 1).
        let fwd = pmf
            * match kind {
                EmissionKind::Surface | EmissionKind::Point => es.pdf_pos,
                EmissionKind::Infinite => es.pdf_dir,
                EmissionKind::Directional => 1.0,
            };
        let beta0 = es.radiance / (pmf * es.pdf_pos);
        let hittable = matches!(kind, EmissionKind::Surface | EmissionKind::Infinite);
        let v0 = Vertex::point(Kind::Light(kind), es.p, es.n, beta0);
        self.light.push(
            v0,
            Mis {
                fwd,
                delta: false,
                eps: f32::from(u8::from(hittable)),
                acc: 0.0,
            },
        );
        if kind == EmissionKind::Surface {
            self.connect_lens(0);
        }
        let mut beta = match kind {
            EmissionKind::Surface => {
                es.radiance * (es.n.dot(es.dir).abs() / (pmf * es.pdf_pos * es.pdf_dir))
            }
            EmissionKind::Point => es.radiance / (pmf * es.pdf_dir),
            EmissionKind::Infinite => es.radiance / (pmf * es.pdf_dir * es.pdf_pos),
            EmissionKind::Directional => es.radiance / (pmf * es.pdf_pos),
        };
        let mut origin = if es.n == Vec3::ZERO {
            es.p
        } else {
            offset_origin(es.p, sampled_point_error(es.p), es.n, es.dir)
        };
        let mut dir = es.dir;
        // Survival is judged on the throughput relative to the emitted ray's.
        let mut scale = 1.0f32;
        let mut pdf_dir = es.pdf_dir;
        for k in 1..max as usize {
            let Some((v, _)) = self.hit(origin, dir, beta) else {
                break;
            };
            let fwd =
                if k == 1 && matches!(kind, EmissionKind::Infinite | EmissionKind::Directional) {
                    es.pdf_pos * v.it.ng.dot(dir).abs()
                } else {
                    v.area_density(self.light.v[k - 1].it.p, pdf_dir)
                };
            let eps = if k == 1 {
                self.next_event_ratio(&start, &v)
            } else {
                1.0
            };
            self.light.push(
                v,
                Mis {
                    fwd,
                    delta: false,
                    eps,
                    acc: 0.0,
                },
            );
            if self.shading.connectable(&v) {
                self.connect_lens(k);
            }
            if k + 1 >= max as usize {
                break;
            }
            let d = dims(k as u32 - 1) + 7;
            let Some((s, rev)) = self.scatter(&v, d) else {
                break;
            };
            let prev = self.light.v[k - 1];
            let rev_area = match prev.kind {
                Kind::Light(EmissionKind::Infinite) => rev,
                _ => prev.area_density(v.it.p, rev),
            };
            self.light.mis[k].delta = s.delta;
            mis::complete(&mut self.light.mis, k - 1, Side::Light, rev_area);
            // Importance transport: no 1/η², shading normals corrected.
            let ng = v.it.ng;
            let correction = (v.wo.dot(v.it.frame.n) * s.wi.dot(ng)).abs()
                / (v.wo.dot(ng) * s.wi.dot(v.it.frame.n)).abs();
            let factor = s.weight * (s.eta * s.eta * correction);
            if !factor.is_finite() {
                break;
            }
            beta *= factor;
            scale *= factor.max_element();
            if k as u32 >= scene.settings.rr_depth && scale < 1.0 {
                if self.u1(d + 3) >= scale {
                    break;
                }
                beta /= scale;
                scale = 1.0;
            }
            origin = offset_origin(v.it.p, v.it.err, ng, s.wi);
            dir = s.wi;
            pdf_dir = s.pdf;
        }
    }

    /// (D / L)² of the light subpath's start seen from its second vertex
    /// `v`: next-event estimation's density of the light point against
    /// the emitted ray's.
    fn next_event_ratio(&self, start: &Start, v: &Vertex) -> f32 {
        let es = &start.sample;
        let light = &self.scene.lights.lights()[start.light];
        match es.kind {
            EmissionKind::Point | EmissionKind::Directional => 1.0,
            EmissionKind::Surface => {
                let mut e = [EmitterEval::default()];
                let hit = EmitterHit {
                    origin: v.it.p,
                    p: es.p,
                    n: es.n,
                    primitive: es.primitive,
                };
                light.eval_hits(&[hit], &mut e);
                let light_vertex = Vertex::point(Kind::Light(es.kind), es.p, es.n, Rgb::ZERO);
                ratio2(light_vertex.area_density(v.it.p, e[0].pdf), es.pdf_pos)
            }
            EmissionKind::Infinite => {
                let mut e = [EmitterEval::default()];
                light.eval_escaped(&[-es.dir], &mut e);
                ratio2(e[0].pdf, es.pdf_dir)
            }
        }
    }

    /// The t = 1 strategy: light vertex `k` connected to the lens and
    /// splatted where it lands.
    fn connect_lens(&mut self, k: usize) {
        let scene = self.scene;
        let Some(splats) = self.splats else { return };
        let Some(importance) = scene.camera.importance() else {
            return;
        };
        let b = self.light.v[k];
        let mut ls = [LensSample::default()];
        importance.sample_wi(&[b.it.p], &[self.u2(dims(k as u32) + 11)], &mut ls);
        let ls = ls[0];
        if ls.pdf <= 0.0 || ls.importance <= 0.0 {
            return;
        }
        let w = ls.wi;
        let (value, rev_prev) = match b.kind {
            Kind::Light(EmissionKind::Surface) => {
                let cos = b.it.ng.dot(w);
                if cos <= 0.0 {
                    return;
                }
                (b.beta * cos, 0.0)
            }
            Kind::Surface => {
                if !b.consistent(w) {
                    return;
                }
                let f = self.shading.eval(&b, w, b.wo);
                if f.value == Rgb::ZERO {
                    return;
                }
                let correction = b.it.ng.dot(w).abs() / b.it.ng.dot(b.wo).abs();
                let prev = self.light.v[k - 1];
                let rev_prev = match prev.kind {
                    Kind::Light(EmissionKind::Infinite) => f.pdf,
                    _ => prev.area_density(b.it.p, f.pdf),
                };
                (b.beta * f.value * correction, rev_prev)
            }
            _ => return,
        };
        let value = value * (ls.importance / ls.pdf);
        if value == Rgb::ZERO || !value.is_finite() {
            return;
        }
        let mut pdf = [CameraRayPdf::default()];
        importance.pdf_ray(&[(ls.p, -w)], &mut pdf);
        let rev_end = if importance.directional() {
            pdf[0].pdf_pos * b.it.ng.dot(w).abs()
        } else {
            b.area_density(ls.p, pdf[0].pdf_dir)
        };
        let light_sum = side_sum(&self.light.mis[..=k], Side::Light, k, rev_end, rev_prev);
        let lens = Vertex::point(Kind::Camera, ls.p, Vec3::ZERO, Rgb::ONE);
        if !self.visible(&b, &lens) {
            return;
        }
        splats.splat(
            ls.raster,
            value * self.mis(k + 1, 1, weight(0.0, light_sum, 1.0)),
        );
    }

    /// Traces the camera subpath and adds every strategy with t ≥ 2 and
    /// s = 0; returns their sum.
    fn trace_camera(&mut self, origin: Vec3, dir: Vec3, weight0: f32, max: u32) -> Rgb {
        let scene = self.scene;
        let Some(importance) = scene.camera.importance() else {
            return Rgb::ZERO;
        };
        let mut pdf = [CameraRayPdf::default()];
        importance.pdf_ray(&[(origin, dir)], &mut pdf);
        let mut beta = Rgb::splat(weight0);
        self.camera.push(
            Vertex::point(Kind::Camera, origin, Vec3::ZERO, beta),
            Mis {
                fwd: 1.0,
                delta: false,
                eps: 1.0,
                acc: 0.0,
            },
        );
        let mut radiance = Rgb::ZERO;
        let (mut ray_origin, mut ray_dir) = (origin, dir);
        let mut pdf_dir = pdf[0].pdf_dir;
        let mut eta_scale = 1.0f32;
        for i in 1..=max as usize {
            let Some((v, prim)) = self.hit(ray_origin, ray_dir, beta) else {
                radiance += self.escaped(ray_dir, beta, pdf_dir);
                break;
            };
            let fwd = if i == 1 && importance.directional() {
                // One direction for every ray: the window's density,
                // projected onto the surface.
                pdf[0].pdf_pos * v.it.ng.dot(ray_dir).abs()
            } else {
                v.area_density(self.camera.v[i - 1].it.p, pdf_dir)
            };
            self.camera.push(
                v,
                Mis {
                    fwd,
                    delta: false,
                    eps: 1.0,
                    acc: 0.0,
                },
            );
            let emitter = scene.surfaces.emitter[prim as usize];
            if emitter != NO_EMITTER {
                let primitive = scene.surfaces.emitter_prim[prim as usize];
                radiance += self.hit_emitter(i, emitter as usize, primitive);
            }
            if i >= max as usize {
                break;
            }
            if self.shading.connectable(&v) {
                radiance += self.next_event(i, max);
                radiance += self.connect_light(i, max);
            }
            let d = dims(i as u32 - 1);
            let Some((s, rev)) = self.scatter(&v, d) else {
                break;
            };
            let prev = self.camera.v[i - 1];
            self.camera.mis[i].delta = s.delta;
            mis::complete(
                &mut self.camera.mis,
                i - 1,
                Side::Camera,
                prev.area_density(v.it.p, rev),
            );
            beta *= s.weight;
            eta_scale *= s.eta * s.eta;
            let survival = beta.max_element() * eta_scale;
            if !beta.is_finite() || survival <= 0.0 {
                break;
            }
            if i as u32 >= scene.settings.rr_depth && survival < 1.0 {
                if self.u1(d + 3) >= survival {
                    break;
                }
                beta /= survival;
            }
            ray_origin = offset_origin(v.it.p, v.it.err, v.it.ng, s.wi);
            ray_dir = s.wi;
            pdf_dir = s.pdf;
        }
        radiance
    }

    /// s = 0 on a surface emitter: camera vertex `i` lies on light `l`.
    fn hit_emitter(&mut self, i: usize, l: usize, primitive: u32) -> Rgb {
        let scene = self.scene;
        let v = self.camera.v[i];
        let prev = self.camera.v[i - 1];
        let light = &scene.lights.lights()[l];
        let mut e = [EmitterEval::default()];
        let hit = EmitterHit {
            origin: prev.it.p,
            p: v.it.p,
            n: v.it.ng,
            primitive,
        };
        light.eval_hits(&[hit], &mut e);
        if e[0].radiance == Rgb::ZERO {
            return Rgb::ZERO;
        }
        let value = v.beta * e[0].radiance;
        let pmf = scene.lights.pmf(l);
        let Some(emission) = light.emission() else {
            return value;
        };
        let mut em = [EmissionPdf::default()];
        let ray = EmittedRay {
            p: v.it.p,
            n: v.it.ng,
            dir: v.wo,
            primitive,
        };
        emission.emission_pdf(&[ray], &mut em);
        let l_fwd = pmf * em[0].pdf_pos;
        let d = pmf * v.area_density(prev.it.p, e[0].pdf);
        let rev_prev = prev.area_density(v.it.p, em[0].pdf_dir);
        let saved = self.camera.mis[i].eps;
        self.camera.mis[i].eps = if i >= 2 { ratio2(d, l_fwd) } else { 1.0 };
        let sum = side_sum(&self.camera.mis[..=i], Side::Camera, i, l_fwd, rev_prev);
        self.camera.mis[i].eps = saved;
        value * self.mis(0, i + 1, weight(sum, 0.0, 1.0))
    }

    /// s = 0 towards the environment: the camera ray left the scene along
    /// `dir` from its last vertex with throughput `beta`, drawn with
    /// solid-angle density `pdf_dir`.
    fn escaped(&mut self, dir: Vec3, beta: Rgb, pdf_dir: f32) -> Rgb {
        let scene = self.scene;
        let i = self.camera.len();
        let prev = self.camera.v[i - 1];
        let mut total = Rgb::ZERO;
        for &l in scene.lights.environment() {
            let light = &scene.lights.lights()[l];
            let mut e = [EmitterEval::default()];
            light.eval_escaped(&[dir], &mut e);
            if e[0].radiance == Rgb::ZERO {
                continue;
            }
            let value = beta * e[0].radiance;
            let Some(emission) = light.emission() else {
                total += value;
                continue;
            };
            let pmf = scene.lights.pmf(l);
            let mut em = [EmissionPdf::default()];
            let ray = EmittedRay {
                p: prev.it.p,
                n: Vec3::ZERO,
                dir: -dir,
                primitive: 0,
            };
            emission.emission_pdf(&[ray], &mut em);
            let l_fwd = pmf * em[0].pdf_dir;
            let d = pmf * e[0].pdf;
            let rev_prev = em[0].pdf_pos * prev.it.ng.dot(dir).abs();
            self.camera.mis.push(Mis {
                fwd: pdf_dir,
                delta: false,
                eps: if i >= 2 { ratio2(d, l_fwd) } else { 0.0 },
                acc: 0.0,
            });
            let sum = side_sum(&self.camera.mis, Side::Camera, i, l_fwd, rev_prev);
            self.camera.mis.pop();
            total += value * self.mis(0, i + 1, weight(sum, 0.0, 1.0));
        }
        total
    }

    /// s = 1, t = i + 1: next-event estimation at camera vertex `i`.
    fn next_event(&mut self, i: usize, max: u32) -> Rgb {
        let scene = self.scene;
        if scene.lights.is_empty() || i + 1 > max as usize {
            return Rgb::ZERO;
        }
        let d = dims(i as u32 - 1) + 4;
        let (l, pmf, _) = scene.lights.select(self.u1(d));
        let light = &scene.lights.lights()[l];
        let Some(emission) = light.emission() else {
            return Rgb::ZERO;
        };
        let a = self.camera.v[i];
        let mut ls = [LightSample::default()];
        light.sample(&[a.it.p], &[self.u2(d + 1)], &mut ls);
        let ls = ls[0];
        if ls.pdf <= 0.0 || pmf <= 0.0 {
            return Rgb::ZERO;
        }
        let w = (ls.p - a.it.p).normalize_or_zero();
        if !a.consistent(w) {
            return Rgb::ZERO;
        }
        let f = self.shading.eval(&a, a.wo, w);
        let value = a.beta * f.value * ls.radiance / (pmf * ls.pdf);
        if value == Rgb::ZERO || !value.is_finite() {
            return Rgb::ZERO;
        }
        let kind = emission.kind();
        let z = Vertex::point(Kind::Light(kind), ls.p, ls.n, Rgb::ZERO);
        let mut em = [EmissionPdf::default()];
        let ray = EmittedRay {
            p: ls.p,
            n: ls.n,
            dir: -w,
            primitive: 0,
        };
        emission.emission_pdf(&[ray], &mut em);
        let em = em[0];
        let (l_fwd, direct, from_camera, to_camera) = match kind {
            EmissionKind::Surface => (
                pmf * em.pdf_pos,
                pmf * z.area_density(a.it.p, ls.pdf),
                z.area_density(a.it.p, f.pdf),
                a.area_density(ls.p, em.pdf_dir),
            ),
            EmissionKind::Point => (pmf, pmf, 0.0, a.area_density(ls.p, em.pdf_dir)),
            EmissionKind::Infinite => (
                pmf * em.pdf_dir,
                pmf * ls.pdf,
                f.pdf,
                em.pdf_pos * a.it.ng.dot(w).abs(),
            ),
            EmissionKind::Directional => (pmf, pmf, 0.0, em.pdf_pos * a.it.ng.dot(w).abs()),
        };
        let hittable = matches!(kind, EmissionKind::Surface | EmissionKind::Infinite);
        let light_mis = [Mis {
            fwd: l_fwd,
            delta: false,
            eps: f32::from(u8::from(hittable)),
            acc: 0.0,
        }];
        let light_sum = side_sum(&light_mis, Side::Light, 0, from_camera, 0.0);
        let prev = self.camera.v[i - 1];
        let rev_prev = prev.area_density(a.it.p, self.shading.eval(&a, w, a.wo).pdf);
        let camera_sum = side_sum(&self.camera.mis[..=i], Side::Camera, i, to_camera, rev_prev);
        if !self.visible(&a, &z) {
            return Rgb::ZERO;
        }
        value
            * self.mis(
                1,
                i + 1,
                weight(camera_sum, light_sum, ratio2(direct, l_fwd)),
            )
    }

    /// s ≥ 2, t = i + 1: camera vertex `i` connected to every light vertex
    /// `k` ≥ 1 that `max` allows.
    fn connect_light(&mut self, i: usize, max: u32) -> Rgb {
        let mut total = Rgb::ZERO;
        let a = self.camera.v[i];
        let prev_a = self.camera.v[i - 1];
        for k in 1..self.light.len() {
            // Segments: (k + 1) + (i + 1) − 1.
            if k + i + 1 > max as usize {
                break;
            }
            let b = self.light.v[k];
            if !self.shading.connectable(&b) {
                continue;
            }
            let d = b.it.p - a.it.p;
            let dist2 = d.length_squared();
            if dist2 <= 0.0 {
                continue;
            }
            let w = d / dist2.sqrt();
            if !a.consistent(w) || !b.consistent(-w) {
                continue;
            }
            let fa = self.shading.eval(&a, a.wo, w);
            if fa.value == Rgb::ZERO {
                continue;
            }
            let fb = self.shading.eval(&b, -w, b.wo);
            if fb.value == Rgb::ZERO {
                continue;
            }
            let correction = b.it.ng.dot(w).abs() / b.it.ng.dot(b.wo).abs();
            let value = a.beta * fa.value * fb.value * b.beta * (correction / dist2);
            if value == Rgb::ZERO || !value.is_finite() {
                continue;
            }
            let prev_b = self.light.v[k - 1];
            let rev_a_prev = prev_a.area_density(a.it.p, self.shading.eval(&a, w, a.wo).pdf);
            let rev_a = a.area_density(b.it.p, self.shading.eval(&b, b.wo, -w).pdf);
            let rev_b = b.area_density(a.it.p, fa.pdf);
            let rev_b_prev = match prev_b.kind {
                Kind::Light(EmissionKind::Infinite) => fb.pdf,
                _ => prev_b.area_density(b.it.p, fb.pdf),
            };
            let camera_sum = side_sum(&self.camera.mis[..=i], Side::Camera, i, rev_a, rev_a_prev);
            let light_sum = side_sum(&self.light.mis[..=k], Side::Light, k, rev_b, rev_b_prev);
            if !self.visible(&a, &b) {
                continue;
            }
            total += value * self.mis(k + 1, i + 1, weight(camera_sum, light_sum, 1.0));
        }
        total
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
        // pair at +11..+12.
        assert_eq!(dims(0), CAMERA_DIMS + LIGHT_DIMS);
        assert_eq!(dims(1) - dims(0), VERTEX_DIMS);
        const { assert!(11 + 2 <= VERTEX_DIMS) };
    }
}
