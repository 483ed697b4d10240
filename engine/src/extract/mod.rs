//! Extract: from the ECS world to flat render data, once per sequence and
//! then frame by frame.
//!
//! Extract decides *render space* — world space shifted in double precision
//! so that the camera's position at the scene's first frame is the origin,
//! so that geometry far from the world origin keeps full `f32` precision —
//! tessellates shapes into primitives, builds every module instance
//! through the registry, builds the acceleration structure, lays the
//! per-primitive shading data out in its order (structure of arrays), and
//! unions the modules' [`Effects`] into the frame's effect set.
//!
//! It is split by what changes between frames ([`Sequence`]):
//!
//! * built once: decoded textures, materials, the merged bottom level of
//!   all static shapes (in render space), the object-space bottom level of
//!   each moving, deforming or instanced shape ([`geometry`]), the filter;
//! * updated per frame: instance placements and the top level, deforming
//!   meshes (refitted), modules whose animated parameters changed and what
//!   depends on them, lights on shapes that moved, lights at infinity when
//!   the scene's bounds changed, the camera, the sampler's seed
//!   ([`modules`]).
//!
//! [`extract`] builds the scene's current frame alone.

pub mod facing;
mod geometry;
mod light_tree;
mod lights;
mod materials;
mod media;
mod modules;
mod sequence;
mod shapes;

pub use light_tree::{LightTree, Node as LightTreeNode};
pub use lights::{FLAT_LIMIT, LightTable, SpatialTables};
pub use media::MediaTable;
pub use sequence::{FrameUpdate, Sequence, SequenceOptions};
pub(crate) use shapes::BARYCENTRIC_UVS;

use crate::accel::{Accel, Hit, Motion};
use crate::error::SceneError;
pub use crate::settings::Overrides;
use crate::settings::RenderSettings;
use crate::world::{MeshRepairs, Scene};
use glam::{Vec2, Vec3};
use radiant_core::{
    Camera, Effects, Filter, Frame, ModuleKind, Registry, Sampler, Shader, TextureId, TextureTable,
};
use std::collections::BTreeSet;
use std::time::Duration;

/// "No emitter" in [`Surfaces::emitter`].
pub const NO_EMITTER: u32 = u32::MAX;

/// "The primitive's own material" in [`RenderScene::instance_material`].
pub const NO_MATERIAL: u32 = u32::MAX;

/// Per-primitive shading data, indexed by primitive number
/// ([`Hit::prim`]: every bottom level's primitives in leaf order, one
/// level after the other).
#[derive(Debug, Default)]
pub struct Surfaces {
    /// Material (shader) index.
    pub material: Vec<u32>,
    /// Light index of the emitter on this primitive, or [`NO_EMITTER`].
    pub emitter: Vec<u32>,
    /// Index of the primitive within its emitter's shape.
    pub emitter_prim: Vec<u32>,
    /// Vertex normals of triangles (all zero: use the face normal), in the
    /// primitive's own space; for spheres, the rows of the rotation from
    /// that space to the sphere's object space, where its texture
    /// coordinates are defined (Mitsuba 3's: u = atan2(y, x)/2π, v =
    /// acos(z)/π).
    pub normals: Vec<[Vec3; 3]>,
    /// Vertex texture coordinates of triangles.
    pub uvs: Vec<[Vec2; 3]>,
    /// Vertex tangents of triangles (MikkTSpace, in the primitive's own
    /// space; all zero: take ∂p/∂u of the face). Empty where no shape has
    /// any.
    pub tangents: Vec<[Vec3; 3]>,
    /// Frame around the unit face normal of triangles in render space (by
    /// winding), made once here rather than at every hit; `n` is the
    /// geometric normal. (Primitives of placed instances make theirs at
    /// the hit.)
    pub face_frames: Vec<Frame>,
}

