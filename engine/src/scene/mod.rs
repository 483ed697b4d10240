//! Loading YAML scenes (and the meshes they reference) into the [`world`](crate::world).
//!
//! A scene file is a mapping with these keys (all optional but `camera`):
//!
//! ```yaml
//! integrator: {type: path, max_depth: 8, rr_depth: 5, light_selection: spatial}
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

pub mod docs;
mod gltf;
mod instances;
mod keyframes;
pub mod line_limit;
pub mod media;
pub mod mesh;
pub mod normals;
pub mod obj;
pub mod ply;
pub mod tangents;
pub mod transform;
mod yaml;

pub use crate::error::SceneError;
pub use crate::integrators::adaptive::{Adaptive, ErrorGoal};
pub use crate::settings::{FilterSampling, LightSelection, MAX_FILM_SIZE, RenderSettings};
pub use crate::world::{Scene, Timeline};
pub use gltf::register as register_gltf_image;
pub use instances::MAX_INSTANCES;

use crate::world::{
    Animation, BaseTransform, CameraAnimation, CameraMotion, CameraPose, ClosingMesh, EmitterSpec,
    FlippedNormals, Geometry, Instances, LightSpec, MaterialRef, MeshSequence, ModuleSpec, Name,
    Pose, Track, Transform, TransformTracks,
};
use glam::{DMat4, DVec3};
use hecs::{EntityBuilder, World};
use keyframes::KeyframeReader;
use marked_yaml::Node;
use radiant_core::params::Location;
use radiant_core::{Numbers, Params};
use serde::Deserialize;
use std::collections::HashMap;
use std::path::{Path, PathBuf};
use std::sync::Arc;
use yaml::{Mapping, closest, loc, parse_node};

const TOP_KEYS: &[&str] = &[
    "integrator",
    "film",
    "sampler",
    "camera",
    "textures",
    "materials",
    "shapes",
    "lights",
    "animation",
    "media",
    "atmosphere",
];
const SHAPE_TYPES: &[&str] = &["rectangle", "cube", "sphere", "mesh", "gltf"];

/// Loads the scene file at `path`.
pub fn load(path: impl AsRef<Path>) -> Result<Scene, SceneError> {
    let path = path.as_ref();
    radiant_core::input_file::reject_special_file(path)
        .map_err(|e| SceneError::new(path, None, format!("cannot read the scene file: {e}")))?;
    let text = std::fs::read_to_string(path)
        .map_err(|e| SceneError::new(path, None, format!("cannot read the scene file: {e}")))?;
    let dir = path.parent().map(Path::to_path_buf).unwrap_or_default();
    from_str(&text, path, &dir)
}

/// What the loader keeps while it reads one scene file.
struct Loader<'f> {
    file: &'f Path,
    dir: &'f Path,
    keyframes: KeyframeReader<'f>,
    materials: Vec<(String, ModuleSpec)>,
    material_ids: HashMap<String, u32>,
    /// The scene's media and the interfaces shapes put between them.
    media: media::SceneMedia,
    /// Deforming meshes whose first frame is read once the frame range is
    /// known: (entity, pattern, where `filename` was written).
    sequences: Vec<(hecs::Entity, PendingSequence)>,
    /// Textures that glTF materials define, added to `textures:`.
    textures: Vec<(String, ModuleSpec)>,
}

