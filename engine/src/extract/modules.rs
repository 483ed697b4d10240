//! The frame's module instances, built through the registry and rebuilt
//! only when what they were built from changed.
//!
//! Each module remembers the revision of its parameters it was built from
//! ([`ModuleSpec::revision`], which the animation system advances when an
//! animated value changes). A named texture or material is rebuilt when
//! its own revision moved on or when one it names was rebuilt; the texture
//! entries an old instance added are released for reuse. A light on a
//! shape is rebuilt when its parameters changed or its shape moved; a free
//! light when its parameters or transform changed or the scene's bounding
//! sphere did (lights at infinity depend on it). The camera follows its
//! pose and parameters, the sampler the frame's seed.

use super::geometry::EmitterSource;
use super::materials::NestedMaterials;
use super::{LightTable, RenderScene};
use crate::error::{SceneError, module_error};
use crate::world::{CameraPose, EmitterSpec, LightSpec, ModuleSpec, Scene, Transform};
use glam::{DMat4, DVec3, Mat4, UVec2};
use hecs::Entity;
use marked_yaml::Node;
use radiant_core::registry::ModuleType;
use radiant_core::{
    BoundingSphere, BuildContext, Camera, Effects, EmitterShape, Filter, Light, ModuleKind,
    Registry, Sampler, Shader, Texture, TextureId, TextureTable,
};
use std::collections::{BTreeSet, HashMap, HashSet};

/// What a named texture or material was built from.
struct Built {
    /// The revision of its parameters.
    revision: u64,
    /// The texture entries its build added (released when it is rebuilt).
    owned: Vec<TextureId>,
    /// The named textures and materials it names.
    texture_deps: Vec<usize>,
    material_deps: Vec<usize>,
}

/// Where a light comes from, and what it was built from.
enum Source {
    /// An emitter on a shape.
    Emitter {
        entity: Entity,
        shape: EmitterShape,
        revision: u64,
    },
    /// A light of `lights:`.
    Free {
        entity: Entity,
        revision: u64,
        transform: DMat4,
    },
}

impl Source {
    /// The light's module type.
    fn type_name(&self, scene: &Scene) -> String {
        let world = &scene.world;
        let name = match self {
            Source::Emitter { entity, .. } => world
                .get::<&EmitterSpec>(*entity)
                .map(|s| s.0.type_name.clone()),
            Source::Free { entity, .. } => world
                .get::<&LightSpec>(*entity)
                .map(|s| s.0.type_name.clone()),
        };
        name.unwrap_or_default()
    }
}

/// The module instances' state across frames.
pub(super) struct ModuleState {
    textures: Vec<Built>,
    texture_ids: Vec<TextureId>,
    named_textures: HashMap<String, TextureId>,
    materials: Vec<Built>,
    lights: Vec<Source>,
    sphere: BoundingSphere,
    /// (revision, camera to render space) the camera was built with.
    camera: (u64, Mat4),
    /// The seed the sampler was built with.
    seed: u64,
    render_origin: DVec3,
}

/// The scalar strings in `node`: the names a module's parameters may use.
fn names_in(node: &Node, out: &mut HashSet<String>) {
    match node {
        Node::Scalar(s) => {
            out.insert(s.as_str().to_string());
        }
        Node::Sequence(s) => s.iter().for_each(|n| names_in(n, out)),
        Node::Mapping(m) => m.values().for_each(|n| names_in(n, out)),
    }
}

/// The indices of `named` whose names `spec`'s parameters mention.
fn deps(spec: &ModuleSpec, named: &[(String, ModuleSpec)]) -> Vec<usize> {
    let mut names = HashSet::new();
    names_in(spec.params.node(), &mut names);
    named
        .iter()
        .enumerate()
        .filter(|(_, (n, _))| names.contains(n))
        .map(|(i, _)| i)
        .collect()
}

