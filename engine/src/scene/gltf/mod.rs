//! glTF 2.0 files (`.gltf` with embedded or external buffers, and `.glb`)
//! through the `gltf` crate, expanded into the scene's own entities.
//!
//! * A shape `{type: gltf, filename: model.gltf}` walks the node hierarchy
//!   of the file's default scene and spawns one mesh shape per triangle
//!   primitive, placed by the product of its nodes' transforms (under the
//!   shape's own `transform`). Each glTF material becomes a `principled`
//!   material (base colour, metallic and roughness factors; a base-colour
//!   texture; a normal texture through `normal_map`; an emissive factor as
//!   an area emitter) unless the shape gives one `material` for all.
//!   `KHR_lights_punctual` lights become `point`, `spot` and `directional`
//!   lights (`lights: false` leaves them out).
//! * A camera `{type: gltf, filename: model.gltf}` is the first perspective
//!   camera of the default scene's nodes, as a `perspective` camera with its
//!   vertical field of view.
//!
//! glTF's v runs down an image, as Radiant's does, so texture coordinates
//! are read as they are. A primitive without normals is flat, as the glTF
//! specification requires. Everything else is a located error naming the
//! file and what is wrong: unsupported primitive modes (points, lines),
//! missing buffers or images, accessors reaching past their data.
//!
//! `asset.rs` reads and checks the file and its meshes; this module and
//! `lights.rs` and `camera.rs` write what the file describes as the YAML
//! the loader already reads, so that it goes through the same paths (and
//! checks) as a hand-written scene.

mod asset;
mod camera;
mod lights;

pub(super) use camera::camera_yaml;

