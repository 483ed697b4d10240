//! What both subpaths' walks share, one step of all live samples of a
//! chunk at a time: the closest hits of their rays (one batch query),
//! the surface vertices those hits make, and the scattering of each live
//! path's newest vertex (one shader call per material for the samples,
//! one for the reverse densities).

use super::State;
use super::mis::Mis;
use super::shading::Op;
use super::vertex::{Kind, Vertex};
use crate::accel::Hit;
use crate::extract::RenderScene;
use crate::integrators::surface::{Derivatives, interaction, interaction_with_derivatives};
use glam::Vec3;
use radiant_core::{Effects, Rgb, ShadeContext};

/// Which subpath a step walks.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(super) enum Which {
    /// From a light.
    Light,
    /// From the camera.
    Camera,
}

/// Gives `v` length `n` (old values stay until overwritten).
pub(super) fn fit<T: Clone + Default>(v: &mut Vec<T>, n: usize) {
    v.resize(n, T::default());
}

impl State {
    /// Sizes the per-slot walk state for `n` slots.
    pub(super) fn start_walk(&mut self, n: usize) {
        fit(&mut self.origin, n);
        fit(&mut self.dir, n);
        fit(&mut self.beta, n);
        fit(&mut self.pdf_dir, n);
        fit(&mut self.scale, n);
        fit(&mut self.pdf_pos, n);
        fit(&mut self.hit, n);
        self.live.clear();
    }

    /// The ids of the slots in `self.req`, into `self.req_ids`.
    pub(super) fn gather_ids(&mut self) {
        self.req_ids.clear();
        let ids = &self.ids;
        self.req_ids
            .extend(self.req.iter().map(|&j| ids[j as usize]));
    }

    /// Traces the live slots' rays to their closest hits.
    pub(super) fn trace_closest(&mut self, scene: &RenderScene) {
        scene
            .accel
            .intersect_slots(&self.live, &self.origin, &self.dir, None, &mut self.hit);
        self.rays += self.live.len() as u64;
    }

    /// The surface vertex that slot `j`'s ray hit (`hit`, not a miss).
    pub(super) fn surface_vertex(&self, scene: &RenderScene, j: usize, hit: &Hit) -> Vertex {
        let (origin, dir) = (self.origin[j], self.dir[j]);
        let (it, derivs) = if scene.effects.contains(Effects::TANGENT_FRAMES) {
            interaction_with_derivatives(scene, hit, origin, dir, 0.0)
        } else {
            (
                interaction(scene, hit, origin, dir, 0.0),
                Derivatives::default(),
            )
        };
        let material = scene.material(hit);
        Vertex {
            kind: Kind::Surface,
            it,
            derivs,
            material,
            wo: -dir,
            beta: self.beta[j],
            connectable: scene.shaders[material as usize]
                .effects()
                .contains(Effects::SMOOTH_LOBES),
        }
    }

    /// The MIS state of a vertex reached with area density `fwd`.
    pub(super) fn reached(fwd: f32) -> Mis {
        Mis {
            fwd,
            delta: false,
            eps: 1.0,
            acc: 0.0,
        }
    }

    /// Samples the direction leaving vertex `k` of every live slot of
    /// `which`, with the sampler dimensions from `d` (lobe, direction;
    /// `d + 3` the roulette's, into `self.u1`). Per live slot (in
    /// `self.req`, the live slots' order): `self.bsdf` the sample (`wi`
    /// world), `self.aux` the solid-angle density of the reverse direction
    /// (`v.wo` given `wi`; for a delta lobe its own choice probability),
    /// and a zero `pdf` where sampling failed or the direction leaves on
    /// the wrong side of the geometric surface.
    pub(super) fn scatter(
        &mut self,
        scene: &RenderScene,
        shade: &mut ShadeContext<'_>,
        which: Which,
        k: usize,
        d: u32,
    ) {
        self.req.clear();
        self.req.extend_from_slice(&self.live);
        self.gather_ids();
        let n = self.req.len();
        fit(&mut self.u1, n);
        fit(&mut self.u2, n);
        scene.sampler.fill_1d(&self.req_ids, d, &mut self.u1);
        scene.sampler.fill_2d(&self.req_ids, d + 1, &mut self.u2);
        self.queue.clear();
        let paths = match which {
            Which::Light => &self.light,
            Which::Camera => &self.camera,
        };
        for ((&j, &u1), u2) in self.req.iter().zip(&self.u1).zip(&self.u2) {
            let v = paths.at(j as usize, k);
            let u = Vec3::new(u1, u2.x, u2.y);
            self.queue.push_sample(scene, v, v.wo, u);
        }
        self.queue.run(scene, shade, Op::Sample);
        self.bsdf.clear();
        self.bsdf.extend_from_slice(&self.queue.samples);
        self.queue.clear();
        fit(&mut self.call, n);
        for ((&j, s), call) in self.req.iter().zip(&mut self.bsdf).zip(&mut self.call) {
            let v = paths.at(j as usize, k);
            if s.pdf <= 0.0 || s.weight == Rgb::ZERO || !v.consistent(s.wi) {
                s.pdf = 0.0;
            } else if !s.delta {
                *call = self.queue.push_eval(scene, v, s.wi, v.wo) as u32;
            }
        }
        self.queue.run(scene, shade, Op::Eval);
        fit(&mut self.aux, n);
        for ((s, &call), rev) in self.bsdf.iter().zip(&self.call).zip(&mut self.aux) {
            *rev = if s.delta {
                s.pdf
            } else if s.pdf > 0.0 {
                self.queue.evals[call as usize].pdf
            } else {
                0.0
            };
        }
        scene.sampler.fill_1d(&self.req_ids, d + 3, &mut self.u1);
    }
}
