//! The frame's geometry in the GPU's layout: primitives in leaf order of
//! per-mesh BVHs (binary or compressed wide, [`BvhLayout`]), their shading
//! data beside them, instances, the motion of what moves while the shutter
//! is open, and the top level (see `wgsl/geometry.wgsl` and
//! `wgsl/cwbvh.wgsl` for the layouts).
//!
//! Primitive numbers stay those of the CPU's [`Accel`](crate::accel::Accel)
//! (each bottom level's leaf order from its base), so the shading arrays
//! of [`Surfaces`](crate::extract::Surfaces) are read as they are; the
//! GPU's own leaf order is a permutation of each bottom level's slots.

use super::BvhLayout;
use super::bvh::build_level;
use super::error::GpuError;
use crate::accel::{Motion, Place, Primitive};
use crate::extract::{NO_EMITTER, NO_MATERIAL, RenderScene};
use glam::{Affine3A, DMat4, Mat3A, Vec3, Vec3A};
use obvhs::aabb::Aabb;
use radiant_core::Effects;

/// A `vec4f` of a storage buffer.
pub type Vec4 = [f32; 4];

/// Rows of an instance record (`INSTANCE_ROWS` in `geometry.wgsl`).
const INSTANCE_ROWS: usize = 10;

/// "None" in a reference word (`NO_HIT` in `geometry.wgsl`).
const NONE: u32 = u32::MAX;

/// The frame's geometry, ready to upload.
#[derive(Debug, Clone, Default)]
pub struct Geometry {
    /// All hierarchies' nodes (bottom levels, then the top level), as
    /// [`BvhLayout::rows_per_node`] `vec4f` rows each.
    pub nodes: Vec<Vec4>,
    /// The layout of `nodes`.
    pub layout: BvhLayout,
    /// Primitives, [`Self::prim_rows`] `vec4f` each: the shape at shutter
    /// open, its reference words, then under motion blur the shape at
    /// shutter close.
    pub prims: Vec<Vec4>,
    /// Shading data, [`Self::shading_rows`] `vec4f` per primitive in the
    /// CPU's numbering (vertex normals with the texture coordinates in
    /// their `w`s, then with tangent frames the vertex tangents; for
    /// spheres, the rows of the rotation to the sphere's object space).
    pub shading: Vec<Vec4>,
    /// Instances, ten `vec4f` each (empty without a top level), then the
    /// motion records of moving instances and of a moving camera.
    pub instances: Vec<Vec4>,
    /// The root rays start from: the top level, or the one bottom level.
    pub root: u32,
    /// The row of the camera's motion record in `instances` ([`u32::MAX`]
    /// where the camera does not move while the shutter is open).
    pub camera_motion: u32,
    /// Whether rays go through a top level of instances.
    pub instanced: bool,
    /// Whether any primitive is a sphere.
    pub spheres: bool,
    /// Whether shading frames are oriented by the surfaces'
    /// parametrizations (the frame's effects contain `TANGENT_FRAMES`),
    /// which adds the vertex tangents to the shading data.
    pub tangent_frames: bool,
    /// Whether rays carry a time in the shutter (motion blur), which adds
    /// the shapes at shutter close to the primitives.
    pub motion: bool,
}

fn vec4(v: Vec3, w: f32) -> Vec4 {
    [v.x, v.y, v.z, w]
}

fn box_of(p: &Primitive) -> Option<Aabb> {
    let (lo, hi) = match *p {
        Primitive::Triangle([a, b, c]) => (a.min(b).min(c), a.max(b).max(c)),
        Primitive::Sphere(c, r) => (c - Vec3::splat(r), c + Vec3::splat(r)),
    };
    (lo.is_finite() && hi.is_finite()).then(|| Aabb::new(Vec3A::from(lo), Vec3A::from(hi)))
}

/// The shape rows of a primitive: three vertices, or a sphere's centre
/// and radius (kind in the first row's `w`: 0 triangle, 1 sphere).
fn shape_rows(p: &Primitive) -> [Vec4; 3] {
    match *p {
        Primitive::Triangle([a, b, c]) => [vec4(a, f32::from_bits(0)), vec4(b, 0.0), vec4(c, 0.0)],
        Primitive::Sphere(centre, r) => [
            vec4(centre, f32::from_bits(1)),
            vec4(Vec3::new(r, 0.0, 0.0), 0.0),
            [0.0; 4],
        ],
    }
}

/// The rows of the 3×4 matrix of `m` (translation in `w`).
fn affine_rows(m: &Affine3A) -> [Vec4; 3] {
    let m = glam::Mat4::from(*m).transpose();
    [
        m.x_axis.to_array(),
        m.y_axis.to_array(),
        m.z_axis.to_array(),
    ]
}

/// The rows of the 3×4 matrix of `m` (f64) in f32.
fn matrix_rows(m: &DMat4) -> [Vec4; 3] {
    let m = m.transpose().as_mat4();
    [
        m.x_axis.to_array(),
        m.y_axis.to_array(),
        m.z_axis.to_array(),
    ]
}

