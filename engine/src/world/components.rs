//! Component types of the scene world.

use super::animation::{Track, TransformTracks, Trs};
use glam::{DMat4, DVec3, Vec2, Vec3};
use marked_yaml::Span;
use radiant_core::Params;
use radiant_core::params::Location;
use std::path::PathBuf;
use std::sync::Arc;

/// The name a scene gave an entity.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Name(pub String);

/// Object-to-world transform at the current frame, in double precision
/// (the animation system writes it for animated entities).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Transform(pub DMat4);

/// The part of an animated entity's transform that does not move: its
/// `transform:` as written, applied before the animated pose.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct BaseTransform(pub DMat4);

/// The translation, rotation and scale tracks of a shape or light
/// (`animation:`); its [`Transform`] is pose(t) · [`BaseTransform`].
#[derive(Debug, Clone, PartialEq)]
pub struct Animation(pub TransformTracks);

/// Where the animation system put an animated entity for the current
/// frame: its pose at the frame's time, and at shutter open and close
/// where it moves while the shutter is open.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Pose {
    /// The pose at the frame's time.
    pub frame: Trs,
    /// The poses at shutter open and close, where they differ.
    pub shutter: Option<(Trs, Trs)>,
}

/// One step of the path from a module's parameters to an animated value.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum ParamStep {
    /// The value of a mapping's key.
    Key(String),
    /// An element of a list.
    Index(usize),
}

/// A module parameter given as `keyframes:`: where it is in the
/// parameters, and its track.
#[derive(Debug, Clone, PartialEq)]
pub struct ParamTrack {
    /// The path from the parameters' mapping to the value.
    pub path: Vec<ParamStep>,
    /// Values over time: one number, or a list of numbers.
    pub track: Track<Vec<f64>>,
    /// Whether the value is one number (else a list).
    pub scalar: bool,
    /// Where the `keyframes` mapping was written (errors about the value
    /// point here).
    pub span: Span,
}

impl ParamTrack {
    /// The YAML node that holds `value` (one number, or a list).
    pub fn node(&self, value: &[f64]) -> marked_yaml::Node {
        use marked_yaml::Node;
        use marked_yaml::types::{MarkedScalarNode, MarkedSequenceNode};
        // `{:?}` prints the shortest text that reads back as the same f64.
        let scalar = |v: f64| Node::Scalar(MarkedScalarNode::new(self.span, format!("{v:?}")));
        if self.scalar {
            scalar(value[0])
        } else {
            let items = value.iter().map(|&v| scalar(v)).collect();
            Node::Sequence(MarkedSequenceNode::new(self.span, items))
        }
    }
}

/// A module instance as written in the scene: its `type` and parameters.
#[derive(Debug, Clone)]
pub struct ModuleSpec {
    /// The YAML `type` name.
    pub type_name: String,
    /// Where the `type` was written.
    pub location: Option<Location>,
    /// The remaining keys, for the module to parse; animated values hold
    /// their value at the current frame.
    pub params: Params,
    /// The animated parameters.
    pub tracks: Vec<ParamTrack>,
    /// Counts the changes of the parameters' values: extract rebuilds the
    /// module when it moves on.
    pub revision: u64,
}

