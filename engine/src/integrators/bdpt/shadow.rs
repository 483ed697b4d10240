//! The shadow rays of a connection stage, traced as one batch: each
//! connection queues the segment between its two vertices, and one
//! `Accel::occluded_each` call answers them all.

use super::vertex::{Kind, Vertex};
use crate::accel::offset::{offset_origin, sampled_point_error};
use crate::extract::RenderScene;
use glam::Vec3;

/// Shadow rays stop this fraction short of their end (as `path`'s).
const SHADOW_EPSILON: f32 = 1e-4;

/// A batch of shadow rays, reused from stage to stage.
#[derive(Default)]
pub(super) struct Shadows {
    origin: Vec<Vec3>,
    dir: Vec<Vec3>,
    /// Per ray, after [`Shadows::trace`]: whether something blocks it.
    pub blocked: Vec<bool>,
}

impl Shadows {
    /// Drops every ray.
    pub(super) fn clear(&mut self) {
        self.origin.clear();
        self.dir.clear();
    }

    /// Queues the segment between `a` and `b` (surface, lens or light
    /// points), each end offset off its surface; returns its index.
    pub(super) fn push(&mut self, a: &Vertex, b: &Vertex) -> usize {
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
        self.origin.push(from);
        self.dir.push(to - from);
        self.origin.len() - 1
    }

    /// Traces the queued rays; returns how many.
    pub(super) fn trace(&mut self, scene: &RenderScene) -> u64 {
        let n = self.origin.len();
        self.blocked.clear();
        self.blocked.resize(n, false);
        scene.accel.occluded_each(
            &self.origin,
            &self.dir,
            None,
            1.0 - SHADOW_EPSILON,
            &mut self.blocked,
        );
        n as u64
    }
}