/// A motion record (12 `vec4f`): the rows of `outer` and of `inner`, then
/// the translation, rotation (quaternion) and scale at shutter open and
/// at shutter close (`motion_affine` in `geometry.wgsl`).
fn motion_record(m: &Motion) -> [Vec4; 12] {
    let [o0, o1, o2] = matrix_rows(&m.outer);
    let [i0, i1, i2] = matrix_rows(&m.inner);
    let pose = |t: &crate::world::Trs| {
        [
            vec4(t.translate.as_vec3(), 0.0),
            t.rotate.as_quat().to_array(),
            vec4(t.scale.as_vec3(), 0.0),
        ]
    };
    let [a0, a1, a2] = pose(&m.open);
    let [b0, b1, b2] = pose(&m.close);
    [o0, o1, o2, i0, i1, i2, a0, a1, a2, b0, b1, b2]
}

/// Bottom levels as the last frame laid them out, so that a frame lays
/// out only the levels that changed (deforming meshes) or moved in the
/// arrays (those after a level whose size changed). Instances, the top
/// level and the motion records are laid out every frame.
#[derive(Debug, Default)]
pub struct LevelCache {
    /// Per bottom level of the accelerator.
    levels: Vec<Option<CachedLevel>>,
    /// Bottom levels laid out (not taken from the cache) so far.
    built: u64,
}

impl LevelCache {
    /// How many bottom levels were laid out rather than reused.
    pub fn built(&self) -> u64 {
        self.built
    }
}

/// What a bottom level's layout depends on: the level's version and where
/// its nodes and primitives start (references in them are absolute), and
/// the layout's options.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
struct LevelKey {
    version: u64,
    nodes: usize,
    prims: usize,
    layout: BvhLayout,
    motion: bool,
    tangent_frames: bool,
}

/// One bottom level's rows, as laid out for `key`.
#[derive(Debug)]
struct CachedLevel {
    key: LevelKey,
    nodes: Vec<Vec4>,
    prims: Vec<Vec4>,
    shading: Vec<Vec4>,
    spheres: bool,
    root: u32,
}

impl Geometry {
    /// `vec4f` rows per primitive (`PRIM_ROWS` in `geometry.wgsl`).
    pub fn prim_rows(&self) -> usize {
        if self.motion { 7 } else { 4 }
    }

    /// `vec4f` rows of shading data per primitive (`SHADING_ROWS` in
    /// `geometry.wgsl`).
    pub fn shading_rows(&self) -> usize {
        if self.tangent_frames { 7 } else { 4 }
    }

    /// The number of nodes of all hierarchies.
    pub fn node_count(&self) -> usize {
        self.nodes.len() / self.layout.rows_per_node()
    }

    /// Lays out the geometry of `scene` with hierarchies of `layout`.
    pub fn new(scene: &RenderScene, layout: BvhLayout) -> Result<Self, GpuError> {
        Self::with_cache(scene, layout, &mut LevelCache::default())
    }

    /// [`Geometry::new`], taking the bottom levels that did not change
    /// from `cache` (and keeping this frame's there for the next).
    pub fn with_cache(
        scene: &RenderScene,
        layout: BvhLayout,
        cache: &mut LevelCache,
    ) -> Result<Self, GpuError> {
        let accel = &scene.accel;
        let mut g = Geometry {
            layout,
            tangent_frames: scene.effects.contains(Effects::TANGENT_FRAMES),
            motion: scene.motion_blur(),
            camera_motion: NONE,
            ..Geometry::default()
        };
        let total: usize = accel.blases().iter().map(|b| b.len()).sum();
        g.shading = vec![[0.0; 4]; g.shading_rows() * total];
        cache.levels.resize_with(accel.blases().len(), || None);
        let roots: Vec<u32> = (0..accel.blases().len())
            .map(|b| g.cached_bottom_level(scene, b, cache))
            .collect();
        let instances = accel.instances();
        let direct = instances.len() == 1 && instances[0].place == Place::Identity;
        if direct {
            g.root = roots[instances[0].blas as usize];
        } else {
            g.top_level(scene, &roots);
        }
        if let Some(m) = &scene.camera_motion {
            g.camera_motion = g.instances.len() as u32;
            g.instances.extend(motion_record(m));
        }
        Ok(g)
    }