/// Parses scene text; `file` names it in errors and `dir` resolves
/// relative paths.
pub fn from_str(text: &str, file: &Path, dir: &Path) -> Result<Scene, SceneError> {
    let doc = yaml::parse_document(file, text)?;
    let mut top = Mapping::new(file, &doc, "scene")?;
    let mut world = World::new();

    let (integrator_keys, integrator) = parse_integrator(file, top.get("integrator"))?;
    let (film, filter) = parse_film(file, top.get("film"))?;
    let (spp, adaptive, sampler) = parse_sampler(file, top.get("sampler"))?;
    let (fps, frames) = parse_animation(file, top.get("animation"))?;

    let mut loader = Loader {
        file,
        dir,
        keyframes: KeyframeReader::new(file, fps),
        materials: named_modules(file, top.get("materials"), "material")?,
        material_ids: HashMap::new(),
        media: media::SceneMedia::parse(file, top.get("media"), top.get("atmosphere"))?,
        sequences: Vec::new(),
        textures: Vec::new(),
    };
    loader.material_ids = loader
        .materials
        .iter()
        .enumerate()
        .map(|(i, (name, _))| (name.clone(), i as u32))
        .collect();
    for (_, spec) in &mut loader.materials {
        loader.keyframes.module_tracks(spec)?;
    }
    let mut textures = named_modules(file, top.get("textures"), "texture")?;
    for (_, spec) in &mut textures {
        loader.keyframes.module_tracks(spec)?;
    }

    let camera_node = top.require("camera")?;
    let shutter = loader.camera(&mut world, camera_node)?;

    if let Some(shapes) = top.get("shapes") {
        let seq = shapes.as_sequence().ok_or_else(|| {
            SceneError::new(
                file,
                loc(shapes.span()),
                "`shapes` must be a list (lines starting with `- `)",
            )
        })?;
        for (index, node) in seq.iter().enumerate() {
            loader.shape(&mut world, node, index)?;
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
            loader.light(&mut world, node)?;
        }
    }
    textures.append(&mut loader.textures);
    top.finish(TOP_KEYS)?;
    loader.keyframes.check_all_read(&doc)?;

    // Without a frame range, the frames span the keys (or are frame 1).
    let (start, end) = frames.unwrap_or_else(|| match loader.keyframes.key_span() {
        Some((lo, hi)) => (lo.floor() as i64, hi.ceil() as i64),
        None => (1, 1),
    });
    let timeline = Timeline {
        fps,
        start,
        end,
        shutter,
    };
    loader.read_sequences(&mut world, &timeline)?;

    let mut scene = Scene {
        file: file.to_path_buf(),
        dir: dir.to_path_buf(),
        world,
        settings: RenderSettings {
            width: film.width,
            height: film.height,
            spp,
            max_depth: integrator_keys.max_depth,
            rr_depth: integrator_keys.rr_depth,
            seed: 0,
            light_selection: integrator_keys.light_selection,
            filter_sampling: film.filter_sampling,
            output: film.encoding,
            adaptive,
        },
        integrator,
        timeline,
        frame: timeline.start,
        filter,
        sampler,
        textures,
        materials: loader.materials,
        media: loader.media,
    };
    crate::world::systems::animate(&mut scene, timeline.start)?;
    Ok(scene)
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct AnimationKeys {
    #[serde(default = "default_fps")]
    fps: f64,
    #[serde(default)]
    frames: Option<[i64; 2]>,
}

fn default_fps() -> f64 {
    24.0
}

/// The scene's `animation: {fps, frames: [first, last]}`.
fn parse_animation(
    file: &Path,
    node: Option<&Node>,
) -> Result<(f64, Option<(i64, i64)>), SceneError> {
    let Some(node) = node else {
        return Ok((default_fps(), None));
    };
    let a: AnimationKeys = parse_node(file, node)?;
    let at = |key: &str| {
        node.as_mapping()
            .and_then(|m| m.get_node(key))
            .map_or_else(|| loc(node.span()), |n| loc(n.span()))
    };
    if !(a.fps > 0.0 && a.fps.is_finite()) {
        return Err(SceneError::new(
            file,
            at("fps"),
            format!("fps must be a positive number, found {}", a.fps),
        ));
    }
    if let Some([first, last]) = a.frames
        && (last < first || (last - first) >= 1 << 30)
    {
        return Err(SceneError::new(
            file,
            at("frames"),
            format!("frames is [first, last] with first ≤ last, found [{first}, {last}]"),
        ));
    }
    Ok((a.fps, a.frames.map(|[a, b]| (a, b))))
}

impl Loader<'_> {
    /// Gives `entity` its transform: a fixed `transform`, or one animated
    /// by `animation:` tracks after it.
    fn placement(
        &mut self,
        world: &mut World,
        entity: hecs::Entity,
        transform: DMat4,
        animation: Option<&Node>,
    ) -> Result<(), SceneError> {
        let tracks = match animation {
            Some(n) => self.keyframes.transform_tracks(n)?,
            None => TransformTracks::default(),
        };
        let pose = tracks.at(0.0);
        let spawned = "the entity was just spawned";
        world
            .insert_one(entity, Transform(pose.matrix() * transform))
            .expect(spawned);
        if !tracks.is_constant() {
            world
                .insert(
                    entity,
                    (BaseTransform(transform), Animation(tracks), Pose::default()),
                )
                .expect(spawned);
        }
        Ok(())
    }

    /// Spawns the camera; returns the shutter.
    fn camera(&mut self, world: &mut World, node: &Node) -> Result<Option<(f64, f64)>, SceneError> {
        let file = self.file;
        if type_is(node, "gltf") {
            let camera = gltf::camera_yaml(file, self.dir, node)?;
            return self.camera(world, &camera);
        }
        let mut module = ModuleSpec::from_node(
            file,
            node,
            "camera",
            &["look_at", "transform", "animation", "shutter", "medium"],
        )?;
        self.keyframes.module_tracks(&mut module)?;
        let map = node.as_mapping().expect("from_node checked the mapping");
        if let Some(medium) = map.get_node("medium") {
            self.media.camera = self.media.reference(file, Some(medium))?;
        }
        let (look, transform, animation) = (
            map.get_node("look_at"),
            map.get_node("transform"),
            map.get_node("animation"),
        );
        let shutter = map
            .get_node("shutter")
            .map(|n| parse_shutter(file, n))
            .transpose()?;
        let mut entity = EntityBuilder::new();
        let animated = match (look, transform) {
            (Some(_), Some(t)) => {
                return Err(SceneError::new(
                    file,
                    loc(t.span()),
                    "give the camera either `look_at` or `transform`, not both",
                ));
            }
            (Some(l), None) => {
                if let Some(a) = animation {
                    return Err(SceneError::new(
                        file,
                        loc(a.span()),
                        "a camera with `look_at` moves by keyframes on its points; `animation:` \
                         tracks go with a `transform`",
                    ));
                }
                self.look_at(l)?
            }
            (None, t) => {
                let base = match t {
                    Some(t) => transform::parse_transform(file, t)?,
                    None => DMat4::IDENTITY,
                };
                let tracks = match animation {
                    Some(a) => self.keyframes.transform_tracks(a)?,
                    None => TransformTracks::default(),
                };
                CameraAnimation::Tracks { base, tracks }
            }
        };
        let to_world = match &animated {
            CameraAnimation::Tracks { base, tracks } => tracks.at(0.0).matrix() * *base,
            CameraAnimation::LookAt { origin, target, up } => {
                crate::world::systems::look_at(origin.at(0.0), target.at(0.0), up.at(0.0))
                    .unwrap_or(DMat4::IDENTITY)
            }
        };
        let still = match &animated {
            CameraAnimation::Tracks { tracks, .. } => tracks.is_constant(),
            CameraAnimation::LookAt { origin, target, up } => {
                origin.is_constant() && target.is_constant() && up.is_constant()
            }
        };
        entity.add(CameraPose { to_world, module });
        if !still {
            entity.add_bundle((
                animated,
                CameraMotion {
                    open: to_world,
                    close: to_world,
                },
            ));
        }
        world.spawn(entity.build());
        Ok(shutter)
    }

    /// A camera's `look_at`, whose points may have keyframes.
    fn look_at(&mut self, node: &Node) -> Result<CameraAnimation, SceneError> {
        let file = self.file;
        let mut map = Mapping::new(file, node, "look_at")?;
        let (origin, target) = (map.require("origin")?, map.require("target")?);
        let up = map.get("up");
        map.finish(&["origin", "target", "up"])?;
        let reader = |key: &'static str, n: &Node, kf: &mut KeyframeReader<'_>| {
            let mut point = |v: &Node| {
                keyframes::point(file, v).map_err(|mut e| {
                    e.message = format!("look_at `{key}`: {}", e.message);
                    e
                })
            };
            kf.value_or_track(n, &mut point)
        };
        let origin = reader("origin", origin, &mut self.keyframes)?;
        let target = reader("target", target, &mut self.keyframes)?;
        let up = match up {
            Some(n) => reader("up", n, &mut self.keyframes)?,
            None => Track::constant(DVec3::Y),
        };
        // Every key must give a pose; in between, the system keeps the
        // last good one.
        let times = origin
            .keys()
            .iter()
            .chain(target.keys())
            .chain(up.keys())
            .map(|k| k.time);
        for t in times {
            if crate::world::systems::look_at(origin.at(t), target.at(t), up.at(t)).is_none() {
                return Err(SceneError::new(
                    file,
                    loc(node.span()),
                    format!(
                        "look_at needs a target different from the origin and an `up` not parallel to the view direction (at time {t} s)"
                    ),
                ));
            }
        }
        Ok(CameraAnimation::LookAt { origin, target, up })
    }

    /// Spawns a light of `lights:`.
    fn light(&mut self, world: &mut World, node: &Node) -> Result<(), SceneError> {
        let file = self.file;
        let mut spec = ModuleSpec::from_node(file, node, "light", &["transform", "animation"])?;
        self.keyframes.module_tracks(&mut spec)?;
        let map = node.as_mapping().expect("from_node checked the mapping");
        let transform = match map.get_node("transform") {
            Some(t) => transform::parse_transform(file, t)?,
            None => DMat4::IDENTITY,
        };
        let entity = world.spawn((LightSpec(spec),));
        self.placement(world, entity, transform, map.get_node("animation"))
    }

    /// Spawns shape `index` of `shapes:`.
    fn shape(&mut self, world: &mut World, node: &Node, index: usize) -> Result<(), SceneError> {
        if type_is(node, "gltf") {
            return self.gltf_shape(world, node, index);
        }
        let file = self.file;
        let shape = parse_shape(self, node, index)?;
        // Spawned and given its components in this order, so that the
        // world iterates shapes as it always has (hecs groups entities by
        // their set of components, in the order the sets first appear).
        let entity = world.spawn((
            shape.name,
            Transform(shape.transform),
            shape.geometry,
            shape.material,
        ));
        let spawned = "the entity was just spawned";
        let map = node.as_mapping().expect("parse_shape checked the mapping");
        if shape.flip_normals {
            world.insert_one(entity, FlippedNormals).expect(spawned);
        }
        let emitter_node = map.get_node("emitter");
        if let Some(mut emitter) = shape.emitter {
            self.keyframes.module_tracks(&mut emitter)?;
            world
                .insert_one(entity, EmitterSpec(emitter))
                .expect(spawned);
        }
        self.placement(world, entity, shape.transform, map.get_node("animation"))?;
        if let Some(n) = map.get_node("instances") {
            if let Some(e) = emitter_node {
                return Err(SceneError::new(
                    file,
                    loc(e.span()),
                    "an instanced shape cannot carry an `emitter`: give each glowing copy a shape of its own",
                ));
            }
            let list = instances::parse_instances(file, n, &mut |m| {
                parse_material_ref(self, Some(m), "an instance")
            })?;
            if shape.sphere && list.iter().any(|i| !is_similarity(i.transform)) {
                return Err(SceneError::new(
                    file,
                    loc(n.span()),
                    "a sphere's instances may only rotate, translate and scale uniformly",
                ));
            }
            world
                .insert_one(entity, Instances(Arc::from(list)))
                .expect(spawned);
        }
        if let Some(pending) = shape.sequence {
            self.sequences.push((entity, pending));
        }
        Ok(())
    }

    /// Reads the first frame of every deforming mesh.
    fn read_sequences(&mut self, world: &mut World, timeline: &Timeline) -> Result<(), SceneError> {
        for (entity, pending) in self.sequences.drain(..) {
            let PendingSequence {
                pattern,
                location,
                options,
            } = pending;
            let path = crate::world::systems::sequence_path(&pattern, timeline.start);
            let first = mesh::load_frame(&path, options)
                .map_err(|m| SceneError::new(self.file, location, m))?;
            let first = Arc::new(first);
            let sequence = MeshSequence {
                pattern,
                location,
                options,
                topology: first.clone(),
            };
            world
                .insert(
                    entity,
                    (sequence, Geometry::Mesh(first.clone()), ClosingMesh(first)),
                )
                .expect("the shape was spawned");
        }
        Ok(())
    }
}

