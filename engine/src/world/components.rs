//! Component types of the scene world.

use glam::{DMat4, Vec2, Vec3};
use radiant_core::Params;
use radiant_core::params::Location;
use std::sync::Arc;

/// The name a scene gave an entity.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Name(pub String);

/// Object-to-world transform, in double precision.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Transform(pub DMat4);

/// A module instance as written in the scene: its `type` and parameters.
#[derive(Debug, Clone)]
pub struct ModuleSpec {
    /// The YAML `type` name.
    pub type_name: String,
    /// Where the `type` was written.
    pub location: Option<Location>,
    /// The remaining keys, for the module to parse.
    pub params: Params,
}

/// The shape of a surface entity (conventions of Mitsuba 3).
#[derive(Debug, Clone)]
pub enum Geometry {
    /// The square [-1,1]² in the z = 0 plane, normal +z.
    Rectangle,
    /// The cube [-1,1]³, normals outwards.
    Cube,
    /// The unit sphere at the origin, normals outwards.
    Sphere,
    /// A triangle mesh.
    Mesh(Arc<MeshData>),
}

/// What the mesh loader repaired, for reporting.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct MeshRepairs {
    /// Triangles dropped for non-finite vertex coordinates.
    pub non_finite: usize,
    /// Triangles dropped for zero area (including repeated vertices).
    pub degenerate: usize,
    /// Vertex normals that were zero or non-finite (the face normal is used).
    pub bad_normals: usize,
}

/// A triangle mesh in object space.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct MeshData {
    /// Vertex positions.
    pub positions: Vec<Vec3>,
    /// Per-vertex shading normals, if the mesh has them.
    pub normals: Option<Vec<Vec3>>,
    /// Per-vertex texture coordinates, if the mesh has them.
    pub uvs: Option<Vec<Vec2>>,
    /// Vertex indices of each triangle.
    pub triangles: Vec<[u32; 3]>,
    /// What loading repaired.
    pub repairs: MeshRepairs,
}

/// Index of a surface's material in the scene's material list.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct MaterialRef(pub u32);

/// An emitter attached to a surface.
#[derive(Debug, Clone)]
pub struct EmitterSpec(pub ModuleSpec);

/// A light that is not attached to a surface.
#[derive(Debug, Clone)]
pub struct LightSpec(pub ModuleSpec);

/// The camera's pose (camera to world) and module.
#[derive(Debug, Clone)]
pub struct CameraPose {
    /// Camera space (+z forward, +y up, +x left) to world.
    pub to_world: DMat4,
    /// The camera module.
    pub module: ModuleSpec,
}
