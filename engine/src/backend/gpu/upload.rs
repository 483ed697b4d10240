//! The frame's geometry in the GPU's layout: primitives in leaf order of
//! per-mesh binary BVHs, their shading data beside them, instances, and
//! the top level (see `wgsl/geometry.wgsl` for the layouts).
//!
//! Primitive numbers stay those of the CPU's [`Accel`](crate::accel::Accel)
//! (each bottom level's leaf order from its base), so the shading arrays
//! of [`Surfaces`](crate::extract::Surfaces) are read as they are; the
//! GPU's own leaf order is a permutation of each bottom level's slots.

use super::bvh::{Node, build_level};
use super::error::GpuError;
use crate::accel::{Place, Primitive};
use crate::extract::{NO_EMITTER, NO_MATERIAL, RenderScene};
use glam::Vec3A;
use obvhs::aabb::Aabb;
use radiant_core::Effects;

/// A `vec4f` of a storage buffer.
pub type Vec4 = [f32; 4];

/// The frame's geometry, ready to upload.
#[derive(Debug, Clone, Default)]
pub struct Geometry {
    /// All hierarchies' nodes (bottom levels, then the top level).
    pub nodes: Vec<Node>,
    /// Primitives, four `vec4f` each.
    pub prims: Vec<Vec4>,
    /// Shading data, [`Self::shading_rows`] `vec4f` per primitive in the
    /// CPU's numbering (vertex normals with the texture coordinates in
    /// their `w`s, then with tangent frames the vertex tangents; for
    /// spheres, the rows of the rotation to the sphere's object space).
    pub shading: Vec<Vec4>,
    /// Whether shading frames are oriented by the surfaces'
    /// parametrizations (the frame's effects contain `TANGENT_FRAMES`),
    /// which adds the vertex tangents to the shading data.
    pub tangent_frames: bool,
    /// Instances, ten `vec4f` each (empty without a top level).
    pub instances: Vec<Vec4>,
    /// The root rays start from: the top level, or the one bottom level.
    pub root: u32,
    /// Whether rays go through a top level of instances.
    pub instanced: bool,
    /// Whether any primitive is a sphere.
    pub spheres: bool,
}

fn vec4(v: glam::Vec3, w: f32) -> Vec4 {
    [v.x, v.y, v.z, w]
}

fn box_of(p: &Primitive) -> Option<Aabb> {
    let (lo, hi) = match *p {
        Primitive::Triangle([a, b, c]) => (a.min(b).min(c), a.max(b).max(c)),
        Primitive::Sphere(c, r) => (c - glam::Vec3::splat(r), c + glam::Vec3::splat(r)),
    };
    (lo.is_finite() && hi.is_finite()).then(|| Aabb::new(Vec3A::from(lo), Vec3A::from(hi)))
}

impl Geometry {
    /// `vec4f` rows of shading data per primitive (`SHADING_ROWS` in
    /// `geometry.wgsl`).
    pub fn shading_rows(&self) -> usize {
        if self.tangent_frames { 7 } else { 4 }
    }