/// A camera's `shutter: [open, close]`, in frames after the frame's time.
fn parse_shutter(file: &Path, node: &Node) -> Result<(f64, f64), SceneError> {
    let [open, close] = parse_node::<Numbers<2>>(file, node)?.0;
    if !(open < close && (close - open) <= 1e6) {
        return Err(SceneError::new(
            file,
            loc(node.span()),
            format!(
                "shutter is [open, close] in frames after the frame's time, with open < close (e.g. [0, 0.5], or [-0.25, 0.25] centred); found [{open}, {close}]"
            ),
        ));
    }
    Ok((open, close))
}

/// The integrator keys every integrator shares, read by the loader (the
/// integrator module parses the rest).
pub(crate) const INTEGRATOR_KEYS: &[&str] = &["max_depth", "rr_depth", "light_selection"];

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

/// The scene's `integrator:`: the keys every integrator shares, and the
/// module (its type is checked against the registry at extract).
fn parse_integrator(
    file: &Path,
    node: Option<&marked_yaml::Node>,
) -> Result<(IntegratorParams, ModuleSpec), SceneError> {
    let Some(node) = node else {
        let default = crate::integrators::module::DEFAULT;
        return Ok((
            IntegratorParams {
                max_depth: -1,
                rr_depth: 5,
                light_selection: LightSelection::default(),
            },
            default_module(default),
        ));
    };
    let spec = ModuleSpec::from_node(file, node, "integrator", INTEGRATOR_KEYS)?;
    let mut keys = marked_yaml::types::MarkedMappingNode::new_empty(*node.span());
    for (k, v) in node.as_mapping().into_iter().flat_map(|m| m.iter()) {
        if INTEGRATOR_KEYS.contains(&k.as_str()) {
            keys.insert(k.clone(), v.clone());
        }
    }
    let p: IntegratorParams = parse_node(file, &marked_yaml::Node::Mapping(keys))?;
    if p.max_depth < -1 {
        return Err(SceneError::new(
            file,
            spec.params.location_of("max_depth").or_else(|| {
                node.as_mapping()
                    .and_then(|m| m.get_node("max_depth"))
                    .and_then(|n| loc(n.span()))
            }),
            format!(
                "max_depth must be -1 (unlimited) or at least 0, found {}",
                p.max_depth
            ),
        ));
    }
    Ok((p, spec))
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
    #[serde(default)]
    tonemap: TonemapKeys,
    #[serde(default)]
    bit_depth: crate::film::encoding::BitDepth,
    #[serde(default)]
    exr: crate::film::encoding::ExrSamples,
    #[serde(default = "default_jpeg_quality")]
    jpeg_quality: u8,
    #[serde(default)]
    alpha: bool,
    /// The keys above as the encoder takes them (checked after parsing).
    #[serde(skip)]
    encoding: crate::film::encoding::Encoding,
}

