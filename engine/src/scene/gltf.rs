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

use super::yaml::{Mapping, loc, parse_document};
use super::{Loader, mesh, parse_flag, transform};
use crate::world::{EmitterSpec, Geometry, MaterialRef, MeshData, ModuleSpec, Name};
use glam::{DMat4, DVec3, DVec4, Vec2, Vec3};
use gltf::mesh::Mode;
use marked_yaml::Node;
use radiant_core::params::Location;
use std::collections::HashMap;
use std::fmt::Write as _;
use std::path::{Path, PathBuf};
use std::sync::Arc;

/// A glTF file read with its buffers.
struct Asset {
    path: PathBuf,
    document: gltf::Document,
    buffers: Vec<gltf::buffer::Data>,
}

impl Asset {
    /// Reads the glTF file at `path` and every buffer it names.
    fn open(path: &Path) -> Result<Self, String> {
        let name = path.display();
        radiant_core::input_file::reject_special_file(path)
            .map_err(|e| format!("cannot read the glTF file: {e}"))?;
        let bytes =
            std::fs::read(path).map_err(|e| format!("cannot read glTF file `{name}`: {e}"))?;
        let gltf = gltf::Gltf::from_slice(&bytes)
            .map_err(|e| format!("glTF file `{name}` is not valid glTF 2.0: {e}"))?;
        let base = path.parent().unwrap_or(Path::new("."));
        for buffer in gltf.document.buffers() {
            if let gltf::buffer::Source::Uri(uri) = buffer.source()
                && !uri.contains(':')
                && !base.join(uri).is_file()
            {
                return Err(format!(
                    "glTF file `{name}`: buffer {} is the file `{uri}`, which cannot be read \
                     (looked for `{}`)",
                    buffer.index(),
                    base.join(uri).display()
                ));
            }
        }
        let buffers = gltf::import_buffers(&gltf.document, Some(base), gltf.blob)
            .map_err(|e| format!("glTF file `{name}`: cannot load its buffers: {e}"))?;
        Ok(Self {
            path: path.to_path_buf(),
            document: gltf.document,
            buffers,
        })
    }

