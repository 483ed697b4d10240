//! Extract: from the ECS world to flat render data.
//!
//! This step decides *render space* (world space shifted so the camera sits
//! at the origin, computed in double precision), tessellates shapes into
//! primitives, builds every module instance through the registry, builds
//! the BVH, lays the per-primitive shading data out in BVH order
//! (structure of arrays), and unions the modules' [`Effects`] into the
//! frame's effect set.

mod lights;
mod materials;
mod shapes;

pub use lights::LightTable;

use crate::accel::{Accel, BuildQuality, Primitive};
use crate::error::{SceneError, module_error};
use crate::scene::Scene;
pub use crate::settings::Overrides;
use crate::settings::RenderSettings;
use crate::world::{
    CameraPose, EmitterSpec, FlippedNormals, Geometry, LightSpec, MaterialRef, MeshRepairs,
    ModuleSpec, Name, Transform,
};
use glam::{DMat4, UVec2, Vec2, Vec3};
use materials::NestedMaterials;
use radiant_core::registry::ModuleType;
use radiant_core::{
    BoundingSphere, BuildContext, Camera, Effects, EmitterShape, Filter, Frame, Light, ModuleKind,
    Registry, Sampler, Shader, Texture, TextureTable,
};
use shapes::{ShapePrim, tessellate};
use std::collections::{BTreeSet, HashMap};
use std::time::Duration;

/// "No emitter" in [`Surfaces::emitter`].
pub const NO_EMITTER: u32 = u32::MAX;

/// Per-primitive shading data, indexed by BVH-order primitive index.
#[derive(Debug, Default)]
pub struct Surfaces {
    /// Material (shader) index.
    pub material: Vec<u32>,
    /// Light index of the emitter on this primitive, or [`NO_EMITTER`].
    pub emitter: Vec<u32>,
    /// Index of the primitive within its emitter's shape.
    pub emitter_prim: Vec<u32>,
    /// Vertex normals of triangles (all zero: use the face normal).
    pub normals: Vec<[Vec3; 3]>,
    /// Vertex texture coordinates of triangles.
    pub uvs: Vec<[Vec2; 3]>,
    /// Frame around the unit face normal of triangles (by winding), made
    /// once here rather than at every hit; `n` is the geometric normal.
    pub face_frames: Vec<Frame>,
}

/// Counts that `radiant info` reports.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct SceneStats {
    /// Triangles after tessellation.
    pub triangles: usize,
    /// Analytic spheres.
    pub spheres: usize,
    /// Shapes carrying an emitter.
    pub emissive_shapes: usize,
    /// What was repaired in all shapes together (on load and in render
    /// space).
    pub repairs: MeshRepairs,
    /// Each shape in which something was repaired, by name (and mesh
    /// file), with its counts (a mesh used by several shapes is listed for each).
    pub repaired_shapes: Vec<(String, MeshRepairs)>,
    /// BVH build time.
    pub bvh_build: Duration,
}

/// Everything a backend needs to render one frame.
pub struct RenderScene {
    /// The frame's settings, overrides applied.
    pub settings: RenderSettings,
    /// The BVH and primitives.
    pub accel: Accel,
    /// Shading data per primitive.
    pub surfaces: Surfaces,
    /// Shader per material index.
    pub shaders: Vec<Box<dyn Shader>>,
    /// Material names, per material index.
    pub material_names: Vec<String>,
    /// The lights.
    pub lights: LightTable,
    /// The camera.
    pub camera: Box<dyn Camera>,
    /// The pixel filter.
    pub filter: Box<dyn Filter>,
    /// The sampler.
    pub sampler: Box<dyn Sampler>,
    /// The textures.
    pub textures: TextureTable,
    /// The light-transport features the frame needs.
    pub effects: Effects,
    /// The module types in use.
    pub modules: BTreeSet<(ModuleKind, String)>,
    /// Counts for reporting.
    pub stats: SceneStats,
}

struct Builder<'r> {
    registry: &'r Registry,
    scene: &'r Scene,
    modules: BTreeSet<(ModuleKind, String)>,
}

impl Builder<'_> {
    fn build<T: ModuleType + ?Sized>(
        &mut self,
        spec: &ModuleSpec,
        ctx: &mut BuildContext<'_>,
    ) -> Result<Box<T>, SceneError> {
        let module = self
            .registry
            .build::<T>(&spec.type_name, &spec.params, ctx)
            .map_err(|e| module_error(&self.scene.file, spec, e))?;
        self.modules.insert((T::KIND, spec.type_name.clone()));
        Ok(module)
    }
}