/// `film: {tonemap: {type: clamp | reinhard | aces | agx, exposure: EV}}`.
#[derive(Deserialize, Default)]
#[serde(deny_unknown_fields)]
struct TonemapKeys {
    #[serde(rename = "type", default)]
    curve: crate::film::tonemap::Curve,
    #[serde(default)]
    exposure: f32,
}

fn default_jpeg_quality() -> u8 {
    crate::film::encoding::DEFAULT_JPEG_QUALITY
}

/// The film's output encoding from its keys; `node` is the film mapping,
/// for the location of a bad value.
fn film_encoding(
    file: &Path,
    node: &marked_yaml::Node,
    p: &FilmParams,
) -> Result<crate::film::encoding::Encoding, SceneError> {
    let at = |keys: &[&str]| {
        let mut n = Some(node);
        for key in keys {
            n = n.and_then(|n| n.as_mapping()).and_then(|m| m.get_node(key));
        }
        loc(n.unwrap_or(node).span())
    };
    let tonemap = crate::film::tonemap::Tonemap::new(p.tonemap.curve, p.tonemap.exposure)
        .map_err(|e| SceneError::new(file, at(&["tonemap", "exposure"]), e.to_string()))?;
    if !(1..=100).contains(&p.jpeg_quality) {
        return Err(SceneError::new(
            file,
            at(&["jpeg_quality"]),
            format!(
                "film jpeg_quality must be between 1 and 100, found {}",
                p.jpeg_quality
            ),
        ));
    }
    Ok(crate::film::encoding::Encoding {
        tonemap,
        bit_depth: p.bit_depth,
        exr: p.exr,
        jpeg_quality: p.jpeg_quality,
        alpha: p.alpha,
        // Parsed apart, with each name's location (`parse_aovs`).
        aovs: Default::default(),
    })
}

