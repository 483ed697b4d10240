//! What a module sees while it is being built from its parameters.

use crate::params::{Location, ParamError, Spanned, TextureInput};
use crate::{TextureId, TextureTable};
use glam::{DMat4, DVec3, Mat4, UVec2, Vec3};
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
}

impl BuildContext<'_> {
    /// Converts a world-space point to render space.
    pub fn to_render(&self, world: DVec3) -> Vec3 {
        (world - self.render_origin).as_vec3()
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
