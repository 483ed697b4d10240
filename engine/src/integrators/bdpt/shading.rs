//! Shader calls of a batch of vertices: requests are queued with their
//! vertex's material, shading inputs (local frame) and argument, then run
//! with one `Shader` call per material on its contiguous slice (requests
//! sorted by material, as `path` shades), and the answers are read back
//! in request order. Every walk step and every connection stage of `bdpt`
//! fills one queue and runs it once.
//!
//! Directions are world space at the queue's surface: `eval` takes `wo`
//! and `wi` pointing away from the vertex, `sample` answers `wi` in world
//! space.

use super::vertex::Vertex;
use crate::extract::RenderScene;
use crate::integrators::sort::sort_by_key;
use glam::{Vec2, Vec3};
use radiant_core::{BsdfEval, BsdfSample, Effects, Rgb, ShadeContext, SurfaceBatch};

/// What a queue's requests ask.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(super) enum Op {
    /// f(wo, wi) · |cos θi| and the density of `wi` given `wo`.
    Eval,
    /// A direction given `wo`, from three uniform numbers.
    Sample,
    /// The material's albedo seen from `wo`.
    Albedo,
}

/// A queue of shading requests of one [`Op`] (see the module
/// documentation), reused from batch to batch.
#[derive(Default)]
pub(super) struct Queue {
    // Requests, in the order they were pushed.
    material: Vec<u32>,
    /// The vertices' frames (sample requests only: their answers turn
    /// to world space).
    frame: Vec<radiant_core::Frame>,
    wo: Vec<Vec3>,
    uv: Vec<Vec2>,
    dp_du: Vec<Vec3>,
    dp_dv: Vec<Vec3>,
    /// `wi` (local) for [`Op::Eval`], the uniform numbers for
    /// [`Op::Sample`].
    arg: Vec<Vec3>,
    // Requests by material.
    order: Vec<u32>,
    scratch: Vec<u32>,
    cursor: Vec<u32>,
    offsets: Vec<u32>,
    s_wo: Vec<Vec3>,
    s_uv: Vec<Vec2>,
    s_du: Vec<Vec3>,
    s_dv: Vec<Vec3>,
    s_arg: Vec<Vec3>,
    s_eval: Vec<BsdfEval>,
    s_sample: Vec<BsdfSample>,
    s_albedo: Vec<Rgb>,
    /// Answers of [`Op::Eval`], by request.
    pub evals: Vec<BsdfEval>,
    /// Answers of [`Op::Sample`] (`wi` in world space), by request.
    pub samples: Vec<BsdfSample>,
    /// Answers of [`Op::Albedo`], by request.
    pub albedos: Vec<Rgb>,
}

impl Queue {
    /// Drops every request.
    pub(super) fn clear(&mut self) {
        self.material.clear();
        self.frame.clear();
        self.wo.clear();
        self.uv.clear();
        self.dp_du.clear();
        self.dp_dv.clear();
        self.arg.clear();
    }

    /// Number of requests queued.
    pub(super) fn len(&self) -> usize {
        self.material.len()
    }

    /// Queues a request at surface vertex `v` seen from world direction
    /// `wo`, with `arg` in the local frame (see [`Queue::arg`]); returns its
    /// index.
    #[inline]
    fn push(&mut self, scene: &RenderScene, v: &Vertex, wo: Vec3, arg: Vec3) -> usize {
        let frame = &v.it.frame;
        self.material.push(v.material);
        self.wo.push(frame.to_local(wo));
        self.uv.push(v.it.uv);
        if scene.effects.contains(Effects::TANGENT_FRAMES) {
            self.dp_du.push(frame.to_local(v.derivs.dp_du));
            self.dp_dv.push(frame.to_local(v.derivs.dp_dv));
        }
        self.arg.push(arg);
        self.material.len() - 1
    }

    /// Queues the evaluation of `v` for world directions `wo`, `wi`.
    #[inline]
    pub(super) fn push_eval(
        &mut self,
        scene: &RenderScene,
        v: &Vertex,
        wo: Vec3,
        wi: Vec3,
    ) -> usize {
        let wi = v.it.frame.to_local(wi);
        self.push(scene, v, wo, wi)
    }

    /// Queues a direction sample at `v` given world `wo`, with the lobe
    /// number and the direction's pair in `u`.
    pub(super) fn push_sample(
        &mut self,
        scene: &RenderScene,
        v: &Vertex,
        wo: Vec3,
        u: Vec3,
    ) -> usize {
        self.frame.push(v.it.frame);
        self.push(scene, v, wo, u)
    }

