//! The light subpaths of a chunk, walked one vertex index at a time for
//! all samples together: lights chosen in proportion to power and emitted
//! rays sampled (one `Emission` call per light), then closest hits,
//! importance-transport scattering (refraction's 1/η² left out, pbrt's
//! shading-normal correction) and Russian roulette relative to the
//! emitted ray's throughput. Each vertex index ends with the t = 1
//! strategy: its vertices connected to the lens (one `Importance` call
//! for the lens points, one for the camera rays' densities, one shader
//! call per material, one batch of shadow rays) and splatted where they
//! land.

use super::mis::{self, Mis, Side, ratio2, side_sum, weight};
use super::shading::Op;
use super::vertex::{Kind, Vertex};
use super::walk::{Which, fit};
use super::{CAMERA_DIMS, Start, State, dims, strategy_index};
use crate::accel::Hit;
use crate::accel::offset::{offset_origin, sampled_point_error};
use crate::extract::RenderScene;
use crate::integrators::splat::SplatFilm;
use crate::integrators::strategies::StrategyFilms;
use glam::Vec3;
use radiant_core::{EmissionKind, EmissionSample, EmitterHit, Rgb, ShadeContext};

impl State {
    /// Walks the chunk's light subpaths (into `self.light`), splatting
    /// their lens connections into `splats`.
    pub(super) fn trace_lights(
        &mut self,
        scene: &RenderScene,
        shade: &mut ShadeContext<'_>,
        splats: Option<&SplatFilm>,
        strategies: Option<&StrategyFilms>,
    ) {
        let n = self.ids.len();
        let max = self.max;
        self.light.reset(n, max.max(1));
        self.start_walk(n);
        if max < 1 || scene.lights.is_empty() {
            return;
        }
        self.start_lights(scene);
        self.connect_lens(scene, shade, (splats, strategies), 0);
        for k in 1..max {
            if self.live.is_empty() {
                break;
            }
            self.trace_closest(scene);
            self.light_vertices(scene, k);
            if k == 1 {
                self.next_event_ratios(scene);
            }
            self.connect_lens(scene, shade, (splats, strategies), k);
            if k + 1 >= max {
                break;
            }
            self.scatter(scene, shade, Which::Light, k, dims(k as u32 - 1) + 7);
            self.continue_lights(scene, k);
        }
    }

