//! Subpath vertices and what every strategy asks of them: BSDF values and
//! densities in either direction, in world space, and the conversion of a
//! solid-angle density into one per unit area at the vertex reached.

use super::mis::Mis;
use crate::extract::RenderScene;
use crate::integrators::surface::{Derivatives, Interaction};
use glam::{Vec2, Vec3};
use radiant_core::{
    BsdfEval, BsdfSample, Effects, EmissionKind, Frame, Rgb, ShadeContext, SurfaceBatch,
};

/// What a vertex lies on.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(super) enum Kind {
    /// The lens (a camera subpath's first vertex).
    Camera,
    /// A light (a light subpath's first vertex), emitting as `EmissionKind`.
    Light(EmissionKind),
    /// A surface, shaded by its material.
    Surface,
}

/// One vertex of a subpath (the structure of arrays would gain nothing:
/// a subpath is walked and connected one vertex at a time).
#[derive(Debug, Clone, Copy)]
pub(super) struct Vertex {
    /// What it lies on.
    pub kind: Kind,
    /// Position, rounding error, geometric normal (zero for points and
    /// lights at infinity), shading frame and texture coordinates.
    pub it: Interaction,
    /// Surface derivatives, world space (only under tangent frames).
    pub derivs: Derivatives,
    /// Material index (surfaces).
    pub material: u32,
    /// Unit direction towards the previous vertex of its subpath.
    pub wo: Vec3,
    /// Throughput up to the vertex, its own scattering excluded.
    pub beta: Rgb,
}

impl Vertex {
    /// A vertex at `p` with normal `n` and no surface: a lens or a light.
    pub(super) fn point(kind: Kind, p: Vec3, n: Vec3, beta: Rgb) -> Self {
        Self {
            kind,
            it: Interaction {
                p,
                err: Vec3::ZERO,
                ng: n,
                frame: Frame::from_normal(if n == Vec3::ZERO { Vec3::Z } else { n }),
                uv: Vec2::ZERO,
            },
            derivs: Derivatives::default(),
            material: 0,
            wo: Vec3::ZERO,
            beta,
        }
    }

    /// The density per unit area at this vertex of a direction sampled at
    /// `from` with solid-angle density `pdf` (for a point without a
    /// normal, per unit solid angle at `from` over distance²).
    #[inline]
    pub(super) fn area_density(&self, from: Vec3, pdf: f32) -> f32 {
        let d = self.it.p - from;
        let dist2 = d.length_squared();
        if dist2 <= 0.0 {
            return 0.0;
        }
        let cos = if self.it.ng == Vec3::ZERO {
            1.0
        } else {
            (self.it.ng.dot(d) / dist2.sqrt()).abs()
        };
        pdf * cos / dist2
    }

    /// Whether the world direction `w` leaves the surface on the same side
    /// for the geometric and the shading normal (the path tracer drops
    /// the others too).
    #[inline]
    pub(super) fn consistent(&self, w: Vec3) -> bool {
        w.dot(self.it.ng) * w.dot(self.it.frame.n) > 0.0
    }
}

/// Shading calls on single vertices, with the scene's textures.
pub(super) struct Shading<'a> {
    scene: &'a RenderScene,
    ctx: ShadeContext<'a>,
}

impl<'a> Shading<'a> {
    /// Shading for `scene`.
    pub(super) fn new(scene: &'a RenderScene) -> Self {
        Self {
            scene,
            ctx: ShadeContext::new(&scene.textures),
        }
    }

    /// The one-point surface batch of `v` seen from `wo` (world).
    fn call<R>(
        &mut self,
        v: &Vertex,
        wo: Vec3,
        f: impl FnOnce(&dyn radiant_core::Shader, &mut ShadeContext<'a>, SurfaceBatch<'_>) -> R,
    ) -> R {
        let shader = self.scene.shaders[v.material as usize].as_ref();
        let frame = &v.it.frame;
        let wo = [frame.to_local(wo)];
        let uv = [v.it.uv];
        let du = [frame.to_local(v.derivs.dp_du)];
        let dv = [frame.to_local(v.derivs.dp_dv)];
        let mut batch = SurfaceBatch::new(&wo, &uv);
        if shader.effects().contains(Effects::TANGENT_FRAMES) {
            batch.dp_du = &du;
            batch.dp_dv = &dv;
        }
        f(shader, &mut self.ctx, batch)
    }

    /// f(wo, wi) · |cos θi| and the density of `wi` given `wo` (world
    /// directions, away from the surface).
    pub(super) fn eval(&mut self, v: &Vertex, wo: Vec3, wi: Vec3) -> BsdfEval {
        let local = [v.it.frame.to_local(wi)];
        let mut out = [BsdfEval::default()];
        self.call(v, wo, |s, ctx, batch| s.eval(ctx, batch, &local, &mut out));
        out[0]
    }

    /// A sampled direction given `wo` (world), with `wi` in world space.
    pub(super) fn sample(&mut self, v: &Vertex, wo: Vec3, u: [f32; 3]) -> BsdfSample {
        let u = [Vec3::from(u)];
        let mut out = [BsdfSample::default()];
        self.call(v, wo, |s, ctx, batch| s.sample(ctx, batch, &u, &mut out));
        let mut s = out[0];
        s.wi = v.it.frame.to_world(s.wi);
        s
    }

    /// The albedo of `v`'s material seen from `v.wo` (for the output
    /// variables).
    pub(super) fn albedo(&mut self, v: &Vertex) -> Rgb {
        let mut out = [Rgb::ZERO];
        self.call(v, v.wo, |s, ctx, batch| s.albedo(ctx, batch, &mut out));
        out[0]
    }

    /// Whether `v`'s material has a smooth lobe (connections can reach it).
    pub(super) fn connectable(&self, v: &Vertex) -> bool {
        v.kind == Kind::Surface
            && self.scene.shaders[v.material as usize]
                .effects()
                .contains(Effects::SMOOTH_LOBES)
    }
}

/// A subpath: its vertices and their MIS state, reused from sample to
/// sample (cleared, never shrunk).
#[derive(Default)]
pub(super) struct Subpath {
    /// The vertices.
    pub v: Vec<Vertex>,
    /// Their MIS state.
    pub mis: Vec<Mis>,
}

impl Subpath {
    /// Empties the subpath, keeping its memory.
    pub(super) fn clear(&mut self) {
        self.v.clear();
        self.mis.clear();
    }

    /// Appends a vertex.
    pub(super) fn push(&mut self, v: Vertex, mis: Mis) {
        self.v.push(v);
        self.mis.push(mis);
    }

    /// Number of vertices.
    pub(super) fn len(&self) -> usize {
        self.v.len()
    }
}
