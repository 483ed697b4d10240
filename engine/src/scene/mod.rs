//! Loading YAML scenes (and the meshes they reference) into the [`world`](crate::world).
//!
//! A scene file is a mapping with these keys (all optional but `camera`):
//!
//! ```yaml
//! integrator: {type: path, max_depth: 8, rr_depth: 5, light_selection: power}
//! film: {width: 256, height: 256, filter: {type: gaussian, stddev: 0.5}}
//! sampler: {type: independent, spp: 64}
//! camera: {type: perspective, fov: 40, look_at: {origin: [0, 0, 4], target: [0, 0, 0], up: [0, 1, 0]}}
//! textures: {name: {type: constant, value: 0.5}}
//! materials: {white: {type: diffuse, reflectance: [0.8, 0.8, 0.8]}}
//! shapes:
//!   - {type: rectangle, material: white, transform: {scale: 2}}
//!   - {type: mesh, filename: bunny.obj, material: white}
//!   - type: sphere
//!     center: [0, 1, 0]
//!     radius: 0.25
//!     emitter: {type: area, radiance: 10}
//! lights:
//!   - {type: point, position: [0, 2, 0], intensity: 5}
//! ```
//!
//! Every error names the file, line and column, what was expected and what
//! is allowed. Relative paths are resolved against the scene file's folder.

pub mod obj;
pub mod transform;
mod yaml;

pub use crate::error::SceneError;
pub use crate::settings::{FilterSampling, LightSelection, MAX_FILM_SIZE, RenderSettings};

use crate::world::{
    CameraPose, EmitterSpec, FlippedNormals, Geometry, LightSpec, MaterialRef, ModuleSpec, Name,
    Transform,
};
use glam::{DMat4, DVec3};
use hecs::World;
use radiant_core::{Numbers, Params};
use serde::Deserialize;
use std::collections::HashMap;
use std::path::{Path, PathBuf};
use std::sync::Arc;
pub(crate) use yaml::module_spec;
use yaml::{Mapping, closest, loc, parse_node};

/// A loaded scene: the world plus the settings and module definitions that
/// are not entities.
pub struct Scene {
    /// The scene file.
    pub file: PathBuf,
    /// The folder relative paths are resolved against.
    pub dir: PathBuf,
    /// Shapes, lights and the camera.
    pub world: World,
    /// Integrator, film and sampler settings.
    pub settings: RenderSettings,
    /// The pixel filter.
    pub filter: ModuleSpec,
    /// The sampler.
    pub sampler: ModuleSpec,
    /// Named textures, in file order.
    pub textures: Vec<(String, ModuleSpec)>,
    /// Materials (shaders), indexed by [`MaterialRef`].
    pub materials: Vec<(String, ModuleSpec)>,
}

const TOP_KEYS: &[&str] = &[
    "integrator",
    "film",
    "sampler",
    "camera",
    "textures",
    "materials",
    "shapes",
    "lights",
];
const SHAPE_TYPES: &[&str] = &["rectangle", "cube", "sphere", "mesh"];
const INTEGRATORS: &[&str] = &["path"];

/// Loads the scene file at `path`.
pub fn load(path: impl AsRef<Path>) -> Result<Scene, SceneError> {
    let path = path.as_ref();
    let text = std::fs::read_to_string(path)
        .map_err(|e| SceneError::new(path, None, format!("cannot read the scene file: {e}")))?;
    let dir = path.parent().map(Path::to_path_buf).unwrap_or_default();
    from_str(&text, path, &dir)
}