    /// Chooses each slot's light, samples its emitted ray and pushes the
    /// light vertex; the slots whose ray is valid become live.
    fn start_lights(&mut self, scene: &RenderScene) {
        let n = self.ids.len();
        fit(&mut self.u1, n);
        fit(&mut self.u2, n);
        fit(&mut self.u3, n);
        scene.sampler.fill_1d(&self.ids, CAMERA_DIMS, &mut self.u1);
        fit(&mut self.start, n);
        for (s, &u) in self.start.iter_mut().zip(&self.u1) {
            let (l, pmf, _) = scene.lights.select(u);
            *s = Start {
                light: l as u32,
                pmf,
                sample: EmissionSample::default(),
            };
        }
        let start = &self.start;
        self.by_light
            .sort(n, scene.lights.len(), |j| start[j as usize].light);
        // Sampler pairs in light order.
        self.req_ids.clear();
        let ids = &self.ids;
        self.req_ids
            .extend(self.by_light.order.iter().map(|&j| ids[j as usize]));
        scene
            .sampler
            .fill_2d(&self.req_ids, CAMERA_DIMS + 1, &mut self.u2);
        scene
            .sampler
            .fill_2d(&self.req_ids, CAMERA_DIMS + 3, &mut self.u3);
        self.emitted.clear();
        self.emitted.resize(n, EmissionSample::default());
        for (l, r) in self.by_light.ranges() {
            if let Some(emission) = scene.lights.lights()[l].emission() {
                let (u, v) = (&self.u2[r.clone()], &self.u3[r.clone()]);
                emission.sample_emission(u, v, &mut self.emitted[r]);
            }
        }
        for (&j, es) in self.by_light.order.iter().zip(&self.emitted) {
            self.start[j as usize].sample = *es;
        }
        for j in 0..n {
            let Start {
                pmf, sample: es, ..
            } = self.start[j];
            if !(es.pdf_pos > 0.0 && es.pdf_dir > 0.0 && pmf > 0.0) || es.radiance == Rgb::ZERO {
                continue;
            }
            let kind = es.kind;
            // The light vertex: L₁ in the measure of its kind, its
            // throughput before the direction (a surface light's, for
            // t = 1).
            let fwd = pmf
                * match kind {
                    EmissionKind::Surface | EmissionKind::Point => es.pdf_pos,
                    EmissionKind::Infinite => es.pdf_dir,
                    EmissionKind::Directional => 1.0,
                };
            let beta0 = es.radiance / (pmf * es.pdf_pos);
            let hittable = matches!(kind, EmissionKind::Surface | EmissionKind::Infinite);
            let v0 = Vertex::point(Kind::Light(kind), es.p, es.n, beta0);
            let mis = Mis {
                fwd,
                delta: false,
                eps: f32::from(u8::from(hittable)),
                acc: 0.0,
            };
            self.light.push(j, v0, mis);
            self.beta[j] = match kind {
                EmissionKind::Surface => {
                    es.radiance * (es.n.dot(es.dir).abs() / (pmf * es.pdf_pos * es.pdf_dir))
                }
                EmissionKind::Point => es.radiance / (pmf * es.pdf_dir),
                EmissionKind::Infinite => es.radiance / (pmf * es.pdf_dir * es.pdf_pos),
                EmissionKind::Directional => es.radiance / (pmf * es.pdf_pos),
            };
            self.origin[j] = if es.n == Vec3::ZERO {
                es.p
            } else {
                offset_origin(es.p, sampled_point_error(es.p), es.n, es.dir)
            };
            self.dir[j] = es.dir;
            self.pdf_dir[j] = es.pdf_dir;
            // Survival is judged on the throughput relative to the
            // emitted ray's.
            self.scale[j] = 1.0;
            self.live.push(j as u32);
        }
    }

    /// Pushes vertex `k` of every live slot whose ray hit a surface; the
    /// others leave the walk.
    fn light_vertices(&mut self, scene: &RenderScene, k: usize) {
        self.next.clear();
        for idx in 0..self.live.len() {
            let j = self.live[idx] as usize;
            let hit = self.hit[j];
            if hit.prim == Hit::MISS.prim {
                continue;
            }
            let v = self.surface_vertex(scene, j, &hit);
            let es = &self.start[j].sample;
            let fwd = if k == 1
                && matches!(es.kind, EmissionKind::Infinite | EmissionKind::Directional)
            {
                es.pdf_pos * v.it.ng.dot(self.dir[j]).abs()
            } else {
                v.area_density(self.light.at(j, k - 1).it.p, self.pdf_dir[j])
            };
            self.light.push(j, v, Self::reached(fwd));
            self.next.push(j as u32);
        }
        std::mem::swap(&mut self.live, &mut self.next);
    }