    /// Lays out the geometry of `scene`. Motion while the shutter is open
    /// has no GPU code yet: such scenes are refused.
    pub fn new(scene: &RenderScene) -> Result<Self, GpuError> {
        let accel = &scene.accel;
        let surfaces = &scene.surfaces;
        let mut g = Geometry {
            tangent_frames: scene.effects.contains(Effects::TANGENT_FRAMES),
            ..Geometry::default()
        };
        let rows = g.shading_rows();
        let total: usize = accel.blases().iter().map(|b| b.len()).sum();
        g.shading = vec![[0.0; 4]; rows * total];
        let mut roots = Vec::with_capacity(accel.blases().len());
        for (b, blas) in accel.blases().iter().enumerate() {
            if blas.deforms() {
                return Err(GpuError::Unsupported(
                    "meshes that deform while the shutter is open (motion blur)".into(),
                ));
            }
            let base = accel.base(b);
            let prims = blas.primitives();
            let boxes: Vec<Option<Aabb>> = prims.iter().map(box_of).collect();
            let first_slot = (g.prims.len() / 4) as u32;
            let level = build_level(&boxes, first_slot, &mut g.nodes);
            roots.push(level.root);
            for &i in &level.order {
                let id = base + i;
                let k = id as usize;
                let (a, b, c, kind) = match prims[i as usize] {
                    Primitive::Triangle([a, b, c]) => (a, b, c, 0),
                    Primitive::Sphere(centre, r) => {
                        g.spheres = true;
                        (centre, glam::Vec3::new(r, 0.0, 0.0), glam::Vec3::ZERO, 1)
                    }
                };
                let emitter = surfaces.emitter.get(k).copied().unwrap_or(NO_EMITTER);
                let info = [
                    surfaces.material[k],
                    emitter,
                    surfaces.emitter_prim.get(k).copied().unwrap_or(0),
                    id,
                ];
                g.prims.extend([
                    vec4(a, f32::from_bits(kind)),
                    vec4(b, 0.0),
                    vec4(c, 0.0),
                    info.map(f32::from_bits),
                ]);
                let n = surfaces.normals[k];
                let uv = surfaces.uvs.get(k).copied().unwrap_or_default();
                let row = &mut g.shading[rows * k..rows * (k + 1)];
                row[..4].copy_from_slice(&[
                    vec4(n[0], uv[0].x),
                    vec4(n[1], uv[0].y),
                    vec4(n[2], uv[1].x),
                    [uv[1].y, uv[2].x, uv[2].y, 0.0],
                ]);
                if let Some(t) = surfaces.tangents.get(k).filter(|_| rows > 4) {
                    row[4..].copy_from_slice(&t.map(|t| vec4(t, 0.0)));
                }
            }
        }
        let instances = accel.instances();
        let direct = instances.len() == 1 && instances[0].place == Place::Identity;
        if direct {
            g.root = roots[instances[0].blas as usize];
            return Ok(g);
        }
        g.instanced = true;
        let mut boxes = Vec::with_capacity(instances.len());
        for (i, inst) in instances.iter().enumerate() {
            let (to_object, normals, to_render) = match &inst.place {
                Place::Identity => (
                    glam::Affine3A::IDENTITY,
                    glam::Mat3A::IDENTITY,
                    glam::Affine3A::IDENTITY,
                ),
                Place::Fixed(p) => (p.to_object, p.normals, p.to_render),
                Place::Moving(_) => {
                    return Err(GpuError::Unsupported(
                        "shapes that move while the shutter is open (motion blur)".into(),
                    ));
                }
            };
            boxes.push(accel.instance_bounds(i));
            let rows = |a: &glam::Affine3A| {
                let m = glam::Mat4::from(*a).transpose();
                [
                    m.x_axis.to_array(),
                    m.y_axis.to_array(),
                    m.z_axis.to_array(),
                ]
            };
            let n = glam::Mat3::from(normals).transpose();
            let meta = [
                roots[inst.blas as usize],
                match scene.instance_material[i] {
                    NO_MATERIAL => u32::MAX,
                    m => m,
                },
                0,
                0,
            ];
            g.instances.extend(rows(&to_object));
            g.instances.extend([
                vec4(n.x_axis, 0.0),
                vec4(n.y_axis, 0.0),
                vec4(n.z_axis, 0.0),
            ]);
            g.instances.extend(rows(&to_render));
            g.instances.push(meta.map(f32::from_bits));
        }
        // The top level's leaves reference instance indices directly: its
        // order permutes the instances.
        let level = build_level(&boxes, 0, &mut g.nodes);
        let mut ordered = Vec::with_capacity(g.instances.len());
        for &i in &level.order {
            ordered.extend_from_slice(&g.instances[i as usize * 10..i as usize * 10 + 10]);
        }
        g.instances = ordered;
        g.root = level.root;
        Ok(g)
    }
}
