//! glTF 2.0 files (`.gltf` with embedded or external buffers, and `.glb`)
//! through the `gltf` crate, expanded into the scene's own entities.
//!
//! * A shape `{type: gltf, filename: model.gltf}` walks the node hierarchy
//!   of the file's default scene and spawns one mesh shape per triangle
//!   primitive, placed by the product of its nodes' transforms (under the
//!   shape's own `transform`). Each glTF material becomes a `principled`
//!   material (`material.rs`: base colour, metallic and roughness as
//!   factors times textures, a normal texture through `normal_map`,
//!   `KHR_texture_transform`, an emissive factor as an area emitter)
//!   unless the shape gives one `material` for all; the primitive's mesh
//!   carries the texture coordinate set its material's textures read.
//!   Embedded images become `gltf_image` textures (`image.rs`).
//!   `KHR_lights_punctual` lights become `point`, `spot` and `directional`
//!   lights (`lights: false` leaves them out).
//! * A camera `{type: gltf, filename: model.gltf}` is the first camera of
//!   the default scene's nodes, as a `perspective` or `orthographic`
//!   camera.
//!
//! glTF's v runs down an image, as Radiant's does, so texture coordinates
//! are read as they are. A primitive without normals is flat, as the glTF
//! specification requires. Everything else is a located error naming the
//! file and what is wrong: unsupported primitive modes (points, lines),
//! missing buffers or images, accessors reaching past their data.
//!
//! `asset.rs` reads and checks the file and its meshes; this module and
//! `material.rs`, `lights.rs` and `camera.rs` write what the file
//! describes as the YAML the loader already reads, so that it goes through
//! the same paths (and checks) as a hand-written scene.

mod asset;
mod camera;
mod image;
mod lights;
mod material;

pub(super) use camera::camera_yaml;
pub use image::register;

use super::yaml::{Mapping, loc, parse_document};
use super::{Loader, parse_flag, transform};
use crate::world::{EmitterSpec, Geometry, MeshData, Name};
use asset::Asset;
use glam::DMat4;
use marked_yaml::Node;
use std::collections::HashMap;
use std::path::Path;
use std::sync::Arc;

/// A number list for generated YAML.
pub(super) fn list(values: &[f64]) -> String {
    let items: Vec<String> = values.iter().map(|v| format!("{v:?}")).collect();
    format!("[{}]", items.join(", "))
}

/// A YAML string, quoted.
fn quoted(s: &str) -> String {
    format!("{:?}", s)
}

/// Parses generated YAML text; `origin` names the glTF file in errors.
pub(super) fn generated(origin: &Path, text: &str) -> Result<Node, crate::error::SceneError> {
    parse_document(origin, text)
}

impl Loader<'_> {
    /// Spawns the shapes (and, unless `lights: false`, the lights) of a
    /// `type: gltf` shape.
    pub(super) fn gltf_shape(
        &mut self,
        world: &mut hecs::World,
        node: &Node,
        index: usize,
    ) -> Result<(), crate::error::SceneError> {
        use crate::error::SceneError;
        let (file, dir) = (self.file, self.dir);
        let mut map = Mapping::new(file, node, "shape")?;
        map.string("type")?;
        let name = map
            .string("name")?
            .map_or_else(|| format!("shape {index}"), |(n, _)| n);
        let filename_node = map.require("filename")?;
        let at = loc(filename_node.span());
        let located = |message: String| SceneError::new(file, at, message);
        let filename = filename_node
            .as_scalar()
            .map(|s| s.as_str().to_string())
            .ok_or_else(|| located("`filename` must be a path to a glTF file".into()))?;
        let shape_transform = match map.get("transform") {
            Some(t) => transform::parse_transform(file, t)?,
            None => DMat4::IDENTITY,
        };
        let face_normals =
            parse_flag(file, map.get("face_normals"), "face_normals")?.unwrap_or(false);
        let lights = parse_flag(file, map.get("lights"), "lights")?.unwrap_or(true);
        let material_node = map.get("material");
        map.finish(&[
            "type",
            "name",
            "filename",
            "transform",
            "material",
            "face_normals",
            "lights",
        ])?;
        let override_material = material_node
            .map(|m| super::parse_material_ref(self, Some(m), &name))
            .transpose()?;

        let asset = Asset::open(&dir.join(&filename)).map_err(located)?;
        let nodes = asset.nodes().map_err(located)?;
        let mut meshes: HashMap<(usize, usize, u32), Arc<MeshData>> = HashMap::new();
        let mut materials: HashMap<Option<usize>, material::Material> = HashMap::new();
        for (gnode, to_scene) in &nodes {
            let Some(gmesh) = gnode.mesh() else { continue };
            for primitive in gmesh.primitives() {
                let material = primitive.material();
                let material = match override_material {
                    Some(m) => material::Material {
                        material: m,
                        emitter: None,
                        tex_coord: 0,
                    },
                    None => match materials.get(&material.index()) {
                        Some(m) => m.clone(),
                        None => {
                            let m = self.gltf_material(&asset, &material, at)?;
                            materials.insert(material.index(), m.clone());
                            m
                        }
                    },
                };
                let key = (gmesh.index(), primitive.index(), material.tex_coord);
                let data = match meshes.get(&key) {
                    Some(d) => d.clone(),
                    None => {
                        let d = Arc::new(
                            asset
                                .primitive(&gmesh, &primitive, material.tex_coord, face_normals)
                                .map_err(located)?,
                        );
                        meshes.insert(key, d.clone());
                        d
                    }
                };
                let node_name = gnode
                    .name()
                    .map_or_else(|| gnode.index().to_string(), str::to_string);
                let placed = shape_transform * *to_scene;
                let entity = world.spawn((
                    Name(format!("{name}/{node_name}/{}", primitive.index())),
                    crate::world::Transform(placed),
                    Geometry::Mesh(data),
                    material.material,
                ));
                if let Some(e) = material.emitter {
                    world
                        .insert_one(entity, EmitterSpec(e))
                        .expect("the entity was just spawned");
                }
                self.placement(world, entity, placed, None)?;
            }
        }
        if lights {
            for (gnode, to_scene) in &nodes {
                if let Some(light) = gnode.light() {
                    let text = lights::light_yaml(&light, shape_transform * *to_scene);
                    let light_node = generated(&asset.path, &text)?;
                    self.light(world, &light_node)?;
                }
            }
        }
        Ok(())
    }
}