    /// (D / L)² of each live slot's light vertex seen from its vertex 1:
    /// next-event estimation's density of the light point against the
    /// emitted ray's, into vertex 1's `eps` (one `Light` call per light).
    fn next_event_ratios(&mut self, scene: &RenderScene) {
        let live = &self.live;
        let start = &self.start;
        self.by_light.sort(live.len(), scene.lights.len(), |r| {
            start[live[r as usize] as usize].light
        });
        let n = self.live.len();
        fit(&mut self.emitter_hits, n);
        fit(&mut self.emitter_evals, n);
        fit(&mut self.dirs, n);
        for (l, r) in self.by_light.ranges() {
            let light = &scene.lights.lights()[l];
            let Some(emission) = light.emission() else {
                continue;
            };
            let kind = emission.kind();
            for p in r.clone() {
                let j = self.live[self.by_light.order[p] as usize] as usize;
                let es = &self.start[j].sample;
                self.emitter_hits[p] = EmitterHit {
                    origin: self.light.at(j, 1).it.p,
                    p: es.p,
                    n: es.n,
                    primitive: es.primitive,
                };
                self.dirs[p] = -es.dir;
            }
            match kind {
                EmissionKind::Surface => light.eval_hits(
                    &self.emitter_hits[r.clone()],
                    &mut self.emitter_evals[r.clone()],
                ),
                EmissionKind::Infinite => {
                    light.eval_escaped(&self.dirs[r.clone()], &mut self.emitter_evals[r.clone()])
                }
                EmissionKind::Point | EmissionKind::Directional => {}
            }
            for p in r {
                let j = self.live[self.by_light.order[p] as usize] as usize;
                let es = self.start[j].sample;
                let e = self.emitter_evals[p];
                let eps = match kind {
                    EmissionKind::Point | EmissionKind::Directional => 1.0,
                    EmissionKind::Surface => {
                        let from = self.light.at(j, 1).it.p;
                        ratio2(self.light.at(j, 0).area_density(from, e.pdf), es.pdf_pos)
                    }
                    EmissionKind::Infinite => ratio2(e.pdf, es.pdf_dir),
                };
                self.light.mis_mut(j, 1)[1].eps = eps;
            }
        }
    }

    /// Follows the live slots' scattering from vertex `k` (after
    /// [`State::scatter`]): completes the MIS state two vertices behind,
    /// updates throughput and roulette; the slots that go on stay live.
    fn continue_lights(&mut self, scene: &RenderScene, k: usize) {
        self.next.clear();
        for r in 0..self.req.len() {
            let j = self.req[r] as usize;
            let s = self.bsdf[r];
            if s.pdf <= 0.0 {
                continue;
            }
            let rev = self.aux[r];
            let v = *self.light.at(j, k);
            let prev = self.light.at(j, k - 1);
            let rev_area = match prev.kind {
                Kind::Light(EmissionKind::Infinite) => rev,
                _ => prev.area_density(v.it.p, rev),
            };
            let m = self.light.mis_mut(j, k);
            m[k].delta = s.delta;
            mis::complete(m, k - 1, Side::Light, rev_area);
            // Importance transport: no 1/η², shading normals corrected.
            let ng = v.it.ng;
            let correction = (v.wo.dot(v.it.frame.n) * s.wi.dot(ng)).abs()
                / (v.wo.dot(ng) * s.wi.dot(v.it.frame.n)).abs();
            let factor = s.weight * (s.eta * s.eta * correction);
            if !factor.is_finite() {
                continue;
            }
            self.beta[j] *= factor;
            self.scale[j] *= factor.max_element();
            let scale = self.scale[j];
            if k as u32 >= scene.settings.rr_depth && scale < 1.0 {
                if self.u1[r] >= scale {
                    continue;
                }
                self.beta[j] /= scale;
                self.scale[j] = 1.0;
            }
            self.origin[j] = offset_origin(v.it.p, v.it.err, ng, s.wi);
            self.dir[j] = s.wi;
            self.pdf_dir[j] = s.pdf;
            self.next.push(j as u32);
        }
        std::mem::swap(&mut self.live, &mut self.next);
    }