impl ModuleSpec {
    /// Splits a module mapping into its `type` and the parameters the
    /// module parses, leaving out `engine_keys` (which the caller reads
    /// from the node itself); `what` names the module in errors.
    pub fn from_node(
        file: &std::path::Path,
        node: &marked_yaml::Node,
        what: &str,
        engine_keys: &[&str],
    ) -> Result<Self, crate::error::SceneError> {
        use crate::error::SceneError;
        use marked_yaml::Node;
        use marked_yaml::types::MarkedMappingNode;
        let loc = |n: &Node| Location::of(n.span());
        let map = node.as_mapping().ok_or_else(|| {
            SceneError::new(
                file,
                loc(node),
                format!("expected a mapping with a `type` for the {what}"),
            )
        })?;
        let type_node = map.get_node("type").ok_or_else(|| {
            SceneError::new(file, loc(node), format!("the {what} needs a `type`"))
        })?;
        let type_name = type_node
            .as_scalar()
            .ok_or_else(|| {
                SceneError::new(
                    file,
                    loc(type_node),
                    format!("the {what}'s `type` must be a name"),
                )
            })?
            .as_str()
            .to_string();
        let mut rest = MarkedMappingNode::new_empty(*node.span());
        for (k, v) in map.iter() {
            if k.as_str() != "type" && !engine_keys.contains(&k.as_str()) {
                rest.insert(k.clone(), v.clone());
            }
        }
        Ok(Self::new(
            type_name,
            loc(type_node),
            Params::new(Node::Mapping(rest)),
        ))
    }

    /// A module spec with fixed parameters.
    pub fn new(type_name: String, location: Option<Location>, params: Params) -> Self {
        Self {
            type_name,
            location,
            params,
            tracks: Vec::new(),
            revision: 0,
        }
    }
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

/// A mesh read from a numbered sequence of OBJ files, one per frame
/// (`filename: sim/frame_####.obj`): its [`Geometry`] is the mesh at the
/// current frame, every frame with the triangles of the first.
#[derive(Debug, Clone)]
pub struct MeshSequence {
    /// The file name pattern as resolved against the scene's folder; the
    /// run of `#` is the frame number, zero-padded to the run's length.
    pub pattern: PathBuf,
    /// Where `filename` was written.
    pub location: Option<Location>,
    /// How each frame's file is read.
    pub options: crate::scene::mesh::MeshOptions,
    /// The first frame's mesh: every frame must have its triangles.
    pub topology: Arc<MeshData>,
}

/// The mesh of a deforming shape at shutter close, where the shutter is
/// open (its [`Geometry`] then holds the mesh at shutter open).
#[derive(Debug, Clone)]
pub struct ClosingMesh(pub Arc<MeshData>);

/// Copies of a shape (`instances:`), sharing its geometry.
#[derive(Debug, Clone)]
pub struct Instances(pub Arc<[InstanceSpec]>);

/// One copy of an instanced shape.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct InstanceSpec {
    /// Applied after the shape's own transform.
    pub transform: DMat4,
    /// A material of its own, instead of the shape's.
    pub material: Option<MaterialRef>,
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
    /// Per triangle, the MikkTSpace tangent (unit, along ∂p/∂u) at each of
    /// its vertices, where the mesh has texture coordinates.
    pub tangents: Option<Vec<[Vec3; 3]>>,
    /// Vertex indices of each triangle.
    pub triangles: Vec<[u32; 3]>,
    /// What loading repaired.
    pub repairs: MeshRepairs,
    /// Whether `normals` were computed on load (the file had none): a
    /// blend of two frames of a deforming mesh computes them again.
    pub computed_normals: bool,
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
    /// Camera space (+z forward, +y up, +x left) to world, at the current
    /// frame.
    pub to_world: DMat4,
    /// The camera module.
    pub module: ModuleSpec,
}

/// How the camera moves: a `look_at` whose points have tracks, or a
/// `transform` with `animation:` tracks.
#[derive(Debug, Clone, PartialEq)]
pub enum CameraAnimation {
    /// `look_at` with animated points.
    LookAt {
        /// The eye.
        origin: Track<DVec3>,
        /// The point looked at.
        target: Track<DVec3>,
        /// The up direction.
        up: Track<DVec3>,
    },
    /// `animation:` tracks after the camera's `transform`.
    Tracks {
        /// The camera's `transform` (or the identity).
        base: DMat4,
        /// Its tracks.
        tracks: TransformTracks,
    },
}

/// The camera's pose at shutter open and close, where it moves while the
/// shutter is open (the animation system writes it).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CameraMotion {
    /// Camera to world at shutter open.
    pub open: DMat4,
    /// Camera to world at shutter close.
    pub close: DMat4,
}