/// `film: {aovs: [albedo, normal]}` (or the `--aov` flag's comma list as
/// one string): each name checked where it is written.
fn parse_aovs(
    file: &Path,
    node: Option<&marked_yaml::Node>,
) -> Result<crate::film::aov::AovSet, SceneError> {
    use crate::film::aov::{Aov, parse_list};
    let Some(node) = node else {
        return Ok(Default::default());
    };
    let items: Vec<&marked_yaml::Node> = match node {
        marked_yaml::Node::Sequence(s) => s.iter().collect(),
        _ => vec![node],
    };
    let mut set = Vec::new();
    for item in items {
        let located = |message: String| SceneError::new(file, loc(item.span()), message);
        let text = item.as_scalar().ok_or_else(|| {
            located(format!(
                "film aovs must be a list of output variable names, such as [albedo, normal]; \
                 the names are {}",
                Aov::ALL.map(Aov::name).join(", ")
            ))
        })?;
        set.extend(parse_list(text.as_str()).map_err(|e| located(format!("film aovs: {e}")))?);
    }
    Ok(set.into_iter().collect())
}

fn default_width() -> u32 {
    768
}

fn default_height() -> u32 {
    576
}

/// A module of type `type_name` with no parameters (its defaults).
pub(crate) fn default_module(type_name: &str) -> ModuleSpec {
    ModuleSpec::new(
        type_name.to_string(),
        None,
        Params::new(marked_yaml::Node::Mapping(
            marked_yaml::types::MarkedMappingNode::new_empty(marked_yaml::Span::new_blank()),
        )),
    )
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
                tonemap: TonemapKeys::default(),
                bit_depth: Default::default(),
                exr: Default::default(),
                jpeg_quality: default_jpeg_quality(),
                alpha: false,
                encoding: Default::default(),
            },
            default_module("gaussian"),
        ));
    };
    let mut map = Mapping::new(file, node, "film")?;
    let filter = match map.get("filter") {
        Some(f) => ModuleSpec::from_node(file, f, "filter", &[])?,
        None => default_module("gaussian"),
    };
    let width = map.get("width");
    let height = map.get("height");
    // Parsed with the other plain keys below.
    map.get("filter_sampling");
    for key in ["tonemap", "bit_depth", "exr", "jpeg_quality", "alpha"] {
        map.get(key);
    }
    let aovs = map.get("aovs");
    map.finish(&[
        "width",
        "height",
        "filter",
        "filter_sampling",
        "tonemap",
        "bit_depth",
        "exr",
        "jpeg_quality",
        "alpha",
        "aovs",
    ])?;
    let mut rest = marked_yaml::types::MarkedMappingNode::new_empty(*node.span());
    for (key, value) in node.as_mapping().into_iter().flat_map(|m| m.iter()) {
        if !["filter", "aovs"].contains(&key.as_str()) {
            rest.insert(key.clone(), value.clone());
        }
    }
    let mut p: FilmParams = parse_node(file, &marked_yaml::Node::Mapping(rest))?;
    p.encoding = film_encoding(file, node, &p)?;
    p.encoding.aovs = parse_aovs(file, aovs)?;
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