    /// The t = 1 strategy for vertex `k` of every live slot: connected to
    /// the lens and splatted where it lands.
    fn connect_lens(
        &mut self,
        scene: &RenderScene,
        shade: &mut ShadeContext<'_>,
        (splats, strategies): (Option<&SplatFilm>, Option<&StrategyFilms>),
        k: usize,
    ) {
        let Some(splats) = splats else { return };
        let Some(importance) = scene.camera.importance() else {
            return;
        };
        self.req.clear();
        for &j in &self.live {
            let b = self.light.at(j as usize, k);
            let reaches = match b.kind {
                Kind::Light(EmissionKind::Surface) => k == 0,
                _ => k > 0 && b.connectable,
            };
            if reaches {
                self.req.push(j);
            }
        }
        if self.req.is_empty() {
            return;
        }
        self.gather_ids();
        let n = self.req.len();
        fit(&mut self.u2, n);
        scene
            .sampler
            .fill_2d(&self.req_ids, dims(k as u32) + 11, &mut self.u2);
        self.refs.clear();
        let light = &self.light;
        self.refs
            .extend(self.req.iter().map(|&j| light.at(j as usize, k).it.p));
        fit(&mut self.lens, n);
        importance.sample_wi(&self.refs, &self.u2, &mut self.lens);
        // Shader calls at surface vertices.
        self.queue.clear();
        fit(&mut self.call, n);
        for r in 0..n {
            let b = self.light.at(self.req[r] as usize, k);
            let ls = self.lens[r];
            if b.kind == Kind::Surface && ls.pdf > 0.0 && ls.importance > 0.0 && b.consistent(ls.wi)
            {
                self.call[r] = self.queue.push_eval(scene, b, ls.wi, b.wo) as u32;
            }
        }
        self.queue.run(scene, shade, Op::Eval);
        // Values; the camera rays' densities of those that count.
        self.kept.clear();
        self.values.clear();
        self.aux.clear();
        self.camera_rays.clear();
        for r in 0..n {
            let j = self.req[r] as usize;
            let ls = self.lens[r];
            if ls.pdf <= 0.0 || ls.importance <= 0.0 {
                continue;
            }
            let b = self.light.at(j, k);
            let w = ls.wi;
            let (value, rev_prev) = match b.kind {
                Kind::Light(EmissionKind::Surface) => {
                    let cos = b.it.ng.dot(w);
                    if cos <= 0.0 {
                        continue;
                    }
                    (b.beta * cos, 0.0)
                }
                Kind::Surface => {
                    if !b.consistent(w) {
                        continue;
                    }
                    let f = self.queue.evals[self.call[r] as usize];
                    if f.value == Rgb::ZERO {
                        continue;
                    }
                    let correction = b.it.ng.dot(w).abs() / b.it.ng.dot(b.wo).abs();
                    let prev = self.light.at(j, k - 1);
                    let rev_prev = match prev.kind {
                        Kind::Light(EmissionKind::Infinite) => f.pdf,
                        _ => prev.area_density(b.it.p, f.pdf),
                    };
                    (b.beta * f.value * correction, rev_prev)
                }
                _ => continue,
            };
            let value = value * (ls.importance / ls.pdf);
            if value == Rgb::ZERO || !value.is_finite() {
                continue;
            }
            self.kept.push(r as u32);
            self.values.push(value);
            self.aux.push(rev_prev);
            self.camera_rays.push((ls.p, -w));
        }
        fit(&mut self.camera_pdfs, self.kept.len());
        importance.pdf_ray(&self.camera_rays, &mut self.camera_pdfs);
        self.shadows.clear();
        for q in 0..self.kept.len() {
            let r = self.kept[q] as usize;
            let j = self.req[r] as usize;
            let (ls, b) = (self.lens[r], self.light.at(j, k));
            let pdf = self.camera_pdfs[q];
            let rev_end = if importance.directional() {
                pdf.pdf_pos * b.it.ng.dot(ls.wi).abs()
            } else {
                b.area_density(ls.p, pdf.pdf_dir)
            };
            let light_sum = side_sum(self.light.mis(j, k), Side::Light, k, rev_end, self.aux[q]);
            let w = self.strategy(k + 1, 1, weight(0.0, light_sum, 1.0));
            self.values[q] *= w;
            let lens = Vertex::point(Kind::Camera, ls.p, Vec3::ZERO, Rgb::ONE);
            self.shadows.push(b, &lens);
        }
        self.rays += self.shadows.trace(scene);
        for (q, &r) in self.kept.iter().enumerate() {
            if !self.shadows.blocked[q] {
                let raster = self.lens[r as usize].raster;
                splats.splat(raster, self.values[q]);
                if let Some(films) = strategies {
                    films.splat(strategy_index(k + 1, 1), raster, self.values[q]);
                }
            }
        }
    }
}
