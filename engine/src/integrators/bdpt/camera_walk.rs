//! The camera subpaths of a chunk, walked one vertex index at a time for
//! all samples together (radiance transport, as `path`), adding at each
//! index the strategies whose camera side ends there: s = 0 where the
//! path hits an emitter or leaves the scene towards an environment light
//! (one `Light` and one `Emission` call per light), then next-event
//! estimation and the connections to the light subpath
//! (`connect.rs`). A sample's strategies are summed in the order the
//! one-path-at-a-time walk added them, so the image does not depend on
//! the batching.

use super::mis::{self, Mis, Side, ratio2, side_sum, weight};
use super::vertex::{Kind, Vertex};
use super::walk::{Which, fit};
use super::{State, dims};
use crate::accel::Hit;
use crate::accel::offset::offset_origin;
use crate::extract::{NO_EMITTER, RenderScene};
use glam::Vec3;
use radiant_core::{EmittedRay, EmitterEval, EmitterHit, Rgb, ShadeContext};

impl State {
    /// Walks the chunk's camera subpaths from its camera rays
    /// (`origin`, `dir`, `weight` by slot), leaving each slot's camera
    /// strategies' sum in `self.radiance`.
    pub(super) fn trace_cameras(
        &mut self,
        scene: &RenderScene,
        shade: &mut ShadeContext<'_>,
        (origin, dir, weight): (&[Vec3], &[Vec3], &[f32]),
    ) {
        let n = self.ids.len();
        let max = self.max;
        self.camera.reset(n, max + 1);
        self.radiance.clear();
        self.radiance.resize(n, Rgb::ZERO);
        self.start_walk(n);
        let Some(importance) = scene.camera.importance() else {
            return;
        };
        if max == 0 {
            return;
        }
        self.camera_rays.clear();
        for j in 0..n {
            if weight[j] > 0.0 {
                self.live.push(j as u32);
                self.camera_rays.push((origin[j], dir[j]));
            }
        }
        fit(&mut self.camera_pdfs, self.live.len());
        importance.pdf_ray(&self.camera_rays, &mut self.camera_pdfs);
        for (&j, pdf) in self.live.iter().zip(&self.camera_pdfs) {
            let j = j as usize;
            let beta = Rgb::splat(weight[j]);
            let lens = Vertex::point(Kind::Camera, origin[j], Vec3::ZERO, beta);
            self.camera.push(j, lens, Self::reached(1.0));
            self.beta[j] = beta;
            self.origin[j] = origin[j];
            self.dir[j] = dir[j];
            self.pdf_dir[j] = pdf.pdf_dir;
            self.pdf_pos[j] = pdf.pdf_pos;
            self.scale[j] = 1.0;
        }
        let directional = importance.directional();
        for i in 1..=max {
            if self.live.is_empty() {
                break;
            }
            self.trace_closest(scene);
            self.camera_vertices(scene, i, directional);
            self.escaped(scene, i);
            self.hit_emitters(scene, i);
            if i >= max {
                break;
            }
            self.req.clear();
            for &j in &self.live {
                if self.camera.at(j as usize, i).connectable {
                    self.req.push(j);
                }
            }
            if !self.req.is_empty() {
                self.next_event(scene, shade, i);
                self.connect_light(scene, shade, i);
            }
            let d = dims(i as u32 - 1);
            self.scatter(scene, shade, Which::Camera, i, d);
            self.continue_cameras(scene, i);
        }
    }