/// The sampler of a scene without a `sampler` block: Owen-scrambled Sobol
/// points cost about what independent numbers cost (3 % more instructions
/// a sample on `scenes/bench/spot-point.yaml`) and cut the error at equal
/// samples 1.04–4.6× on the speed suite's scenes
/// (`engine/benches/SUITE.md`).
pub(crate) const DEFAULT_SAMPLER: &str = "sobol";

fn default_spp() -> u32 {
    64
}

fn parse_sampler(
    file: &Path,
    node: Option<&marked_yaml::Node>,
) -> Result<(u32, Option<Adaptive>, ModuleSpec), SceneError> {
    let Some(node) = node else {
        return Ok((default_spp(), None, default_module(DEFAULT_SAMPLER)));
    };
    let spec = ModuleSpec::from_node(file, node, "sampler", &["spp", "adaptive"])?;
    let adaptive = parse_adaptive(file, node)?;
    let mut keys = marked_yaml::types::MarkedMappingNode::new_empty(*node.span());
    let spp = node
        .as_mapping()
        .and_then(|m| m.iter().find(|(k, _)| k.as_str() == "spp"));
    if let Some((k, v)) = spp {
        // A count of samples: zero or a negative number is named as such,
        // not left to the integer parser ("invalid digit found in string").
        let value = v
            .as_scalar()
            .and_then(|s| s.as_str().trim().parse::<f64>().ok());
        if value.is_some_and(|n| n < 1.0) {
            return Err(SceneError::new(
                file,
                loc(v.span()),
                format!(
                    "spp must be a positive integer (samples per pixel, 1 or more), found {}",
                    v.as_scalar().map_or("", |s| s.as_str())
                ),
            ));
        }
        keys.insert(k.clone(), v.clone());
    }
    let p: SamplerKeys = parse_node(file, &marked_yaml::Node::Mapping(keys))?;
    Ok((p.spp, adaptive, spec))
}