/// Builds modules of one scene for one frame.
struct Builder<'a> {
    registry: &'a Registry,
    scene: &'a Scene,
    resolution: UVec2,
    seed: u64,
    spp: u32,
    camera_to_render: Mat4,
    render_origin: DVec3,
    sphere: BoundingSphere,
    modules: &'a mut BTreeSet<(ModuleKind, String)>,
}

impl Builder<'_> {
    fn build<T: ModuleType + ?Sized>(
        &mut self,
        spec: &ModuleSpec,
        textures: &mut TextureTable,
        named: &HashMap<String, TextureId>,
        shape: Option<&EmitterShape>,
        to_world: DMat4,
    ) -> Result<Box<T>, SceneError> {
        self.build_as(spec, textures, named, shape, to_world, None)
    }

    /// [`Builder::build`], for named material `material` where it is one
    /// (so that a material containing itself is caught).
    fn build_as<T: ModuleType + ?Sized>(
        &mut self,
        spec: &ModuleSpec,
        textures: &mut TextureTable,
        named: &HashMap<String, TextureId>,
        shape: Option<&EmitterShape>,
        to_world: DMat4,
        material: Option<usize>,
    ) -> Result<Box<T>, SceneError> {
        let nested = NestedMaterials::new(self.registry, self.scene);
        let _building = material.map(|i| nested.enter(i));
        let mut ctx = BuildContext {
            resolution: self.resolution,
            camera_to_render: self.camera_to_render,
            render_origin: self.render_origin,
            seed: self.seed,
            spp: self.spp,
            emitter_shape: shape,
            to_world,
            scene_sphere: self.sphere,
            scene_dir: &self.scene.dir,
            textures,
            named_textures: named,
            materials: Some(&nested),
        };
        let module = self
            .registry
            .build::<T>(&spec.type_name, &spec.params, &mut ctx)
            .map_err(|e| module_error(&self.scene.file, spec, e))?;
        self.modules.insert((T::KIND, spec.type_name.clone()));
        self.modules.append(&mut nested.used.borrow_mut());
        Ok(module)
    }
}

/// The camera's pose in render space (rotation only; the camera sits at
/// its position relative to the render origin).
pub(super) fn camera_to_render(pose: DMat4, render_origin: DVec3) -> Mat4 {
    DMat4::from_cols(
        pose.x_axis,
        pose.y_axis,
        pose.z_axis,
        (pose.w_axis.truncate() - render_origin).extend(1.0),
    )
    .as_mat4()
}

/// The scene's camera pose.
pub(super) fn camera_pose(scene: &Scene) -> Result<CameraPose, SceneError> {
    let mut query = scene.world.query::<&CameraPose>();
    let pose = query.iter().next().cloned();
    pose.ok_or_else(|| SceneError::new(&scene.file, None, "the scene has no camera"))
}

/// What the first build of the modules produced.
pub(super) struct Initial {
    pub shaders: Vec<Box<dyn Shader>>,
    pub textures: TextureTable,
    pub lights: LightTable,
    pub camera: Box<dyn Camera>,
    pub filter: Box<dyn Filter>,
    pub sampler: Box<dyn Sampler>,
    pub modules: BTreeSet<(ModuleKind, String)>,
}

