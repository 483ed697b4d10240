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

/// What loading and tessellation repaired in a shape, for reporting.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct MeshRepairs {
    /// Triangles dropped for non-finite vertex coordinates (in the file, or
    /// after the transform to render space overflowed).
    pub non_finite: usize,
    /// Triangles dropped for zero area (repeated vertices, collinear
    /// vertices, or a normal that is zero in single precision once in
    /// render space).
    pub degenerate: usize,
    /// Vertex normals that were zero or non-finite (the face normal is used).
    pub bad_normals: usize,
    /// Texture coordinates that were non-finite (set to (0, 0)).
    pub bad_uvs: usize,
    /// The mesh has no texture coordinates: each triangle gets (0, 0),
    /// (1, 0), (0, 1), as Mitsuba does.
    pub missing_uvs: bool,
}

impl MeshRepairs {
    /// Adds the counts of `other` to these.
    pub fn add(&mut self, other: &MeshRepairs) {
        self.non_finite += other.non_finite;
        self.degenerate += other.degenerate;
        self.bad_normals += other.bad_normals;
        self.bad_uvs += other.bad_uvs;
        self.missing_uvs |= other.missing_uvs;
    }

    /// Whether anything was dropped or replaced (missing texture
    /// coordinates are normal and do not count).
    pub fn any(&self) -> bool {
        self.non_finite + self.degenerate + self.bad_normals + self.bad_uvs > 0
    }

    /// One line saying what was repaired, e.g. "dropped 2 triangles with
    /// non-finite coordinates and 3 of zero area, replaced 1 vertex normal".
    pub fn describe(&self) -> String {
        let plural =
            |n: usize, one: &str, many: &str| format!("{n} {}", if n == 1 { one } else { many });
        let mut dropped = Vec::new();
        if self.non_finite > 0 {
            dropped.push(format!(
                "{} with non-finite coordinates",
                plural(self.non_finite, "triangle", "triangles")
            ));
        }
        if self.degenerate > 0 {
            dropped.push(format!(
                "{} of zero area",
                plural(self.degenerate, "triangle", "triangles")
            ));
        }
        let mut parts = Vec::new();
        if !dropped.is_empty() {
            parts.push(format!("dropped {}", dropped.join(" and ")));
        }
        if self.bad_normals > 0 {
            parts.push(format!(
                "replaced {} of zero length or non-finite by the face normal",
                plural(self.bad_normals, "vertex normal", "vertex normals")
            ));
        }
        if self.bad_uvs > 0 {
            parts.push(format!(
                "set {} to (0, 0)",
                plural(
                    self.bad_uvs,
                    "non-finite texture coordinate",
                    "non-finite texture coordinates"
                )
            ));
        }
        if parts.is_empty() {
            "nothing repaired".to_string()
        } else {
            parts.join(", ")
        }
    }
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
    /// The file the mesh was read from, for messages.
    pub source: String,
}

/// Marks a shape whose normals are flipped (`flip_normals: true`): its
/// front side, the side that reflects and emits, faces the other way.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct FlippedNormals;

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