    /// Pushes vertex `i` of every live slot whose ray hit a surface. Slots
    /// whose ray left the scene go to `self.req`, those that hit an
    /// emitter to `self.kept` (their light in `self.light_of`, primitive
    /// in `self.call`); the others stay live.
    fn camera_vertices(&mut self, scene: &RenderScene, i: usize, directional: bool) {
        self.next.clear();
        self.req.clear();
        self.kept.clear();
        self.light_of.clear();
        self.call.clear();
        for idx in 0..self.live.len() {
            let j = self.live[idx] as usize;
            let hit = self.hit[j];
            if hit.prim == Hit::MISS.prim {
                self.req.push(j as u32);
                continue;
            }
            let v = self.surface_vertex(scene, j, &hit);
            let fwd = if i == 1 && directional {
                // One direction for every ray: the window's density,
                // projected onto the surface.
                self.pdf_pos[j] * v.it.ng.dot(self.dir[j]).abs()
            } else {
                v.area_density(self.camera.at(j, i - 1).it.p, self.pdf_dir[j])
            };
            self.camera.push(j, v, Self::reached(fwd));
            let emitter = scene.surfaces.emitter[hit.prim as usize];
            if emitter != NO_EMITTER {
                self.kept.push(j as u32);
                self.light_of.push(emitter);
                self.call
                    .push(scene.surfaces.emitter_prim[hit.prim as usize]);
            }
            self.next.push(j as u32);
        }
        std::mem::swap(&mut self.live, &mut self.next);
    }

    /// s = 0 towards the environment for the slots in `self.req`, whose
    /// ray from vertex i − 1 left the scene (one `eval_escaped` and one
    /// `emission_pdf` call per environment light).
    fn escaped(&mut self, scene: &RenderScene, i: usize) {
        let n = self.req.len();
        if n == 0 || scene.lights.environment().is_empty() {
            return;
        }
        self.dirs.clear();
        self.emitted_rays.clear();
        for &j in &self.req {
            let j = j as usize;
            let d = self.dir[j];
            self.dirs.push(d);
            self.emitted_rays.push(EmittedRay {
                p: self.camera.at(j, i - 1).it.p,
                n: Vec3::ZERO,
                dir: -d,
                primitive: 0,
            });
        }
        self.values.clear();
        self.values.resize(n, Rgb::ZERO);
        fit(&mut self.emitter_evals, n);
        fit(&mut self.emission_pdfs, n);
        for &l in scene.lights.environment() {
            let light = &scene.lights.lights()[l];
            light.eval_escaped(&self.dirs, &mut self.emitter_evals);
            let emission = light.emission();
            if let Some(emission) = emission {
                emission.emission_pdf(&self.emitted_rays, &mut self.emission_pdfs);
            }
            let pmf = scene.lights.pmf(l);
            for r in 0..n {
                let j = self.req[r] as usize;
                let e = self.emitter_evals[r];
                if e.radiance == Rgb::ZERO {
                    continue;
                }
                let value = self.beta[j] * e.radiance;
                if emission.is_none() {
                    self.values[r] += value;
                    self.log.add(j, 0, i + 1, value);
                    continue;
                }
                let em = self.emission_pdfs[r];
                let l_fwd = pmf * em.pdf_dir;
                let d = pmf * e.pdf;
                let prev = self.camera.at(j, i - 1);
                let rev_prev = em.pdf_pos * prev.it.ng.dot(self.dirs[r]).abs();
                // The escaped direction as vertex i, past the row's end.
                let m = self.camera.mis_mut(j, i);
                m[i] = Mis {
                    fwd: self.pdf_dir[j],
                    delta: false,
                    eps: if i >= 2 { ratio2(d, l_fwd) } else { 0.0 },
                    acc: 0.0,
                };
                let sum = side_sum(m, Side::Camera, i, l_fwd, rev_prev);
                let w = self.strategy(0, i + 1, weight(sum, 0.0, 1.0));
                self.values[r] += value * w;
                self.log.add(j, 0, i + 1, value * w);
            }
        }
        for (&j, v) in self.req.iter().zip(&self.values) {
            self.radiance[j as usize] += *v;
        }
    }