impl ModuleState {
    /// Builds every module of `scene` for the frame it stands at.
    pub(super) fn build(
        scene: &Scene,
        registry: &Registry,
        settings: &crate::settings::RenderSettings,
        render_origin: DVec3,
        emitters: Vec<EmitterSource>,
        sphere: BoundingSphere,
    ) -> Result<(Self, Initial), SceneError> {
        let pose = camera_pose(scene)?;
        let to_render = camera_to_render(pose.to_world, render_origin);
        let mut modules = BTreeSet::new();
        let mut b = Builder {
            registry,
            scene,
            resolution: UVec2::new(settings.width, settings.height),
            seed: settings.seed,
            spp: settings.spp,
            camera_to_render: to_render,
            render_origin,
            sphere,
            modules: &mut modules,
        };
        let mut textures = TextureTable::default();
        let mut named = HashMap::new();
        let mut built_textures = Vec::new();
        let mut texture_ids = Vec::new();
        for (name, spec) in &scene.textures {
            let texture =
                b.build::<dyn Texture>(spec, &mut textures, &named, None, DMat4::IDENTITY)?;
            let owned = textures.take_added();
            let id = textures.add(texture);
            textures.take_added();
            named.insert(name.clone(), id);
            texture_ids.push(id);
            built_textures.push(Built {
                revision: spec.revision,
                owned,
                texture_deps: deps(spec, &scene.textures),
                material_deps: Vec::new(),
            });
        }
        let mut shaders = Vec::with_capacity(scene.materials.len());
        let mut built_materials = Vec::new();
        for (i, (_, spec)) in scene.materials.iter().enumerate() {
            shaders.push(build_material(&mut b, i, &mut textures, &named)?);
            built_materials.push(Built {
                revision: spec.revision,
                owned: textures.take_added(),
                texture_deps: deps(spec, &scene.textures),
                material_deps: deps(spec, &scene.materials),
            });
        }

        let (lights, sources) = build_lights(&mut b, &mut textures, &named, emitters)?;
        let filter =
            b.build::<dyn Filter>(&scene.filter, &mut textures, &named, None, DMat4::IDENTITY)?;
        let sampler =
            b.build::<dyn Sampler>(&scene.sampler, &mut textures, &named, None, DMat4::IDENTITY)?;
        let camera =
            b.build::<dyn Camera>(&pose.module, &mut textures, &named, None, DMat4::IDENTITY)?;
        textures.take_added();
        let state = Self {
            textures: built_textures,
            texture_ids,
            named_textures: named,
            materials: built_materials,
            lights: sources,
            sphere,
            camera: (pose.module.revision, to_render),
            seed: settings.seed,
            render_origin,
        };
        let initial = Initial {
            shaders,
            textures,
            lights: LightTable::new(lights, settings.light_selection),
            camera,
            filter,
            sampler,
            modules,
        };
        Ok((state, initial))
    }

    /// Each light's module type, by light index.
    pub(super) fn light_types(&self, scene: &Scene) -> Vec<String> {
        self.lights.iter().map(|s| s.type_name(scene)).collect()
    }

    /// The named textures: (id, name, module type).
    pub(super) fn texture_names(&self, scene: &Scene) -> Vec<(TextureId, String, String)> {
        scene
            .textures
            .iter()
            .zip(&self.texture_ids)
            .map(|((name, spec), &id)| (id, name.clone(), spec.type_name.clone()))
            .collect()
    }