/// Parses scene text; `file` names it in errors and `dir` resolves
/// relative paths.
pub fn from_str(text: &str, file: &Path, dir: &Path) -> Result<Scene, SceneError> {
    let doc = yaml::parse_document(file, text)?;
    let mut top = Mapping::new(file, &doc, "scene")?;
    let mut world = World::new();

    let (max_depth, rr_depth, light_selection) = parse_integrator(file, top.get("integrator"))?;
    let (film, filter) = parse_film(file, top.get("film"))?;
    let (spp, sampler) = parse_sampler(file, top.get("sampler"))?;

    let camera_node = top.require("camera")?;
    world.spawn((parse_camera(file, camera_node)?,));

    let textures = named_modules(file, top.get("textures"), "texture")?;
    let mut materials = named_modules(file, top.get("materials"), "material")?;
    let mut material_ids: HashMap<String, u32> = materials
        .iter()
        .enumerate()
        .map(|(i, (name, _))| (name.clone(), i as u32))
        .collect();

    if let Some(shapes) = top.get("shapes") {
        let seq = shapes.as_sequence().ok_or_else(|| {
            SceneError::new(
                file,
                loc(shapes.span()),
                "`shapes` must be a list (lines starting with `- `)",
            )
        })?;
        for (index, node) in seq.iter().enumerate() {
            let shape = parse_shape(file, dir, node, index, &mut materials, &mut material_ids)?;
            let entity = world.spawn((
                shape.name,
                Transform(shape.transform),
                shape.geometry,
                shape.material,
            ));
            if shape.flip_normals {
                world
                    .insert_one(entity, FlippedNormals)
                    .expect("entity was just spawned");
            }
            if let Some(emitter) = shape.emitter {
                world
                    .insert_one(entity, EmitterSpec(emitter))
                    .expect("entity was just spawned");
            }
        }
    }

    if let Some(lights) = top.get("lights") {
        let seq = lights.as_sequence().ok_or_else(|| {
            SceneError::new(
                file,
                loc(lights.span()),
                "`lights` must be a list (lines starting with `- `)",
            )
        })?;
        for node in seq.iter() {
            let spec = LightSpec(module_spec(file, node, "light", &["transform"])?);
            let transform = match node.as_mapping().and_then(|m| m.get_node("transform")) {
                Some(t) => transform::parse_transform(file, t)?,
                None => DMat4::IDENTITY,
            };
            world.spawn((spec, Transform(transform)));
        }
    }
    top.finish(TOP_KEYS)?;

    Ok(Scene {
        file: file.to_path_buf(),
        dir: dir.to_path_buf(),
        world,
        settings: RenderSettings {
            width: film.width,
            height: film.height,
            spp,
            max_depth,
            rr_depth,
            seed: 0,
            light_selection,
            filter_sampling: film.filter_sampling,
        },
        filter,
        sampler,
        textures,
        materials,
    })
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct IntegratorParams {
    #[serde(default = "unlimited")]
    max_depth: i32,
    #[serde(default = "five")]
    rr_depth: u32,
    #[serde(default)]
    light_selection: LightSelection,
}

fn unlimited() -> i32 {
    -1
}

fn five() -> u32 {
    5
}

fn parse_integrator(
    file: &Path,
    node: Option<&marked_yaml::Node>,
) -> Result<(i32, u32, LightSelection), SceneError> {
    let Some(node) = node else {
        return Ok((-1, 5, LightSelection::default()));
    };
    let spec = module_spec(file, node, "integrator", &[])?;
    if !INTEGRATORS.contains(&spec.type_name.as_str()) {
        return Err(unknown_type(file, &spec, "integrator", INTEGRATORS));
    }
    let p: IntegratorParams = spec
        .params
        .parse()
        .map_err(|e| SceneError::from_param(file, e))?;
    if p.max_depth < -1 {
        return Err(SceneError::new(
            file,
            spec.params.location_of("max_depth"),
            format!(
                "max_depth must be -1 (unlimited) or at least 0, found {}",
                p.max_depth
            ),
        ));
    }
    Ok((p.max_depth, p.rr_depth, p.light_selection))
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct FilmParams {
    #[serde(default = "default_width")]
    width: u32,
    #[serde(default = "default_height")]
    height: u32,
    #[serde(default)]
    filter_sampling: FilterSampling,
}

fn default_width() -> u32 {
    768
}

fn default_height() -> u32 {
    576
}

/// A module of type `type_name` with no parameters (its defaults).
pub(crate) fn default_module(type_name: &str) -> ModuleSpec {
    ModuleSpec {
        type_name: type_name.to_string(),
        location: None,
        params: Params::new(marked_yaml::Node::Mapping(
            marked_yaml::types::MarkedMappingNode::new_empty(marked_yaml::Span::new_blank()),
        )),
    }
}

fn parse_film(
    file: &Path,
    node: Option<&marked_yaml::Node>,
) -> Result<(FilmParams, ModuleSpec), SceneError> {
    let Some(node) = node else {
        return Ok((
            FilmParams {
                width: default_width(),
                height: default_height(),
                filter_sampling: FilterSampling::default(),
            },
            default_module("gaussian"),
        ));
    };
    let mut map = Mapping::new(file, node, "film")?;
    let filter = match map.get("filter") {
        Some(f) => module_spec(file, f, "filter", &[])?,
        None => default_module("gaussian"),
    };
    let width = map.get("width");
    let height = map.get("height");
    // Parsed with the other plain keys below.
    map.get("filter_sampling");
    map.finish(&["width", "height", "filter", "filter_sampling"])?;
    let mut rest = marked_yaml::types::MarkedMappingNode::new_empty(*node.span());
    for (key, value) in node.as_mapping().into_iter().flat_map(|m| m.iter()) {
        if key.as_str() != "filter" {
            rest.insert(key.clone(), value.clone());
        }
    }
    let p: FilmParams = parse_node(file, &marked_yaml::Node::Mapping(rest))?;
    for (value, key, n) in [(p.width, "width", width), (p.height, "height", height)] {
        if !(1..=MAX_FILM_SIZE).contains(&value) {
            return Err(SceneError::new(
                file,
                n.and_then(|n| loc(n.span())),
                format!("film {key} must be between 1 and {MAX_FILM_SIZE} pixels, found {value}"),
            ));
        }
    }
    Ok((p, filter))
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct SamplerKeys {
    #[serde(default = "default_spp")]
    spp: u32,
}

fn default_spp() -> u32 {
    64
}

fn parse_sampler(
    file: &Path,
    node: Option<&marked_yaml::Node>,
) -> Result<(u32, ModuleSpec), SceneError> {
    let Some(node) = node else {
        return Ok((default_spp(), default_module("independent")));
    };
    let spec = module_spec(file, node, "sampler", &["spp"])?;
    let mut keys = marked_yaml::types::MarkedMappingNode::new_empty(*node.span());
    if let Some((k, v)) = node
        .as_mapping()
        .and_then(|m| m.iter().find(|(k, _)| k.as_str() == "spp"))
    {
        keys.insert(k.clone(), v.clone());
    }
    let p: SamplerKeys = parse_node(file, &marked_yaml::Node::Mapping(keys))?;
    if p.spp == 0 {
        return Err(SceneError::new(
            file,
            loc(node.span()),
            "spp must be at least 1",
        ));
    }
    Ok((p.spp, spec))
}

fn parse_camera(file: &Path, node: &marked_yaml::Node) -> Result<CameraPose, SceneError> {
    let module = module_spec(file, node, "camera", &["look_at", "transform"])?;
    let map = node.as_mapping().expect("module_spec checked the mapping");
    let to_world = match (map.get_node("look_at"), map.get_node("transform")) {
        (Some(_), Some(t)) => {
            return Err(SceneError::new(
                file,
                loc(t.span()),
                "give the camera either `look_at` or `transform`, not both",
            ));
        }
        (Some(l), None) => transform::parse_look_at(file, l)?,
        (None, Some(t)) => transform::parse_transform(file, t)?,
        (None, None) => DMat4::IDENTITY,
    };
    Ok(CameraPose { to_world, module })
}

fn named_modules(
    file: &Path,
    node: Option<&marked_yaml::Node>,
    what: &str,
) -> Result<Vec<(String, ModuleSpec)>, SceneError> {
    let Some(node) = node else {
        return Ok(Vec::new());
    };
    let map = node.as_mapping().ok_or_else(|| {
        SceneError::new(
            file,
            loc(node.span()),
            format!("expected a mapping from {what} names to {what} definitions"),
        )
    })?;
    map.iter()
        .map(|(name, def)| {
            Ok((
                name.as_str().to_string(),
                module_spec(file, def, what, &[])?,
            ))
        })
        .collect()
}

fn unknown_type(file: &Path, spec: &ModuleSpec, what: &str, known: &[&str]) -> SceneError {
    let hint = closest(&spec.type_name, known)
        .map(|s| format!(" (did you mean `{s}`?)"))
        .unwrap_or_default();
    SceneError::new(
        file,
        spec.location,
        format!(
            "unknown {what} type `{}`{hint}; known {what} types: {}",
            spec.type_name,
            known.join(", ")
        ),
    )
}

struct ShapeDef {
    name: Name,
    transform: DMat4,
    geometry: Geometry,
    material: MaterialRef,
    emitter: Option<ModuleSpec>,
    flip_normals: bool,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct SphereKeys {
    #[serde(default)]
    center: Numbers<3>,
    #[serde(default = "one")]
    radius: f64,
}

fn one() -> f64 {
    1.0
}

fn parse_shape(
    file: &Path,
    dir: &Path,
    node: &marked_yaml::Node,
    index: usize,
    materials: &mut Vec<(String, ModuleSpec)>,
    material_ids: &mut HashMap<String, u32>,
) -> Result<ShapeDef, SceneError> {
    let mut map = Mapping::new(file, node, "shape")?;
    let (type_name, type_loc) = map.string("type")?.ok_or_else(|| {
        SceneError::new(
            file,
            map.location(),
            format!(
                "the shape needs a `type`, one of: {}",
                SHAPE_TYPES.join(", ")
            ),
        )
    })?;
    let name = map
        .string("name")?
        .map_or_else(|| format!("shape {index}"), |(n, _)| n);
    let mut transform = match map.get("transform") {
        Some(t) => transform::parse_transform(file, t)?,
        None => DMat4::IDENTITY,
    };
    let emitter = map
        .get("emitter")
        .map(|e| module_spec(file, e, "emitter", &[]))
        .transpose()?;
    let material = parse_material_ref(file, map.get("material"), &name, materials, material_ids)?;
    let flip_node = map.get("flip_normals");
    let flip_normals = match flip_node {
        Some(node) => match node.as_scalar().and_then(|s| s.as_bool()) {
            Some(b) => b,
            None => {
                return Err(SceneError::new(
                    file,
                    loc(node.span()),
                    "`flip_normals` must be true or false",
                ));
            }
        },
        None => false,
    };

    let (geometry, allowed): (Geometry, &[&str]) = match type_name.as_str() {
        "rectangle" => (Geometry::Rectangle, &[]),
        "cube" => (Geometry::Cube, &[]),
        "sphere" => {
            let mut keys = marked_yaml::types::MarkedMappingNode::new_empty(*node.span());
            for key in ["center", "radius"] {
                if let Some(v) = map.get(key) {
                    keys.insert(key.into(), v.clone());
                }
            }
            let s: SphereKeys = parse_node(file, &marked_yaml::Node::Mapping(keys))?;
            if !(s.radius > 0.0 && s.radius.is_finite()) {
                return Err(SceneError::new(
                    file,
                    map.location(),
                    format!(
                        "a sphere's radius must be positive and finite, found {}",
                        s.radius
                    ),
                ));
            }
            transform = transform
                * DMat4::from_translation(DVec3::from(s.center))
                * DMat4::from_scale(DVec3::splat(s.radius));
            (Geometry::Sphere, &["center", "radius"])
        }
        "mesh" => {
            let filename_node = map.require("filename")?;
            let (filename, file_loc) = match filename_node.as_scalar() {
                Some(s) => (s.as_str().to_string(), loc(filename_node.span())),
                None => {
                    return Err(SceneError::new(
                        file,
                        loc(filename_node.span()),
                        "`filename` must be a path to an OBJ file",
                    ));
                }
            };
            let mesh = obj::load_obj(&dir.join(&filename))
                .map_err(|msg| SceneError::new(file, file_loc, msg))?;
            (Geometry::Mesh(Arc::new(mesh)), &["filename"])
        }
        other => {
            let hint = closest(other, SHAPE_TYPES)
                .map(|s| format!(" (did you mean `{s}`?)"))
                .unwrap_or_default();
            return Err(SceneError::new(
                file,
                type_loc,
                format!(
                    "unknown shape type `{other}`{hint}; known shape types: {}",
                    SHAPE_TYPES.join(", ")
                ),
            ));
        }
    };
    let mut keys = vec![
        "type",
        "name",
        "transform",
        "emitter",
        "material",
        "flip_normals",
    ];
    keys.extend_from_slice(allowed);
    map.finish(&keys)?;
    if let (Geometry::Sphere, true, Some(node)) = (&geometry, flip_normals, flip_node) {
        return Err(SceneError::new(
            file,
            loc(node.span()),
            "`flip_normals` is not supported on spheres; use a cube or a mesh for an inward-facing enclosure",
        ));
    }
    if matches!(geometry, Geometry::Sphere) && !is_similarity(transform) {
        return Err(SceneError::new(
            file,
            type_loc,
            "a sphere's transform may only rotate, translate and scale uniformly",
        ));
    }
    Ok(ShapeDef {
        name: Name(name),
        transform,
        geometry,
        material,
        emitter,
        flip_normals,
    })
}

fn is_similarity(m: DMat4) -> bool {
    let (x, y, z) = (
        m.x_axis.truncate(),
        m.y_axis.truncate(),
        m.z_axis.truncate(),
    );
    let (lx, ly, lz) = (x.length(), y.length(), z.length());
    let tol = 1e-6 * lx.max(ly).max(lz);
    (lx - ly).abs() < tol
        && (lx - lz).abs() < tol
        && x.dot(y).abs() < tol * lx
        && x.dot(z).abs() < tol * lx
        && y.dot(z).abs() < tol * lx
}

fn parse_material_ref(
    file: &Path,
    node: Option<&marked_yaml::Node>,
    shape_name: &str,
    materials: &mut Vec<(String, ModuleSpec)>,
    material_ids: &mut HashMap<String, u32>,
) -> Result<MaterialRef, SceneError> {
    match node {
        None => {
            // Mitsuba's default: a 50% grey diffuse surface.
            let key = "<default diffuse>".to_string();
            let id = *material_ids.entry(key.clone()).or_insert_with(|| {
                materials.push((key, default_module("diffuse")));
                materials.len() as u32 - 1
            });
            Ok(MaterialRef(id))
        }
        Some(n) if n.as_scalar().is_some() => {
            let name = n.as_scalar().expect("checked").as_str();
            material_ids.get(name).map(|&i| MaterialRef(i)).ok_or_else(|| {
                let mut known: Vec<&str> = materials
                    .iter()
                    .map(|(k, _)| k.as_str())
                    .filter(|k| !k.starts_with('<'))
                    .collect();
                known.sort_unstable();
                let hint = closest(name, &known)
                    .map(|s| format!(" (did you mean `{s}`?)"))
                    .unwrap_or_default();
                SceneError::new(
                    file,
                    loc(n.span()),
                    format!(
                        "undefined material `{name}`{hint}; materials defined under `materials:`: {}",
                        if known.is_empty() { "none".to_string() } else { known.join(", ") }
                    ),
                )
            })
        }
        Some(n) => {
            let spec = module_spec(file, n, "material", &[])?;
            materials.push((format!("<material of {shape_name}>"), spec));
            Ok(MaterialRef(materials.len() as u32 - 1))
        }
    }
}