    /// Bottom level `b` from `cache` where it is the same level at the same
    /// place in the arrays as last frame, else laid out and kept there.
    /// Returns its root.
    fn cached_bottom_level(
        &mut self,
        scene: &RenderScene,
        b: usize,
        cache: &mut LevelCache,
    ) -> u32 {
        let blas = &scene.accel.blases()[b];
        let key = LevelKey {
            version: blas.version(),
            nodes: self.nodes.len(),
            prims: self.prims.len(),
            layout: self.layout,
            motion: self.motion,
            tangent_frames: self.tangent_frames,
        };
        let rows = self.shading_rows();
        let shading =
            rows * scene.accel.base(b) as usize..rows * (scene.accel.base(b) as usize + blas.len());
        if let Some(level) = cache.levels[b].as_ref().filter(|l| l.key == key) {
            self.nodes.extend_from_slice(&level.nodes);
            self.prims.extend_from_slice(&level.prims);
            self.shading[shading].copy_from_slice(&level.shading);
            self.spheres |= level.spheres;
            return level.root;
        }
        let spheres = std::mem::take(&mut self.spheres);
        let root = self.bottom_level(scene, b);
        cache.built += 1;
        cache.levels[b] = Some(CachedLevel {
            nodes: self.nodes[key.nodes..].to_vec(),
            prims: self.prims[key.prims..].to_vec(),
            shading: self.shading[shading].to_vec(),
            spheres: self.spheres,
            root,
            key,
        });
        self.spheres |= spheres;
        root
    }

    /// Lays out bottom level `b` of the scene's accelerator: its nodes,
    /// its primitives in leaf order and their shading data. Returns its
    /// root.
    fn bottom_level(&mut self, scene: &RenderScene, b: usize) -> u32 {
        let surfaces = &scene.surfaces;
        let blas = &scene.accel.blases()[b];
        let base = scene.accel.base(b);
        let prims = blas.primitives();
        let closing = blas.closing_primitives();
        // A deforming primitive's box contains it at both ends of the
        // shutter, so it contains every vertex interpolated between them.
        let boxes: Vec<Option<Aabb>> = match closing {
            None => prims.iter().map(box_of).collect(),
            Some(close) => prims
                .iter()
                .zip(close)
                .map(|(a, b)| Some(box_of(a)?.union(&box_of(b)?)))
                .collect(),
        };
        let first_slot = (self.prims.len() / self.prim_rows()) as u32;
        let level = build_level(&boxes, first_slot, self.layout, &mut self.nodes);
        let rows = self.shading_rows();
        for &i in &level.order {
            let id = base + i;
            let k = id as usize;
            let p = &prims[i as usize];
            self.spheres |= matches!(p, Primitive::Sphere(..));
            let emitter = surfaces.emitter.get(k).copied().unwrap_or(NO_EMITTER);
            let info = [
                surfaces.material[k],
                emitter,
                surfaces.emitter_prim.get(k).copied().unwrap_or(0),
                id,
            ];
            self.prims.extend(shape_rows(p));
            self.prims.push(info.map(f32::from_bits));
            if self.motion {
                let close = closing.map_or(p, |c| &c[i as usize]);
                self.prims.extend(shape_rows(close));
            }
            let n = surfaces.normals[k];
            let uv = surfaces.uvs.get(k).copied().unwrap_or_default();
            let row = &mut self.shading[rows * k..rows * (k + 1)];
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
        level.root
    }

    /// Lays out the instances and the top level over them, and the motion
    /// records of moving instances after the instances.
    fn top_level(&mut self, scene: &RenderScene, roots: &[u32]) {
        let accel = &scene.accel;
        let instances = accel.instances();
        self.instanced = true;
        let mut boxes = Vec::with_capacity(instances.len());
        let mut records = Vec::with_capacity(instances.len() * INSTANCE_ROWS);
        let mut motions = Vec::new();
        for (i, inst) in instances.iter().enumerate() {
            let (to_object, normals, to_render) = match &inst.place {
                Place::Identity | Place::Moving(_) => {
                    (Affine3A::IDENTITY, Mat3A::IDENTITY, Affine3A::IDENTITY)
                }
                Place::Fixed(p) => (p.to_object, p.normals, p.to_render),
            };
            let motion = match &inst.place {
                Place::Moving(m) => {
                    motions.push(motion_record(m));
                    // Rows from the end of the instance records.
                    (instances.len() * INSTANCE_ROWS + (motions.len() - 1) * 12) as u32
                }
                _ => NONE,
            };
            boxes.push(accel.instance_bounds(i));
            let n = glam::Mat3::from(normals).transpose();
            let material = match scene.instance_material[i] {
                NO_MATERIAL => NONE,
                m => m,
            };
            let meta = [roots[inst.blas as usize], material, motion, 0];
            records.extend(affine_rows(&to_object));
            records.extend([
                vec4(n.x_axis, 0.0),
                vec4(n.y_axis, 0.0),
                vec4(n.z_axis, 0.0),
            ]);
            records.extend(affine_rows(&to_render));
            records.push(meta.map(f32::from_bits));
        }
        // The top level's leaves reference instance indices directly: its
        // order permutes the instances.
        let level = build_level(&boxes, 0, self.layout, &mut self.nodes);
        for &i in &level.order {
            let at = i as usize * INSTANCE_ROWS;
            self.instances
                .extend_from_slice(&records[at..at + INSTANCE_ROWS]);
        }
        self.instances.extend(motions.iter().flatten());
        self.root = level.root;
    }
}