    /// Rebuilds what changed since the last frame in `render`: textures
    /// and materials whose parameters (or whose named inputs) changed,
    /// lights whose parameters, shape, transform or scene sphere changed,
    /// the camera, the sampler. Returns how many modules were rebuilt.
    pub(super) fn update(
        &mut self,
        scene: &Scene,
        registry: &Registry,
        render: &mut RenderScene,
        moved: Vec<EmitterSource>,
        sphere: BoundingSphere,
    ) -> Result<usize, SceneError> {
        let settings = render.settings;
        let pose = camera_pose(scene)?;
        let to_render = camera_to_render(pose.to_world, self.render_origin);
        let mut b = Builder {
            registry,
            scene,
            resolution: UVec2::new(settings.width, settings.height),
            seed: settings.seed,
            spp: settings.spp,
            camera_to_render: to_render,
            render_origin: self.render_origin,
            sphere,
            modules: &mut render.modules,
        };
        let textures = &mut render.textures;
        let mut rebuilt = 0;

        // Named textures in file order: a texture may use those above it.
        let mut texture_rebuilt = vec![false; self.textures.len()];
        for (i, (_, spec)) in scene.textures.iter().enumerate() {
            let built = &self.textures[i];
            let dirty = built.revision != spec.revision
                || built.texture_deps.iter().any(|&d| texture_rebuilt[d]);
            if !dirty {
                continue;
            }
            textures.release(&built.owned);
            textures.take_added();
            let texture = b.build::<dyn Texture>(
                spec,
                textures,
                &self.named_textures,
                None,
                DMat4::IDENTITY,
            )?;
            let owned = textures.take_added();
            textures.replace(self.texture_ids[i], texture);
            let built = &mut self.textures[i];
            built.revision = spec.revision;
            built.owned = owned;
            texture_rebuilt[i] = true;
            rebuilt += 1;
        }
        // Materials may name each other in any order: mark to a fixed point.
        let n = self.materials.len();
        let mut dirty: Vec<bool> = (0..n)
            .map(|i| {
                let built = &self.materials[i];
                built.revision != scene.materials[i].1.revision
                    || built.texture_deps.iter().any(|&d| texture_rebuilt[d])
            })
            .collect();
        loop {
            let before = dirty.iter().filter(|&&d| d).count();
            for i in 0..n {
                if !dirty[i] && self.materials[i].material_deps.iter().any(|&d| dirty[d]) {
                    dirty[i] = true;
                }
            }
            if dirty.iter().filter(|&&d| d).count() == before {
                break;
            }
        }
        for i in (0..n).filter(|&i| dirty[i]) {
            textures.release(&self.materials[i].owned);
            textures.take_added();
            render.shaders[i] = build_material(&mut b, i, textures, &self.named_textures)?;
            let built = &mut self.materials[i];
            built.owned = textures.take_added();
            built.revision = scene.materials[i].1.revision;
            rebuilt += 1;
        }

        // Lights.
        let mut replaced: Vec<(usize, Box<dyn Light>)> = Vec::new();
        let sphere_changed = sphere != self.sphere;
        for m in moved {
            if let Source::Emitter { shape, .. } = &mut self.lights[m.light as usize] {
                *shape = m.shape;
            }
            let light = self.rebuild_light(&mut b, textures, m.light as usize)?;
            replaced.push((m.light as usize, light));
        }
        for i in 0..self.lights.len() {
            if replaced.iter().any(|(j, _)| *j == i) {
                continue;
            }
            let stale = match &self.lights[i] {
                Source::Emitter {
                    entity, revision, ..
                } => scene
                    .world
                    .get::<&EmitterSpec>(*entity)
                    .is_ok_and(|s| s.0.revision != *revision),
                Source::Free {
                    entity,
                    revision,
                    transform,
                } => {
                    sphere_changed
                        || scene
                            .world
                            .get::<&LightSpec>(*entity)
                            .is_ok_and(|s| s.0.revision != *revision)
                        || scene
                            .world
                            .get::<&Transform>(*entity)
                            .is_ok_and(|t| t.0 != *transform)
                }
            };
            if stale {
                let light = self.rebuild_light(&mut b, textures, i)?;
                replaced.push((i, light));
            }
        }
        self.sphere = sphere;
        rebuilt += replaced.len();
        if !replaced.is_empty() {
            render.lights.replace(replaced, settings.light_selection);
        }

        if self.camera != (pose.module.revision, to_render) {
            render.camera = b.build::<dyn Camera>(
                &pose.module,
                textures,
                &self.named_textures,
                None,
                DMat4::IDENTITY,
            )?;
            self.camera = (pose.module.revision, to_render);
            rebuilt += 1;
        }
        if self.seed != settings.seed {
            render.sampler = b.build::<dyn Sampler>(
                &scene.sampler,
                textures,
                &self.named_textures,
                None,
                DMat4::IDENTITY,
            )?;
            self.seed = settings.seed;
            rebuilt += 1;
        }
        textures.take_added();
        Ok(rebuilt)
    }

