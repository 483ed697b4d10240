//! The strategies that join camera vertex `i` of the slots in `req` to a
//! light subpath, in two batched stages: next-event estimation (s = 1:
//! the light point drawn by the light's own `sample`, one call per light)
//! and the connections to light vertices (s ≥ 2: every vertex of the
//! sample's light subpath, or N drawn from the chunk's light vertex cache,
//! [`super::Connections`]). Each stage queues
//! its shader evaluations (the BSDF values and the reverse densities the
//! MIS weights need) and runs them with one call per material, then
//! traces its shadow rays as one batch.

use super::mis::{Mis, Side, ratio2, side_sum, weight};
use super::shading::Op;
use super::vertex::{Kind, Vertex};
use super::walk::fit;
use super::{Connections, State, cache_dim, dims};
use crate::extract::RenderScene;
use radiant_core::{EmissionKind, EmittedRay, LightSample, Rgb, ShadeContext};

impl State {
    /// s = 1, t = i + 1: next-event estimation at vertex `i` of the slots
    /// in `self.req`.
    pub(super) fn next_event(
        &mut self,
        scene: &RenderScene,
        shade: &mut ShadeContext<'_>,
        i: usize,
    ) {
        if scene.lights.is_empty() {
            return;
        }
        let n = self.req.len();
        self.gather_ids();
        let d = dims(i as u32 - 1) + 4;
        fit(&mut self.u1, n);
        fit(&mut self.u2, n);
        scene.sampler.fill_1d(&self.req_ids, d, &mut self.u1);
        scene.sampler.fill_2d(&self.req_ids, d + 1, &mut self.u2);
        fit(&mut self.light_of, n);
        fit(&mut self.pmf, n);
        for r in 0..n {
            let (l, pmf, _) = scene.lights.select(self.u1[r]);
            self.light_of[r] = l as u32;
            self.pmf[r] = pmf;
        }
        let light_of = &self.light_of;
        self.by_light
            .sort(n, scene.lights.len(), |r| light_of[r as usize]);
        // Light points, in light order.
        self.refs.clear();
        self.u3.clear();
        for &r in &self.by_light.order {
            let j = self.req[r as usize] as usize;
            self.refs.push(self.camera.at(j, i).it.p);
            self.u3.push(self.u2[r as usize]);
        }
        self.light_samples.clear();
        self.light_samples.resize(n, LightSample::default());
        for (l, range) in self.by_light.ranges() {
            scene.lights.lights()[l].sample(
                &self.refs[range.clone()],
                &self.u3[range.clone()],
                &mut self.light_samples[range],
            );
        }
        // BSDF values towards the points and the reverse densities.
        self.queue.clear();
        self.kept.clear();
        self.dirs.clear();
        for p in 0..n {
            let r = self.by_light.order[p] as usize;
            let j = self.req[r] as usize;
            let ls = self.light_samples[p];
            let light = &scene.lights.lights()[self.light_of[r] as usize];
            if light.emission().is_none() || ls.pdf <= 0.0 || self.pmf[r] <= 0.0 {
                continue;
            }
            let a = self.camera.at(j, i);
            let w = (ls.p - a.it.p).normalize_or_zero();
            if !a.consistent(w) {
                continue;
            }
            self.queue.push_eval(scene, a, a.wo, w);
            self.queue.push_eval(scene, a, w, a.wo);
            self.kept.push(p as u32);
            self.dirs.push(w);
        }
        self.queue.run(scene, shade, Op::Eval);
        // The light points' emission densities, one call per light.
        let m = self.kept.len();
        self.emitted_rays.clear();
        for (&p, &w) in self.kept.iter().zip(&self.dirs) {
            let ls = self.light_samples[p as usize];
            self.emitted_rays.push(EmittedRay {
                p: ls.p,
                n: ls.n,
                dir: -w,
                primitive: 0,
            });
        }
        fit(&mut self.emission_pdfs, m);
        let mut q0 = 0;
        while q0 < m {
            let l = self.light_of[self.by_light.order[self.kept[q0] as usize] as usize];
            let mut q1 = q0 + 1;
            while q1 < m && self.light_of[self.by_light.order[self.kept[q1] as usize] as usize] == l
            {
                q1 += 1;
            }
            if let Some(emission) = scene.lights.lights()[l as usize].emission() {
                emission.emission_pdf(&self.emitted_rays[q0..q1], &mut self.emission_pdfs[q0..q1]);
            }
            q0 = q1;
        }
        // Values, weights, shadow rays.
        self.shadows.clear();
        self.values.clear();
        self.shadow_of.clear();
        for q in 0..m {
            let p = self.kept[q] as usize;
            let r = self.by_light.order[p] as usize;
            let j = self.req[r] as usize;
            let (ls, w, pmf) = (self.light_samples[p], self.dirs[q], self.pmf[r]);
            let (f, rev) = (self.queue.evals[2 * q], self.queue.evals[2 * q + 1]);
            let a = self.camera.at(j, i);
            let value = a.beta * f.value * ls.radiance / (pmf * ls.pdf);
            let light = &scene.lights.lights()[self.light_of[r] as usize];
            let (true, Some(emission)) =
                (value != Rgb::ZERO && value.is_finite(), light.emission())
            else {
                self.values.push(Rgb::ZERO);
                self.shadow_of.push(u32::MAX);
                continue;
            };
            let kind = emission.kind();
            let z = Vertex::point(Kind::Light(kind), ls.p, ls.n, Rgb::ZERO);
            let em = self.emission_pdfs[q];
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
            let prev = self.camera.at(j, i - 1);
            let rev_prev = prev.area_density(a.it.p, rev.pdf);
            let camera_sum = side_sum(self.camera.mis(j, i), Side::Camera, i, to_camera, rev_prev);
            let w = weight(camera_sum, light_sum, ratio2(direct, l_fwd));
            self.values.push(value * self.strategy(1, i + 1, w));
            self.shadow_of.push(self.shadows.push(a, &z) as u32);
        }
        self.rays += self.shadows.trace(scene);
        for (q, (&s, v)) in self.shadow_of.iter().zip(&self.values).enumerate() {
            if s != u32::MAX && !self.shadows.blocked[s as usize] {
                let r = self.by_light.order[self.kept[q] as usize] as usize;
                self.radiance[self.req[r] as usize] += *v;
                self.log.add(self.req[r] as usize, 1, i + 1, *v);
            }
        }
    }

