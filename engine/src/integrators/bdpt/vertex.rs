//! Subpath vertices, the conversion of a solid-angle density into one per
//! unit area at the vertex reached, and the storage of a chunk's subpaths
//! (one fixed-length row of vertices per camera sample).

use super::mis::Mis;
use crate::integrators::surface::{Derivatives, Interaction};
use glam::{Vec2, Vec3};
use radiant_core::{EmissionKind, Frame, Rgb};

/// What a vertex lies on.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub(super) enum Kind {
    /// The lens (a camera subpath's first vertex).
    #[default]
    Camera,
    /// A light (a light subpath's first vertex), emitting as `EmissionKind`.
    Light(EmissionKind),
    /// A surface, shaded by its material.
    Surface,
}

/// One vertex of a subpath.
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
    /// Whether it is a surface whose material has a smooth lobe
    /// (connections can reach it).
    pub connectable: bool,
}

impl Default for Vertex {
    fn default() -> Self {
        Self::point(Kind::Camera, Vec3::ZERO, Vec3::ZERO, Rgb::ZERO)
    }
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
            connectable: false,
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

/// One kind of subpath (camera or light) of every sample of a chunk: row
/// `j` holds sample `j`'s vertices and their MIS state, `stride` of them
/// at most. Reused from chunk to chunk (never shrunk).
#[derive(Default)]
pub(super) struct Subpaths {
    stride: usize,
    v: Vec<Vertex>,
    mis: Vec<Mis>,
    len: Vec<u32>,
}

impl Subpaths {
    /// Empties the rows of `n` samples of at most `stride` vertices.
    pub(super) fn reset(&mut self, n: usize, stride: usize) {
        self.stride = stride;
        if self.v.len() < n * stride {
            self.v.resize(n * stride, Vertex::default());
            self.mis.resize(n * stride, Mis::default());
        }
        self.len.clear();
        self.len.resize(n, 0);
    }

    /// Appends a vertex to sample `j`'s row.
    #[inline]
    pub(super) fn push(&mut self, j: usize, v: Vertex, mis: Mis) {
        let at = j * self.stride + self.len[j] as usize;
        self.v[at] = v;
        self.mis[at] = mis;
        self.len[j] += 1;
    }

    /// Number of vertices of sample `j`.
    #[inline]
    pub(super) fn len(&self, j: usize) -> usize {
        self.len[j] as usize
    }

    /// Vertex `k` of sample `j`.
    #[inline]
    pub(super) fn at(&self, j: usize, k: usize) -> &Vertex {
        &self.v[j * self.stride + k]
    }

    /// The MIS state of sample `j`'s vertices 0 ..= `k`.
    #[inline]
    pub(super) fn mis(&self, j: usize, k: usize) -> &[Mis] {
        let a = j * self.stride;
        &self.mis[a..=a + k]
    }

    /// The MIS state of sample `j`'s vertices 0 ..= `k`, to complete.
    #[inline]
    pub(super) fn mis_mut(&mut self, j: usize, k: usize) -> &mut [Mis] {
        let a = j * self.stride;
        &mut self.mis[a..=a + k]
    }
}