/// Builds the render data of `scene`'s current frame.
pub fn extract(
    scene: &Scene,
    registry: &Registry,
    overrides: &Overrides,
) -> Result<RenderScene, SceneError> {
    let file = &scene.file;
    let settings = scene
        .settings
        .with(overrides)
        .map_err(|e| SceneError::new(file, None, e.to_string()))?;

    let pose = {
        let mut query = scene.world.query::<&CameraPose>();
        let pose = query.iter().next().cloned();
        pose.ok_or_else(|| SceneError::new(file, None, "the scene has no camera"))?
    };
    let render_origin = pose.to_world.w_axis.truncate();
    let camera_to_render = DMat4::from_cols(
        pose.to_world.x_axis,
        pose.to_world.y_axis,
        pose.to_world.z_axis,
        glam::DVec4::W,
    )
    .as_mat4();

    let mut b = Builder {
        registry,
        scene,
        modules: BTreeSet::new(),
    };
    let mut textures = TextureTable::default();
    let mut named_textures = HashMap::new();
    let nested = NestedMaterials::new(registry, scene);
    let mut scene_sphere = BoundingSphere::default();
    macro_rules! ctx {
        ($shape:expr) => {
            ctx!($shape, DMat4::IDENTITY)
        };
        ($shape:expr, $to_world:expr) => {
            BuildContext {
                resolution: UVec2::new(settings.width, settings.height),
                camera_to_render,
                render_origin,
                seed: settings.seed,
                spp: settings.spp,
                emitter_shape: $shape,
                to_world: $to_world,
                scene_sphere,
                scene_dir: &scene.dir,
                textures: &mut textures,
                named_textures: &named_textures,
                materials: Some(&nested),
            }
        };
    }

    for (name, spec) in &scene.textures {
        let texture = b.build::<dyn Texture>(spec, &mut ctx!(None))?;
        let id = textures.add(texture);
        named_textures.insert(name.clone(), id);
    }
    let mut shaders = Vec::with_capacity(scene.materials.len());
    for (i, (_, spec)) in scene.materials.iter().enumerate() {
        let _building = nested.enter(i);
        shaders.push(b.build::<dyn Shader>(spec, &mut ctx!(None))?);
    }
    b.modules.append(&mut nested.used.borrow_mut());

    let mut prims: Vec<ShapePrim> = Vec::new();
    let mut material = Vec::new();
    let mut emitter = Vec::new();
    let mut emitter_prim = Vec::new();
    let mut lights: Vec<Box<dyn Light>> = Vec::new();
    let mut stats = SceneStats::default();
    let mut query = scene.world.query::<(
        &Name,
        &Transform,
        &Geometry,
        &MaterialRef,
        Option<&EmitterSpec>,
        Option<&FlippedNormals>,
    )>();
    for (name, transform, geometry, mat, emitter_spec, flipped) in query.iter() {
        let start = prims.len();
        let flip = flipped.is_some();
        let mut repairs = tessellate(geometry, transform.0, render_origin, flip, &mut prims);
        let count = prims.len() - start;
        let mut label = name.0.clone();
        if let Geometry::Mesh(mesh) = geometry {
            repairs.add(&mesh.repairs);
            label = format!("{label} ({})", mesh.source);
        }
        stats.repairs.add(&repairs);
        if repairs.any() {
            stats.repaired_shapes.push((label, repairs));
        }
        let light_id = match emitter_spec {
            Some(EmitterSpec(spec)) => {
                let mut shape = EmitterShape::default();
                for p in &prims[start..] {
                    match *p {
                        ShapePrim::Triangle { v, .. } => shape.triangles.push(v),
                        ShapePrim::Sphere { centre, radius } => {
                            shape.spheres.push((centre, radius))
                        }
                    }
                }
                let light = b.build::<dyn Light>(spec, &mut ctx!(Some(&shape)))?;
                let effects = light.effects();
                if light.is_delta()
                    || !effects.contains(Effects::AREA_LIGHTS)
                    || effects.contains(Effects::ENVIRONMENT)
                {
                    return Err(SceneError::new(
                        file,
                        spec.location,
                        format!(
                            "a shape's `emitter` must be a light that emits from the shape's \
                             surface (such as `area`); `{}` does not — put it under `lights:`",
                            spec.type_name
                        ),
                    ));
                }
                lights.push(light);
                stats.emissive_shapes += 1;
                (lights.len() - 1) as u32
            }
            None => NO_EMITTER,
        };
        material.extend(std::iter::repeat_n(mat.0, count));
        emitter.extend(std::iter::repeat_n(light_id, count));
        // Emitter shapes list triangles first, then spheres.
        let tris = prims[start..]
            .iter()
            .filter(|p| matches!(p, ShapePrim::Triangle { .. }))
            .count() as u32;
        let (mut t, mut s) = (0u32, 0u32);
        for p in &prims[start..] {
            emitter_prim.push(match p {
                ShapePrim::Triangle { .. } => {
                    t += 1;
                    t - 1
                }
                ShapePrim::Sphere { .. } => {
                    s += 1;
                    tris + s - 1
                }
            });
        }
    }
    drop(query);
    scene_sphere = bounding_sphere(&prims);
    let mut light_query = scene.world.query::<(&LightSpec, &Transform)>();
    for (LightSpec(spec), transform) in light_query.iter() {
        lights.push(b.build::<dyn Light>(spec, &mut ctx!(None, transform.0))?);
    }
    drop(light_query);

    let filter = b.build::<dyn Filter>(&scene.filter, &mut ctx!(None))?;
    let sampler = b.build::<dyn Sampler>(&scene.sampler, &mut ctx!(None))?;
    let camera = b.build::<dyn Camera>(&pose.module, &mut ctx!(None))?;

    let geometric: Vec<Primitive> = prims
        .iter()
        .map(|p| match *p {
            ShapePrim::Triangle { v, .. } => Primitive::Triangle(v),
            ShapePrim::Sphere { centre, radius } => Primitive::Sphere(centre, radius),
        })
        .collect();
    let (accel, order) = Accel::build(
        &geometric,
        overrides
            .bvh
            .unwrap_or_else(|| BuildQuality::default_for(geometric.len())),
    );
    stats.bvh_build = accel.build_time;
    let mut surfaces = Surfaces::default();
    for &i in &order {
        let i = i as usize;
        surfaces.material.push(material[i]);
        surfaces.emitter.push(emitter[i]);
        surfaces.emitter_prim.push(emitter_prim[i]);
        match prims[i] {
            ShapePrim::Triangle { v, n, uv } => {
                stats.triangles += 1;
                surfaces.normals.push(n);
                surfaces.uvs.push(uv);
                let ng = (v[1] - v[0]).cross(v[2] - v[0]).normalize();
                surfaces.face_frames.push(Frame::from_normal(ng));
            }
            ShapePrim::Sphere { .. } => {
                stats.spheres += 1;
                surfaces.normals.push([Vec3::ZERO; 3]);
                surfaces.uvs.push([Vec2::ZERO; 3]);
                surfaces.face_frames.push(Frame::from_normal(Vec3::Z));
            }
        }
    }

    let mut effects = camera.effects();
    for s in &shaders {
        effects |= s.effects();
    }
    for l in &lights {
        effects |= l.effects();
    }
    let material_names = scene.materials.iter().map(|(n, _)| n.clone()).collect();
    Ok(RenderScene {
        settings,
        accel,
        surfaces,
        shaders,
        material_names,
        lights: LightTable::new(lights, settings.light_selection),
        camera,
        filter,
        sampler,
        textures,
        effects,
        modules: b.modules,
        stats,
    })
}

/// A sphere around the bounding box of `prims` (Mitsuba's convention,
/// enlarged slightly), with a positive radius even for an empty scene.
fn bounding_sphere(prims: &[ShapePrim]) -> BoundingSphere {
    let (mut lo, mut hi) = (Vec3::INFINITY, Vec3::NEG_INFINITY);
    for p in prims {
        match *p {
            ShapePrim::Triangle { v, .. } => {
                for x in v {
                    lo = lo.min(x);
                    hi = hi.max(x);
                }
            }
            ShapePrim::Sphere { centre, radius } => {
                lo = lo.min(centre - radius);
                hi = hi.max(centre + radius);
            }
        }
    }
    if !(lo.cmple(hi).all()) {
        return BoundingSphere {
            centre: Vec3::ZERO,
            radius: 1.0,
        };
    }
    let centre = 0.5 * (lo + hi);
    BoundingSphere {
        centre,
        radius: ((hi - centre).length() * (1.0 + 1e-3)).max(1e-3),
    }
}
