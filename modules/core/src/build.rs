//! What a module sees while it is being built from its parameters.

use crate::params::{Location, ParamError, Spanned, TextureInput};
use crate::{Params, Shader, TextureId, TextureTable};
use glam::{DMat4, DVec3, Mat4, UVec2, Vec3};
use marked_yaml::Node;
use std::collections::HashMap;
use std::path::Path;

/// The geometry of the shape an emitter is attached to, in render space.
/// Primitive indices of [`EmitterHit`](crate::EmitterHit) count the
/// triangles first, then the spheres.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct EmitterShape {
    /// Triangles as vertex triples.
    pub triangles: Vec<[Vec3; 3]>,
    /// Spheres as (centre, radius).
    pub spheres: Vec<(Vec3, f32)>,
}

impl EmitterShape {
    /// Total surface area.
    pub fn area(&self) -> f32 {
        let tris: f32 = self
            .triangles
            .iter()
            .map(|[a, b, c]| 0.5 * (*b - *a).cross(*c - *a).length())
            .sum();
        let spheres: f32 = self
            .spheres
            .iter()
            .map(|(_, r)| 4.0 * std::f32::consts::PI * r * r)
            .sum();
        tris + spheres
    }
}

/// A sphere that bounds the scene's geometry, in render space.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct BoundingSphere {
    /// Centre.
    pub centre: Vec3,
    /// Radius (positive even for an empty scene).
    pub radius: f32,
}

/// Everything a module may need while it is built.
///
/// *Render space* is world space translated so that the camera's position is
/// the origin: geometry far from the world origin keeps full `f32`
/// precision near the camera.
pub struct BuildContext<'a> {
    /// Film resolution in pixels.
    pub resolution: UVec2,
    /// The camera's pose: camera space (+z forward, +y up, +x left, as in
    /// Mitsuba) to render space.
    pub camera_to_render: Mat4,
    /// World-space position of the render-space origin.
    pub render_origin: DVec3,
    /// The render's seed.
    pub seed: u64,
    /// Samples per pixel of the render.
    pub spp: u32,
    /// The shape an emitter is attached to (for lights declared on shapes).
    pub emitter_shape: Option<&'a EmitterShape>,
    /// A light's own `transform` from the scene (light space to world
    /// space); the identity when it has none and for every other module.
    /// Lights apply it to their positions, directions and map frames.
    pub to_world: DMat4,
    /// A sphere bounding all geometry in render space, for lights
    /// infinitely far away. Known only when free lights (the scene's
    /// `lights:`) are built; zero-sized before that.
    pub scene_sphere: BoundingSphere,
    /// Directory that relative paths in the scene are resolved against.
    pub scene_dir: &'a Path,
    /// The scene's texture table, to which textures are added.
    pub textures: &'a mut TextureTable,
    /// Textures defined by name under `textures:`.
    pub named_textures: &'a HashMap<String, TextureId>,
    /// Builds materials that a material refers to (for `blend`,
    /// `normal_map`, `bump`); `None` where materials cannot nest.
    pub materials: Option<&'a dyn MaterialSource>,
}

/// Builds the materials that other materials contain: a wrapper's nested
/// material or the two materials a blend mixes. The engine implements it
/// over the scene's `materials:` and the registry.
pub trait MaterialSource {
    /// Builds the material written at `node`: the name of a material
    /// defined under `materials:` or an inline mapping with a `type`.
    /// A material that contains itself is an error.
    fn build_material(
        &self,
        node: &Node,
        ctx: &mut BuildContext<'_>,
    ) -> Result<Box<dyn Shader>, ParamError>;
}

impl<'a> BuildContext<'a> {
    /// A context for building modules outside a scene (tools, tests,
    /// outside crates): an 8×8 film, the camera at the world origin looking
    /// down +z, seed 0, one sample per pixel, identity transforms, a unit
    /// scene sphere and no nested materials. Set the public fields to
    /// change any of them.
    pub fn standalone(
        scene_dir: &'a Path,
        textures: &'a mut TextureTable,
        named_textures: &'a HashMap<String, TextureId>,
    ) -> Self {
        BuildContext {
            resolution: UVec2::new(8, 8),
            camera_to_render: Mat4::IDENTITY,
            render_origin: DVec3::ZERO,
            seed: 0,
            spp: 1,
            emitter_shape: None,
            to_world: DMat4::IDENTITY,
            scene_sphere: BoundingSphere {
                centre: Vec3::ZERO,
                radius: 1.0,
            },
            scene_dir,
            textures,
            named_textures,
            materials: None,
        }
    }

    /// Converts a world-space point to render space.
    pub fn to_render(&self, world: DVec3) -> Vec3 {
        (world - self.render_origin).as_vec3()
    }

    /// Builds the nested material under `key` of `params` (the name of a
    /// material or an inline material). The module's own serde type should
    /// accept the key (e.g. as `serde::de::IgnoredAny`) so that unknown-key
    /// checking still works.
    pub fn material(&mut self, params: &Params, key: &str) -> Result<Box<dyn Shader>, ParamError> {
        let node = params
            .node()
            .as_mapping()
            .and_then(|m| m.get_node(key))
            .ok_or_else(|| ParamError {
                message: format!(
                    "missing `{key}`: expected the name of a material defined under `materials:` or an inline material such as `{{type: diffuse}}`"
                ),
                location: params.location_of(key),
            })?;
        self.material_at(node)
    }

    /// Builds the nested material written at `node` (see
    /// [`material`](Self::material)); for lists of materials.
    pub fn material_at(&mut self, node: &Node) -> Result<Box<dyn Shader>, ParamError> {
        let source = self.materials.ok_or_else(|| {
            ParamError::at(node.span(), "materials cannot be nested in this context")
        })?;
        source.build_material(node, self)
    }

    /// Resolves a colour parameter to a texture: inline values become
    /// constants, names must be defined under `textures:`.
    pub fn texture(&mut self, input: &Spanned<TextureInput>) -> Result<TextureId, ParamError> {
        match &**input {
            TextureInput::Value(v) => Ok(self.textures.add_constant(*v)),
            TextureInput::Named(name) => self.named_textures.get(name).copied().ok_or_else(|| {
                let mut known: Vec<_> = self.named_textures.keys().map(String::as_str).collect();
                known.sort_unstable();
                ParamError {
                    message: format!(
                        "undefined texture `{name}`; expected a number, an [r, g, b] list or one of the textures defined under `textures:` ({})",
                        if known.is_empty() { "none are defined".to_string() } else { known.join(", ") }
                    ),
                    location: Location::of(input.span()),
                }
            }),
        }
    }
}