    /// The scene to show: the default one, else the first.
    fn scene(&self) -> Result<gltf::Scene<'_>, String> {
        self.document
            .default_scene()
            .or_else(|| self.document.scenes().next())
            .ok_or_else(|| format!("glTF file `{}` has no scene", self.path.display()))
    }

    /// Every node of the scene with its transform to the scene's space, in
    /// depth-first order.
    fn nodes(&self) -> Result<Vec<(gltf::Node<'_>, DMat4)>, String> {
        let mut out = Vec::new();
        let mut stack: Vec<_> = self
            .scene()?
            .nodes()
            .map(|n| (n, DMat4::IDENTITY))
            .collect();
        stack.reverse();
        while let Some((node, parent)) = stack.pop() {
            if out.len() > self.document.nodes().len() {
                return Err(format!(
                    "glTF file `{}`: its node hierarchy has a cycle",
                    self.path.display()
                ));
            }
            let local = node.transform().matrix().map(|c| c.map(f64::from));
            let world = parent * DMat4::from_cols_array_2d(&local);
            let children: Vec<_> = node.children().map(|c| (c, world)).collect();
            stack.extend(children.into_iter().rev());
            out.push((node, world));
        }
        Ok(out)
    }

    /// Checks that `accessor` lies within its buffer view and the view
    /// within its buffer, so that reading it cannot run past the data.
    fn check(&self, accessor: &gltf::Accessor<'_>) -> Result<(), String> {
        let name = self.path.display();
        if accessor.sparse().is_some() {
            return Err(format!(
                "glTF file `{name}`: accessor {} is sparse, which is not supported",
                accessor.index()
            ));
        }
        let Some(view) = accessor.view() else {
            return Err(format!(
                "glTF file `{name}`: accessor {} has no buffer view",
                accessor.index()
            ));
        };
        let held = self
            .buffers
            .get(view.buffer().index())
            .map_or(0, |d| d.len());
        let view_end = view.offset().saturating_add(view.length());
        if view_end > held {
            return Err(format!(
                "glTF file `{name}`: buffer view {} ends at byte {view_end}, but buffer {} holds {held} bytes",
                view.index(),
                view.buffer().index()
            ));
        }
        let size = accessor.size();
        let stride = view.stride().unwrap_or(size);
        let needed = match accessor.count() {
            0 => 0,
            n => accessor
                .offset()
                .saturating_add(stride.saturating_mul(n - 1))
                .saturating_add(size),
        };
        if needed > view.length() {
            return Err(format!(
                "glTF file `{name}`: accessor {} needs {needed} bytes of buffer view {}, which has {}",
                accessor.index(),
                view.index(),
                view.length()
            ));
        }
        Ok(())
    }

    /// The mesh of one primitive, repaired, with its tangents; flat where
    /// it has no normals or `face_normals`.
    fn primitive(
        &self,
        mesh: &gltf::Mesh<'_>,
        primitive: &gltf::Primitive<'_>,
        face_normals: bool,
    ) -> Result<MeshData, String> {
        let what = format!(
            "glTF file `{}`: mesh {} primitive {}",
            self.path.display(),
            mesh.name()
                .map_or_else(|| mesh.index().to_string(), |n| format!("`{n}`")),
            primitive.index()
        );
        for (semantic, accessor) in primitive.attributes() {
            if matches!(
                semantic,
                gltf::Semantic::Positions | gltf::Semantic::Normals | gltf::Semantic::TexCoords(0)
            ) {
                self.check(&accessor)?;
            }
        }
        if let Some(indices) = primitive.indices() {
            self.check(&indices)?;
        }
        let reader = primitive.reader(|b| self.buffers.get(b.index()).map(|d| &d.0[..]));
        let positions: Vec<Vec3> = reader
            .read_positions()
            .ok_or_else(|| format!("{what} has no POSITION attribute"))?
            .map(Vec3::from)
            .collect();
        let n = positions.len();
        let indices: Vec<u32> = match reader.read_indices() {
            Some(i) => i.into_u32().collect(),
            None => (0..n as u32).collect(),
        };
        if let Some(&bad) = indices.iter().find(|&&i| i as usize >= n) {
            return Err(format!(
                "{what} refers to vertex {bad}, but it has {n} vertices"
            ));
        }
        let triangles: Vec<[u32; 3]> = match primitive.mode() {
            Mode::Triangles => indices
                .chunks_exact(3)
                .map(|t| [t[0], t[1], t[2]])
                .collect(),
            // Every other triangle of a strip turns the other way round.
            Mode::TriangleStrip => (0..indices.len().saturating_sub(2))
                .map(|i| {
                    let t = [indices[i], indices[i + 1], indices[i + 2]];
                    if i % 2 == 0 { t } else { [t[1], t[0], t[2]] }
                })
                .collect(),
            Mode::TriangleFan => (1..indices.len().saturating_sub(1))
                .map(|i| [indices[0], indices[i], indices[i + 1]])
                .collect(),
            other => {
                return Err(format!(
                    "{what} draws {other:?}, which Radiant does not render: a mesh needs \
                     triangles (mode 4, or strips 5 and fans 6)"
                ));
            }
        };
        let mut data = MeshData {
            source: format!("{}#mesh{}", self.path.display(), mesh.index()),
            normals: reader.read_normals().map(|n| n.map(Vec3::from).collect()),
            uvs: reader
                .read_tex_coords(0)
                .map(|t| t.into_f32().map(Vec2::from).collect()),
            positions,
            triangles,
            ..MeshData::default()
        };
        for attribute in [
            data.normals.as_ref().map(Vec::len),
            data.uvs.as_ref().map(Vec::len),
        ] {
            if attribute.is_some_and(|len| len != n) {
                return Err(format!(
                    "{what}: its attributes have different numbers of vertices"
                ));
            }
        }
        mesh::repair(&mut data);
        let flat = face_normals || data.normals.is_none();
        mesh::shade(&mut data, flat);
        if data.triangles.is_empty() {
            return Err(format!("{what} has no usable triangles"));
        }
        Ok(data)
    }
}

/// A number list for generated YAML.
fn list(values: &[f64]) -> String {
    let items: Vec<String> = values.iter().map(|v| format!("{v:?}")).collect();
    format!("[{}]", items.join(", "))
}