    /// Builds light `i` again from its source (with the entity's current
    /// parameters and transform).
    fn rebuild_light(
        &mut self,
        b: &mut Builder<'_>,
        textures: &mut TextureTable,
        i: usize,
    ) -> Result<Box<dyn Light>, SceneError> {
        let world = &b.scene.world;
        match &mut self.lights[i] {
            Source::Emitter {
                entity,
                shape,
                revision,
            } => {
                let spec = world
                    .get::<&EmitterSpec>(*entity)
                    .expect("an emitter")
                    .0
                    .clone();
                *revision = spec.revision;
                build_emitter(b, textures, &self.named_textures, &spec, shape)
            }
            Source::Free {
                entity,
                revision,
                transform,
            } => {
                let spec = world.get::<&LightSpec>(*entity).expect("a light").0.clone();
                let t = world
                    .get::<&Transform>(*entity)
                    .map_or(DMat4::IDENTITY, |t| t.0);
                *revision = spec.revision;
                *transform = t;
                b.build::<dyn Light>(&spec, textures, &self.named_textures, None, t)
            }
        }
    }
}

/// Builds material `i` of the scene.
fn build_material(
    b: &mut Builder<'_>,
    i: usize,
    textures: &mut TextureTable,
    named: &HashMap<String, TextureId>,
) -> Result<Box<dyn Shader>, SceneError> {
    let scene = b.scene;
    let spec = &scene.materials[i].1;
    b.build_as::<dyn Shader>(spec, textures, named, None, DMat4::IDENTITY, Some(i))
}

/// Builds the area light `spec` on `shape`, checking that it is one.
fn build_emitter(
    b: &mut Builder<'_>,
    textures: &mut TextureTable,
    named: &HashMap<String, TextureId>,
    spec: &ModuleSpec,
    shape: &EmitterShape,
) -> Result<Box<dyn Light>, SceneError> {
    let light = b.build::<dyn Light>(spec, textures, named, Some(shape), DMat4::IDENTITY)?;
    let effects = light.effects();
    if light.is_delta()
        || !effects.contains(Effects::AREA_LIGHTS)
        || effects.contains(Effects::ENVIRONMENT)
    {
        return Err(SceneError::new(
            &b.scene.file,
            spec.location,
            format!(
                "a shape's `emitter` must be a light that emits from the shape's \
                 surface (such as `area`); `{}` does not — put it under `lights:`",
                spec.type_name
            ),
        ));
    }
    Ok(light)
}

/// The lights of a frame and where each comes from.
type BuiltLights = (Vec<Box<dyn Light>>, Vec<Source>);

/// Builds every light: the emitters on shapes by their light index, then
/// the free lights in the world's order.
fn build_lights(
    b: &mut Builder<'_>,
    textures: &mut TextureTable,
    named: &HashMap<String, TextureId>,
    mut emitters: Vec<EmitterSource>,
) -> Result<BuiltLights, SceneError> {
    emitters.sort_by_key(|e| e.light);
    let mut lights = Vec::new();
    let mut sources = Vec::new();
    let world = &b.scene.world;
    for e in emitters {
        debug_assert_eq!(e.light as usize, lights.len());
        let spec = world
            .get::<&EmitterSpec>(e.entity)
            .expect("an emitter")
            .0
            .clone();
        lights.push(build_emitter(b, textures, named, &spec, &e.shape)?);
        sources.push(Source::Emitter {
            entity: e.entity,
            shape: e.shape,
            revision: spec.revision,
        });
    }
    let free: Vec<(Entity, ModuleSpec, DMat4)> = world
        .query::<(Entity, &LightSpec, &Transform)>()
        .iter()
        .map(|(e, s, t)| (e, s.0.clone(), t.0))
        .collect();
    for (entity, spec, transform) in free {
        lights.push(b.build::<dyn Light>(&spec, textures, named, None, transform)?);
        sources.push(Source::Free {
            entity,
            revision: spec.revision,
            transform,
        });
    }
    Ok((lights, sources))
}