/// Counts that `radiant info` reports.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct SceneStats {
    /// Triangles after tessellation (each shape's once, however often it
    /// is instanced).
    pub triangles: usize,
    /// Analytic spheres.
    pub spheres: usize,
    /// Shapes carrying an emitter.
    pub emissive_shapes: usize,
    /// What was repaired in all shapes together (on load and in render
    /// space).
    pub repairs: MeshRepairs,
    /// Each shape in which something was repaired, by name (and mesh
    /// file), with its counts (a mesh used by several shapes is listed for each).
    pub repaired_shapes: Vec<(String, MeshRepairs)>,
    /// Time the last build or update of the acceleration structure took.
    pub bvh_build: Duration,
    /// Instances of the top level (the merged static shapes count one).
    pub instances: usize,
    /// Triangles summed over all instances.
    pub instanced_triangles: u64,
    /// Shapes with an `animation:` that moves them.
    pub animated_shapes: usize,
    /// Deforming meshes (OBJ sequences).
    pub deforming_meshes: usize,
    /// Shapes with `instances:`.
    pub instanced_shapes: usize,
}

/// Everything a backend needs to render one frame.
pub struct RenderScene {
    /// The frame's settings, overrides applied.
    pub settings: RenderSettings,
    /// The frame number.
    pub frame: i64,
    /// The acceleration structure.
    pub accel: Accel,
    /// Shading data per primitive.
    pub surfaces: Surfaces,
    /// Per instance, the material that replaces its primitives' own
    /// ([`NO_MATERIAL`]: none).
    pub instance_material: Vec<u32>,
    /// Shader per material index.
    pub shaders: Vec<Box<dyn Shader>>,
    /// Material names, per material index.
    pub material_names: Vec<String>,
    /// Material module types, per material index.
    pub material_types: Vec<String>,
    /// The lights.
    pub lights: LightTable,
    /// Light module types, per light index.
    pub light_types: Vec<String>,
    /// The named textures of the scene's `textures:` section: (id, name,
    /// module type), for messages (inline textures have no name).
    pub texture_names: Vec<(TextureId, String, String)>,
    /// The camera.
    pub camera: Box<dyn Camera>,
    /// How camera rays move while the shutter is open: the transform from
    /// the camera's pose at the frame (which the camera module was built
    /// with) to its pose at shutter time τ; `None` where the camera does
    /// not move.
    pub camera_motion: Option<Motion>,
    /// Where render space's origin lies in world space (render space is
    /// world space translated by −`render_origin`).
    pub render_origin: glam::DVec3,
    /// The pixel filter.
    pub filter: Box<dyn Filter>,
    /// The sampler.
    pub sampler: Box<dyn Sampler>,
    /// The integrator (`integrator: {type: …}`), which the backend's
    /// driver for its family renders with.
    pub integrator: Box<dyn crate::integrators::Integrator>,
    /// The textures.
    pub textures: TextureTable,
    /// The participating media (empty for scenes without any).
    pub media: MediaTable,
    /// The light-transport features the frame needs.
    pub effects: Effects,
    /// The module types in use.
    pub modules: BTreeSet<(ModuleKind, String)>,
    /// Counts for reporting.
    pub stats: SceneStats,
}

impl RenderScene {
    /// The material of the surface `hit` found.
    #[inline]
    pub fn material(&self, hit: &Hit) -> u32 {
        match self.instance_material[hit.inst as usize] {
            NO_MATERIAL => self.surfaces.material[hit.prim as usize],
            m => m,
        }
    }

    /// Whether rays carry a time: something moves while the shutter is
    /// open.
    #[inline]
    pub fn motion_blur(&self) -> bool {
        self.effects.contains(Effects::MOTION_BLUR)
    }
}

/// Builds the render data of `scene` as it stands (the frame its systems
/// last moved it to: the scene's first frame after loading).
pub fn extract(
    scene: &Scene,
    registry: &Registry,
    overrides: &Overrides,
) -> Result<RenderScene, SceneError> {
    sequence::build(scene, registry, overrides, &SequenceOptions::default())
        .map(Sequence::into_render_scene)
}