/// The sampler's `adaptive: {error, threshold, confidence, batch, min_spp,
/// max_spp}` (or `adaptive: true` for the defaults), if given.
fn parse_adaptive(file: &Path, sampler: &Node) -> Result<Option<Adaptive>, SceneError> {
    let Some(node) = sampler.as_mapping().and_then(|m| m.get_node("adaptive")) else {
        return Ok(None);
    };
    if let Some(on) = node
        .as_scalar()
        .and_then(|s| s.as_str().parse::<bool>().ok())
    {
        return Ok(on.then(Adaptive::default));
    }
    let a: Adaptive = parse_node(file, node)?;
    if a.error == ErrorGoal::Mse {
        // The relative rule's keys mean nothing to the budget split.
        for key in ["threshold", "confidence", "batch"] {
            if let Some(at) = node.as_mapping().and_then(|m| m.get_node(key)) {
                return Err(SceneError::new(
                    file,
                    loc(at.span()),
                    format!(
                        "`{key}` belongs to the relative rule; with `error: mse` adaptive \
                         sampling spends `spp` samples per pixel on average where they lower \
                         the mean squared error most (allowed: error, min_spp, max_spp)"
                    ),
                ));
            }
        }
    }
    a.check().map_err(|(key, message)| {
        let at = node
            .as_mapping()
            .and_then(|m| m.get_node(key))
            .unwrap_or(node);
        SceneError::new(file, loc(at.span()), message)
    })?;
    Ok(Some(a))
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
                ModuleSpec::from_node(file, def, what, &[])?,
            ))
        })
        .collect()
}

struct ShapeDef {
    name: Name,
    transform: DMat4,
    geometry: Geometry,
    material: MaterialRef,
    emitter: Option<ModuleSpec>,
    flip_normals: bool,
    /// Whether the shape is a sphere.
    sphere: bool,
    /// For a deforming mesh: its frames, to read once the frame range is
    /// known.
    sequence: Option<PendingSequence>,
}