    /// The chunk's light vertex cache: every connectable light vertex
    /// past the light, by slot then index (for `connections: N`).
    pub(super) fn fill_cache(&mut self) {
        self.cache.clear();
        if self.connections == Connections::All {
            return;
        }
        for j in 0..self.ids.len() {
            for k in 1..self.light.len(j) {
                if self.light.at(j, k).connectable {
                    self.cache.push((j as u32, k as u32));
                }
            }
        }
    }

    /// s ≥ 2, t = i + 1: vertex `i` of the slots in `self.req` connected
    /// to light vertices that `max_depth` allows: every one of the slot's
    /// own light subpath, or `N` drawn from the cache (stratified: draw
    /// `d` of `N` from the `d`-th `N`-th of the cache, one sampler
    /// dimension for all), each weighted by the cache's size over `N`
    /// times the chunk's light subpaths.
    pub(super) fn connect_light(
        &mut self,
        scene: &RenderScene,
        shade: &mut ShadeContext<'_>,
        i: usize,
    ) {
        // Candidates (slot in `kept`, light slot in `from`, light vertex
        // in `call`), four shader calls each: f at both ends, then both
        // reverse densities.
        self.queue.clear();
        self.kept.clear();
        self.from.clear();
        self.call.clear();
        self.dirs.clear();
        self.aux.clear();
        let scale = match self.connections {
            Connections::All => {
                for r in 0..self.req.len() {
                    let j = self.req[r] as usize;
                    for k in 1..self.light.len(j) {
                        // Segments: (k + 1) + (i + 1) − 1.
                        if k + i + 1 > self.max {
                            break;
                        }
                        self.candidate(scene, i, j, j, k);
                    }
                }
                1.0
            }
            Connections::Drawn(draws) => {
                let m = self.cache.len();
                if m == 0 {
                    return;
                }
                self.gather_ids();
                fit(&mut self.u1, self.req.len());
                scene
                    .sampler
                    .fill_1d(&self.req_ids, cache_dim(self.max, i), &mut self.u1);
                for r in 0..self.req.len() {
                    let j = self.req[r] as usize;
                    for d in 0..draws {
                        let u = (self.u1[r] + d as f32) / draws as f32;
                        let (from, k) = self.cache[((u * m as f32) as usize).min(m - 1)];
                        if k as usize + i < self.max {
                            self.candidate(scene, i, j, from as usize, k as usize);
                        }
                    }
                }
                m as f32 / (draws as f32 * self.ids.len() as f32)
            }
        };
        self.queue.run(scene, shade, Op::Eval);
        self.shadows.clear();
        self.values.clear();
        self.shadow_of.clear();
        for c in 0..self.kept.len() {
            let (j, k) = (self.kept[c] as usize, self.call[c] as usize);
            let from = self.from[c] as usize;
            let (w, dist2) = (self.dirs[c], self.aux[c]);
            let e = &self.queue.evals[4 * c..4 * c + 4];
            let (fa, fb) = (e[0], e[1]);
            let (a, b) = (self.camera.at(j, i), self.light.at(from, k));
            let value = a.beta * fa.value * fb.value * b.beta;
            let correction = b.it.ng.dot(w).abs() / b.it.ng.dot(b.wo).abs();
            let value = value * (correction * scale / dist2);
            if fa.value == Rgb::ZERO
                || fb.value == Rgb::ZERO
                || value == Rgb::ZERO
                || !value.is_finite()
            {
                self.values.push(Rgb::ZERO);
                self.shadow_of.push(u32::MAX);
                continue;
            }
            let (prev_a, prev_b) = (self.camera.at(j, i - 1), self.light.at(from, k - 1));
            let rev_a_prev = prev_a.area_density(a.it.p, e[2].pdf);
            let rev_a = a.area_density(b.it.p, e[3].pdf);
            let rev_b = b.area_density(a.it.p, fa.pdf);
            let rev_b_prev = match prev_b.kind {
                Kind::Light(EmissionKind::Infinite) => fb.pdf,
                _ => prev_b.area_density(b.it.p, fb.pdf),
            };
            let camera_sum = side_sum(self.camera.mis(j, i), Side::Camera, i, rev_a, rev_a_prev);
            let light_sum = side_sum(self.light.mis(from, k), Side::Light, k, rev_b, rev_b_prev);
            let w = weight(camera_sum, light_sum, 1.0);
            self.values.push(value * self.strategy(k + 1, i + 1, w));
            self.shadow_of.push(self.shadows.push(a, b) as u32);
        }
        self.rays += self.shadows.trace(scene);
        // Each slot's connections summed by light vertex, then added (as
        // the one-path walk did).
        let mut c = 0;
        for &j in &self.req {
            let mut total = Rgb::ZERO;
            while c < self.kept.len() && self.kept[c] == j {
                let s = self.shadow_of[c];
                if s != u32::MAX && !self.shadows.blocked[s as usize] {
                    total += self.values[c];
                    let k = self.call[c] as usize;
                    self.log.add(j as usize, k + 1, i + 1, self.values[c]);
                }
                c += 1;
            }
            self.radiance[j as usize] += total;
        }
    }
}

impl State {
    /// Queues the connection of camera vertex `i` of slot `j` to light
    /// vertex `k` of slot `from`'s subpath, unless one of them cannot
    /// scatter towards the other.
    fn candidate(&mut self, scene: &RenderScene, i: usize, j: usize, from: usize, k: usize) {
        let (a, b) = (self.camera.at(j, i), self.light.at(from, k));
        if !b.connectable {
            return;
        }
        let d = b.it.p - a.it.p;
        let dist2 = d.length_squared();
        if dist2 <= 0.0 {
            return;
        }
        let w = d / dist2.sqrt();
        if !a.consistent(w) || !b.consistent(-w) {
            return;
        }
        self.queue.push_eval(scene, a, a.wo, w);
        self.queue.push_eval(scene, b, -w, b.wo);
        self.queue.push_eval(scene, a, w, a.wo);
        self.queue.push_eval(scene, b, b.wo, -w);
        self.kept.push(j as u32);
        self.from.push(from as u32);
        self.call.push(k as u32);
        self.dirs.push(w);
        self.aux.push(dist2);
    }
}