    /// Queues the albedo of `v` seen from `v.wo`.
    pub(super) fn push_albedo(&mut self, scene: &RenderScene, v: &Vertex) -> usize {
        self.push(scene, v, v.wo, Vec3::ZERO)
    }

    /// Runs every request as `op`, one shader call per material, and
    /// leaves the answers by request in [`Queue::evals`],
    /// [`Queue::samples`] or [`Queue::albedos`].
    pub(super) fn run(&mut self, scene: &RenderScene, ctx: &mut ShadeContext<'_>, op: Op) {
        let n = self.len();
        // Requests already in material order (one material, most often)
        // are shaded where they are; the others are sorted and gathered.
        let in_order = self.material.is_sorted();
        if in_order {
            self.offsets.clear();
            self.offsets.resize(scene.shaders.len() + 1, 0);
            for &m in &self.material {
                self.offsets[m as usize + 1] += 1;
            }
            for m in 0..scene.shaders.len() {
                self.offsets[m + 1] += self.offsets[m];
            }
            std::mem::swap(&mut self.wo, &mut self.s_wo);
            std::mem::swap(&mut self.uv, &mut self.s_uv);
            std::mem::swap(&mut self.arg, &mut self.s_arg);
            std::mem::swap(&mut self.dp_du, &mut self.s_du);
            std::mem::swap(&mut self.dp_dv, &mut self.s_dv);
        } else {
            self.sort(scene);
        }
        match op {
            Op::Eval => self.s_eval.resize(n, BsdfEval::default()),
            Op::Sample => self.s_sample.resize(n, BsdfSample::default()),
            Op::Albedo => self.s_albedo.resize(n, Rgb::ZERO),
        }
        for (m, shader) in scene.shaders.iter().enumerate() {
            let (a, b) = (self.offsets[m] as usize, self.offsets[m + 1] as usize);
            if a == b {
                continue;
            }
            let mut surface = SurfaceBatch::new(&self.s_wo[a..b], &self.s_uv[a..b]);
            if shader.effects().contains(Effects::TANGENT_FRAMES) {
                surface.dp_du = &self.s_du[a..b];
                surface.dp_dv = &self.s_dv[a..b];
            }
            match op {
                Op::Eval => shader.eval(ctx, surface, &self.s_arg[a..b], &mut self.s_eval[a..b]),
                Op::Sample => {
                    shader.sample(ctx, surface, &self.s_arg[a..b], &mut self.s_sample[a..b]);
                }
                Op::Albedo => shader.albedo(ctx, surface, &mut self.s_albedo[a..b]),
            }
        }
        match (op, in_order) {
            (Op::Eval, true) => std::mem::swap(&mut self.s_eval, &mut self.evals),
            (Op::Sample, true) => std::mem::swap(&mut self.s_sample, &mut self.samples),
            (Op::Albedo, true) => std::mem::swap(&mut self.s_albedo, &mut self.albedos),
            (Op::Eval, false) => scatter(&self.order, &self.s_eval, &mut self.evals),
            (Op::Sample, false) => scatter(&self.order, &self.s_sample, &mut self.samples),
            (Op::Albedo, false) => scatter(&self.order, &self.s_albedo, &mut self.albedos),
        }
        if op == Op::Sample {
            for (s, frame) in self.samples.iter_mut().zip(&self.frame) {
                s.wi = frame.to_world(s.wi);
            }
        }
    }

    /// Sorts the requests by material into `order` and gathers their
    /// inputs in that order.
    fn sort(&mut self, scene: &RenderScene) {
        self.order.clear();
        self.order.extend(0..self.len() as u32);
        let material = &self.material;
        sort_by_key(
            &mut self.order,
            &mut self.scratch,
            &mut self.cursor,
            &mut self.offsets,
            scene.shaders.len(),
            |r| material[r as usize],
        );
        gather(&self.order, &self.wo, &mut self.s_wo);
        gather(&self.order, &self.uv, &mut self.s_uv);
        gather(&self.order, &self.arg, &mut self.s_arg);
        if scene.effects.contains(Effects::TANGENT_FRAMES) {
            gather(&self.order, &self.dp_du, &mut self.s_du);
            gather(&self.order, &self.dp_dv, &mut self.s_dv);
        }
    }
}

/// `out[k] = from[order[k]]`.
fn gather<T: Copy + Default>(order: &[u32], from: &[T], out: &mut Vec<T>) {
    out.clear();
    out.extend(order.iter().map(|&r| from[r as usize]));
}

/// `out[order[k]] = from[k]`.
fn scatter<T: Copy + Default>(order: &[u32], from: &[T], out: &mut Vec<T>) {
    out.clear();
    out.resize(order.len(), T::default());
    for (&r, v) in order.iter().zip(from) {
        out[r as usize] = *v;
    }
}