    /// s = 0 on surface emitters: the slots in `self.kept`, whose vertex
    /// `i` lies on light `self.light_of` (one `eval_hits` and one
    /// `emission_pdf` call per light).
    fn hit_emitters(&mut self, scene: &RenderScene, i: usize) {
        let n = self.kept.len();
        if n == 0 {
            return;
        }
        let light_of = &self.light_of;
        self.by_light
            .sort(n, scene.lights.len(), |r| light_of[r as usize]);
        fit(&mut self.emitter_hits, n);
        fit(&mut self.emitter_evals, n);
        fit(&mut self.emitted_rays, n);
        fit(&mut self.emission_pdfs, n);
        for (l, range) in self.by_light.ranges() {
            for p in range.clone() {
                let r = self.by_light.order[p] as usize;
                let j = self.kept[r] as usize;
                let (v, prev) = (self.camera.at(j, i), self.camera.at(j, i - 1));
                let primitive = self.call[r];
                self.emitter_hits[p] = EmitterHit {
                    origin: prev.it.p,
                    p: v.it.p,
                    n: v.it.ng,
                    primitive,
                };
                self.emitted_rays[p] = EmittedRay {
                    p: v.it.p,
                    n: v.it.ng,
                    dir: v.wo,
                    primitive,
                };
            }
            let light = &scene.lights.lights()[l];
            light.eval_hits(
                &self.emitter_hits[range.clone()],
                &mut self.emitter_evals[range.clone()],
            );
            if let Some(emission) = light.emission() {
                emission.emission_pdf(
                    &self.emitted_rays[range.clone()],
                    &mut self.emission_pdfs[range.clone()],
                );
            }
            let pmf = scene.lights.pmf(l);
            for p in range {
                let j = self.kept[self.by_light.order[p] as usize] as usize;
                let e: EmitterEval = self.emitter_evals[p];
                if e.radiance == Rgb::ZERO {
                    continue;
                }
                let (v, prev) = (*self.camera.at(j, i), self.camera.at(j, i - 1));
                let value = v.beta * e.radiance;
                if light.emission().is_none() {
                    self.radiance[j] += value;
                    self.log.add(j, 0, i + 1, value);
                    continue;
                }
                let em = self.emission_pdfs[p];
                let l_fwd = pmf * em.pdf_pos;
                let d = pmf * v.area_density(prev.it.p, e.pdf);
                let rev_prev = prev.area_density(v.it.p, em.pdf_dir);
                let m = self.camera.mis_mut(j, i);
                let saved = m[i].eps;
                m[i].eps = if i >= 2 { ratio2(d, l_fwd) } else { 1.0 };
                let sum = side_sum(m, Side::Camera, i, l_fwd, rev_prev);
                m[i].eps = saved;
                let w = self.strategy(0, i + 1, weight(sum, 0.0, 1.0));
                self.radiance[j] += value * w;
                self.log.add(j, 0, i + 1, value * w);
            }
        }
    }

    /// Moves every camera path past vertex `i` along its sampled direction
    /// (from [`State::scatter`]): acc[i − 1] completed, radiance
    /// throughput and η² tracked, roulette on their product.
    fn continue_cameras(&mut self, scene: &RenderScene, i: usize) {
        self.next.clear();
        for r in 0..self.req.len() {
            let j = self.req[r] as usize;
            let s = self.bsdf[r];
            if s.pdf <= 0.0 {
                continue;
            }
            let (v, prev) = (*self.camera.at(j, i), self.camera.at(j, i - 1));
            let rev_area = prev.area_density(v.it.p, self.aux[r]);
            let m = self.camera.mis_mut(j, i);
            m[i].delta = s.delta;
            mis::complete(m, i - 1, Side::Camera, rev_area);
            let beta = self.beta[j] * s.weight;
            let eta_scale = self.scale[j] * s.eta * s.eta;
            let survival = beta.max_element() * eta_scale;
            if !beta.is_finite() || survival <= 0.0 {
                continue;
            }
            self.beta[j] = beta;
            self.scale[j] = eta_scale;
            if i as u32 >= scene.settings.rr_depth && survival < 1.0 {
                if self.u1[r] >= survival {
                    continue;
                }
                self.beta[j] /= survival;
            }
            self.origin[j] = offset_origin(v.it.p, v.it.err, v.it.ng, s.wi);
            self.dir[j] = s.wi;
            self.pdf_dir[j] = s.pdf;
            self.next.push(j as u32);
        }
        std::mem::swap(&mut self.live, &mut self.next);
    }
}