/// A matrix as the `matrix:` rows of a transform.
fn matrix_yaml(m: DMat4) -> String {
    let rows: Vec<String> = (0..4).map(|r| list(&m.row(r).to_array())).collect();
    format!("{{matrix: [{}]}}", rows.join(", "))
}

/// A YAML string, quoted.
fn quoted(s: &str) -> String {
    format!("{:?}", s)
}

/// Parses generated YAML text; `origin` names the glTF file in errors.
fn generated(origin: &Path, text: &str) -> Result<Node, crate::error::SceneError> {
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
                    let text = light_yaml(&light, shape_transform * *to_scene);
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

/// The light of a glTF node placed by `to_world`, as Radiant YAML. glTF's
/// photometric numbers are carried over as they are: candela as W/sr of
/// `intensity`, lux as W/m² of `irradiance` (see README).
fn light_yaml(light: &gltf::khr_lights_punctual::Light<'_>, to_world: DMat4) -> String {
    use gltf::khr_lights_punctual::Kind;
    let power = f64::from(light.intensity());
    let color = light.color().map(|c| f64::from(c) * power);
    let position = to_world.transform_point3(DVec3::ZERO);
    let direction = (to_world * DVec4::new(0.0, 0.0, -1.0, 0.0))
        .truncate()
        .normalize_or(DVec3::NEG_Z);
    let mut text = String::new();
    match light.kind() {
        Kind::Point => {
            let _ = write!(
                text,
                "{{type: point, position: {}, intensity: {}}}",
                list(&position.to_array()),
                list(&color)
            );
        }
        Kind::Spot {
            inner_cone_angle,
            outer_cone_angle,
        } => {
            let _ = write!(
                text,
                "{{type: spot, position: {}, direction: {}, intensity: {}, cutoff_angle: {:?}, beam_width: {:?}}}",
                list(&position.to_array()),
                list(&direction.to_array()),
                list(&color),
                f64::from(outer_cone_angle).to_degrees(),
                f64::from(inner_cone_angle.min(outer_cone_angle)).to_degrees()
            );
        }
        Kind::Directional => {
            let _ = write!(
                text,
                "{{type: directional, direction: {}, irradiance: {}}}",
                list(&direction.to_array()),
                list(&color)
            );
        }
    }
    text
}

/// The camera mapping that a `camera: {type: gltf, filename: …}` stands
/// for: the first perspective camera among the default scene's nodes, as
/// a `perspective` camera placed by its node (glTF cameras look down −z
/// with +x to the right; Radiant's look down +z with +x to the left).
pub(super) fn camera_yaml(
    file: &Path,
    dir: &Path,
    node: &Node,
) -> Result<Node, crate::error::SceneError> {
    use crate::error::SceneError;
    let mut map = Mapping::new(file, node, "camera")?;
    map.string("type")?;
    let filename_node = map.require("filename")?;
    let at = loc(filename_node.span());
    let located = |message: String| SceneError::new(file, at, message);
    map.finish(&["type", "filename"])?;
    let filename = filename_node
        .as_scalar()
        .map(|s| s.as_str().to_string())
        .ok_or_else(|| located("`filename` must be a path to a glTF file".into()))?;
    let asset = Asset::open(&dir.join(&filename)).map_err(located)?;
    let nodes = asset.nodes().map_err(located)?;
    let (camera, to_world) = nodes
        .iter()
        .find_map(|(n, m)| n.camera().map(|c| (c, *m)))
        .ok_or_else(|| {
            located(format!(
                "glTF file `{}` has no camera in its scene",
                asset.path.display()
            ))
        })?;
    let gltf::camera::Projection::Perspective(p) = camera.projection() else {
        return Err(located(format!(
            "glTF file `{}`: camera {} is orthographic; Radiant imports perspective glTF cameras",
            asset.path.display(),
            camera.index()
        )));
    };
    let flip = DMat4::from_scale(DVec3::new(-1.0, 1.0, -1.0));
    let text = format!(
        "{{type: perspective, fov: {:?}, fov_axis: y, transform: {}}}",
        f64::from(p.yfov()).to_degrees(),
        matrix_yaml(to_world * flip)
    );
    generated(&asset.path, &text)
}