/// A deforming mesh whose first frame is read once the frame range is
/// known.
struct PendingSequence {
    /// The file name pattern, resolved against the scene's folder.
    pattern: PathBuf,
    /// Where `filename` was written.
    location: Option<Location>,
    /// How each frame's file is read.
    options: mesh::MeshOptions,
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

fn parse_shape(loader: &mut Loader<'_>, node: &Node, index: usize) -> Result<ShapeDef, SceneError> {
    let (file, dir) = (loader.file, loader.dir);
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
        .map(|e| ModuleSpec::from_node(file, e, "emitter", &[]))
        .transpose()?;
    let material = parse_material_ref(loader, map.get("material"), &name)?;
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
    // Read by the loader itself.
    map.get("animation");
    map.get("instances");

    let mut sequence = None;
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
            let s: SphereKeys = parse_node(file, &Node::Mapping(keys))?;
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
                        "`filename` must be a path to an OBJ or PLY file",
                    ));
                }
            };
            let options = mesh::MeshOptions {
                flip_tex_coords: parse_flag(file, map.get("flip_tex_coords"), "flip_tex_coords")?,
                face_normals: parse_flag(file, map.get("face_normals"), "face_normals")?
                    .unwrap_or(false),
            };
            const MESH_KEYS: &[&str] = &["filename", "flip_tex_coords", "face_normals"];
            if filename.contains('#') {
                // A deforming mesh: its frames are read once the frame
                // range is known; until then, an empty mesh.
                sequence = Some(PendingSequence {
                    pattern: dir.join(&filename),
                    location: file_loc,
                    options,
                });
                (Geometry::Mesh(Arc::default()), MESH_KEYS)
            } else {
                let mesh = mesh::load(&dir.join(&filename), options)
                    .map_err(|msg| SceneError::new(file, file_loc, msg))?;
                (Geometry::Mesh(Arc::new(mesh)), MESH_KEYS)
            }
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
        "animation",
        "instances",
        "interior",
        "exterior",
    ];
    keys.extend_from_slice(allowed);
    // Read by the media (`media.rs`) once the geometry is known.
    let _ = (map.get("interior"), map.get("exterior"));
    map.finish(&keys)?;
    let sphere = matches!(geometry, Geometry::Sphere);
    if let (true, true, Some(node)) = (sphere, flip_normals, flip_node) {
        return Err(SceneError::new(
            file,
            loc(node.span()),
            "`flip_normals` is not supported on spheres; use a cube or a mesh for an inward-facing enclosure",
        ));
    }
    if sphere && !is_similarity(transform) {
        return Err(SceneError::new(
            file,
            type_loc,
            "a sphere's transform may only rotate, translate and scale uniformly",
        ));
    }
    let material = match loader.media.interface(file, node, &geometry)? {
        Some(interface) => loader.bound_medium(material, interface, flip_normals, &name),
        None => material,
    };
    Ok(ShapeDef {
        name: Name(name),
        transform,
        geometry,
        material,
        emitter,
        flip_normals,
        sphere,
        sequence,
    })
}

/// Whether `node` is a mapping whose `type` is `type_name`.
fn type_is(node: &Node, type_name: &str) -> bool {
    node.as_mapping()
        .and_then(|m| m.get_scalar("type"))
        .is_some_and(|t| t.as_str() == type_name)
}

/// A `true`/`false` value of the key `key`, where it is given.
fn parse_flag(file: &Path, node: Option<&Node>, key: &str) -> Result<Option<bool>, SceneError> {
    node.map(|n| {
        n.as_scalar().and_then(|s| s.as_bool()).ok_or_else(|| {
            SceneError::new(
                file,
                loc(n.span()),
                format!("`{key}` must be true or false"),
            )
        })
    })
    .transpose()
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
    loader: &mut Loader<'_>,
    node: Option<&Node>,
    shape_name: &str,
) -> Result<MaterialRef, SceneError> {
    let file = loader.file;
    let (materials, material_ids) = (&mut loader.materials, &mut loader.material_ids);
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
            material_ids
                .get(name)
                .map(|&i| MaterialRef(i))
                .ok_or_else(|| {
                    let known = materials
                        .iter()
                        .map(|(k, _)| k.as_str())
                        .filter(|k| !k.starts_with('<'))
                        .collect();
                    yaml::undefined(file, n, ("material", "materials", "materials"), name, known)
                })
        }
        Some(n) => {
            let mut spec = ModuleSpec::from_node(file, n, "material", &[])?;
            loader.keyframes.module_tracks(&mut spec)?;
            loader
                .materials
                .push((format!("<material of {shape_name}>"), spec));
            Ok(MaterialRef(loader.materials.len() as u32 - 1))
        }
    }
}