use super::yaml::{Mapping, loc, parse_document};
use super::{Loader, parse_flag, transform};
use crate::world::{EmitterSpec, Geometry, MaterialRef, MeshData, ModuleSpec, Name};
use asset::Asset;
use glam::DMat4;
use marked_yaml::Node;
use radiant_core::params::Location;
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
        let mut meshes: HashMap<(usize, usize), Arc<MeshData>> = HashMap::new();
        let mut materials: HashMap<Option<usize>, (MaterialRef, Option<ModuleSpec>)> =
            HashMap::new();
        for (gnode, to_scene) in &nodes {
            let Some(gmesh) = gnode.mesh() else { continue };
            for primitive in gmesh.primitives() {
                let key = (gmesh.index(), primitive.index());
                let data = match meshes.get(&key) {
                    Some(d) => d.clone(),
                    None => {
                        let d = Arc::new(
                            asset
                                .primitive(&gmesh, &primitive, face_normals)
                                .map_err(located)?,
                        );
                        meshes.insert(key, d.clone());
                        d
                    }
                };
                let material = primitive.material();
                let (material_ref, emitter) = match override_material {
                    Some(m) => (m, None),
                    None => match materials.get(&material.index()) {
                        Some(m) => m.clone(),
                        None => {
                            let m = self.gltf_material(&asset, &material, at)?;
                            materials.insert(material.index(), m.clone());
                            m
                        }
                    },
                };
                let node_name = gnode
                    .name()
                    .map_or_else(|| gnode.index().to_string(), str::to_string);
                let placed = shape_transform * *to_scene;
                let entity = world.spawn((
                    Name(format!("{name}/{node_name}/{}", primitive.index())),
                    crate::world::Transform(placed),
                    Geometry::Mesh(data),
                    material_ref,
                ));
                if let Some(e) = emitter {
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

    /// The material (and emitter) of a glTF material: `principled` with its
    /// factors and base-colour texture, wrapped in `normal_map` where it
    /// has a normal texture.
    fn gltf_material(
        &mut self,
        asset: &Asset,
        material: &gltf::Material<'_>,
        at: Option<Location>,
    ) -> Result<(MaterialRef, Option<ModuleSpec>), crate::error::SceneError> {
        use crate::error::SceneError;
        let located = |message: String| SceneError::new(self.file, at, message);
        let pbr = material.pbr_metallic_roughness();
        let [r, g, b, _alpha] = pbr.base_color_factor().map(f64::from);
        let base_color = match pbr.base_color_texture() {
            // The factor multiplies the texture in glTF; Radiant's inputs
            // take a texture or a value, so a factor other than white is
            // left out where there is a texture (see README).
            Some(info) => self
                .gltf_texture(asset, &info.texture(), info.tex_coord(), false)
                .map_err(located)?,
            None => list(&[r, g, b]),
        };
        let mut text = format!(
            "{{type: principled, base_color: {base_color}, metallic: {:?}, roughness: {:?}}}",
            f64::from(pbr.metallic_factor()),
            f64::from(pbr.roughness_factor())
        );
        if let Some(normal) = material.normal_texture() {
            let normals = self
                .gltf_texture(asset, &normal.texture(), normal.tex_coord(), true)
                .map_err(located)?;
            text = format!("{{type: normal_map, normals: {normals}, material: {text}}}");
        }
        let node = generated(&asset.path, &text)?;
        let spec = ModuleSpec::from_node(&asset.path, &node, "material", &[])?;
        let label = material
            .name()
            .map_or_else(|| format!("{:?}", material.index()), str::to_string);
        self.materials.push((
            format!("<glTF material {label} of {}>", asset.path.display()),
            spec,
        ));
        let material_ref = MaterialRef(self.materials.len() as u32 - 1);
        let emissive = material.emissive_factor().map(f64::from);
        let emitter = if emissive.iter().any(|&e| e > 0.0) {
            let node = generated(
                &asset.path,
                &format!("{{type: area, radiance: {}}}", list(&emissive)),
            )?;
            Some(ModuleSpec::from_node(&asset.path, &node, "emitter", &[])?)
        } else {
            None
        };
        Ok((material_ref, emitter))
    }

    /// Defines an `image` texture for a glTF texture (its image an external
    /// file) and returns its name, quoted for YAML.
    fn gltf_texture(
        &mut self,
        asset: &Asset,
        texture: &gltf::Texture<'_>,
        tex_coord: u32,
        raw: bool,
    ) -> Result<String, String> {
        let name = asset.path.display();
        if tex_coord != 0 {
            return Err(format!(
                "glTF file `{name}`: texture {} reads TEXCOORD_{tex_coord}; only TEXCOORD_0 is supported",
                texture.index()
            ));
        }
        let image = texture.source();
        let uri = match image.source() {
            gltf::image::Source::Uri { uri, .. } if !uri.contains(':') => uri,
            _ => {
                return Err(format!(
                    "glTF file `{name}`: image {} is embedded (a data URI or a buffer view); \
                     Radiant reads glTF images from files beside the glTF file",
                    image.index()
                ));
            }
        };
        let base = asset.path.parent().unwrap_or(Path::new("."));
        let path = base.join(uri);
        if !path.is_file() {
            return Err(format!(
                "glTF file `{name}`: image {} is the file `{uri}`, which cannot be read (looked for `{}`)",
                image.index(),
                path.display()
            ));
        }
        let texture_name = format!(
            "<glTF image {} of {}{}>",
            image.index(),
            name,
            if raw { ", raw" } else { "" }
        );
        if !self.textures.iter().any(|(n, _)| *n == texture_name) {
            let mut text = format!(
                "{{type: image, filename: {}",
                quoted(&path.display().to_string())
            );
            if raw {
                text.push_str(", raw: true");
            }
            text.push('}');
            let node = generated(&asset.path, &text).map_err(|e| e.to_string())?;
            let spec = ModuleSpec::from_node(&asset.path, &node, "texture", &[])
                .map_err(|e| e.to_string())?;
            self.textures.push((texture_name.clone(), spec));
        }
        Ok(quoted(&texture_name))
    }
}
