//! The scene's shapes in the accelerator, and how they follow the frames.
//!
//! Static shapes — neither animated, nor deforming, nor instanced — are
//! tessellated once in render space into one bottom level, placed without
//! a transform (a scene of only static shapes is queried as one hierarchy).
//! Every other shape gets a bottom level of its own in object space, with
//! one instance per copy: its placement is the shift to render space, the
//! copy's transform, the animated pose and the shape's own transform. Each
//! frame, animated shapes get new placements (motions where they move
//! while the shutter is open), deforming meshes are refitted to their new
//! vertices, and the top level follows.

use super::shapes::{ShapePrim, tessellate};
use super::{NO_EMITTER, NO_MATERIAL, SceneStats, Surfaces};
use crate::accel::{
    Accel, Blas, BuildQuality, Instance, Motion, Place, Placement, Primitive, UpdatePolicy,
};
use crate::error::SceneError;
use crate::world::{
    Animation, BaseTransform, ClosingMesh, EmitterSpec, FlippedNormals, Geometry, InstanceSpec,
    Instances, MaterialRef, MeshSequence, Name, Pose, Scene, Transform,
};
use glam::{DMat4, DVec3, Vec2, Vec3};
use hecs::Entity;
use radiant_core::{BoundingSphere, EmitterShape, Frame};
use std::sync::Arc;
use std::time::{Duration, Instant};

/// The geometry of a shape that carries an emitter, in render space, and
/// the light index its primitives name.
pub(super) struct EmitterSource {
    /// The shape.
    pub entity: Entity,
    /// Its triangles and spheres in render space.
    pub shape: EmitterShape,
    /// Its index in the frame's light list.
    pub light: u32,
}

/// A shape with a bottom level of its own.
struct DynamicShape {
    entity: Entity,
    /// Its bottom level.
    blas: usize,
    /// Its first instance; it has one per copy.
    first_instance: usize,
    /// The copies (one, with the identity, for a shape without
    /// `instances:`).
    copies: Arc<[InstanceSpec]>,
    /// Whether it has an animation, a deforming mesh.
    animated: bool,
    deforming: bool,
    /// Its emitter's light index.
    light: Option<u32>,
    /// The meshes the bottom level was last built from (open, close), to
    /// see whether a new frame deformed it.
    meshes: Option<(Arc<crate::world::MeshData>, Arc<crate::world::MeshData>)>,
    /// The pose last placed.
    pose: Option<Pose>,
}

/// What a frame's update of the geometry did.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct GeometryUpdate {
    /// Time spent on the geometry in all (placements, deforming meshes'
    /// primitives and shading data, hierarchies).
    pub total: Duration,
    /// Of which refitting or rebuilding bottom levels and the top level.
    pub bvh: Duration,
    /// Bottom levels refitted and rebuilt.
    pub refitted: usize,
    /// See `refitted`.
    pub rebuilt: usize,
    /// The largest SAH cost over its cost at build among the updated
    /// hierarchies (1 when nothing was refitted).
    pub degradation: f32,
    /// Whether the top level was rebuilt.
    pub top_rebuilt: bool,
}

/// What the first build of the geometry produced.
pub(super) struct Built {
    /// The state kept for later frames.
    pub geometry: SceneGeometry,
    /// The accelerator.
    pub accel: Accel,
    /// The shading data per primitive.
    pub surfaces: Surfaces,
    /// The material per instance ([`NO_MATERIAL`]: its primitives' own).
    pub instance_material: Vec<u32>,
    /// The shapes carrying emitters, with their light indices.
    pub emitters: Vec<EmitterSource>,
}

/// The geometry's state across frames.
pub(super) struct SceneGeometry {
    render_origin: DVec3,
    policy: UpdatePolicy,
    blur: bool,
    dynamic: Vec<DynamicShape>,
    /// The box of the static shapes (render space), if any.
    static_box: Option<(Vec3, Vec3)>,
}

/// Shading attributes of one shape's primitives, laid out by a bottom
/// level's order.
struct Shading<'a> {
    prims: &'a [ShapePrim],
    material: &'a [u32],
    emitter: &'a [u32],
    emitter_prim: &'a [u32],
    /// Whether the primitives are in render space (face frames are stored).
    render_space: bool,
}

/// Writes the shading data of `shading`'s primitives in leaf order `order`
/// at primitive numbers from `base` on.
fn lay_out(surfaces: &mut Surfaces, base: usize, order: &[u32], shading: &Shading<'_>) {
    let end = base + order.len();
    for v in [
        &mut surfaces.material,
        &mut surfaces.emitter,
        &mut surfaces.emitter_prim,
    ] {
        if v.len() < end {
            v.resize(end, 0);
        }
    }
    if surfaces.normals.len() < end {
        surfaces.normals.resize(end, [Vec3::ZERO; 3]);
        surfaces.uvs.resize(end, [Vec2::ZERO; 3]);
        surfaces
            .face_frames
            .resize(end, Frame::from_normal(Vec3::Z));
    }
    let has_tangents = shading
        .prims
        .iter()
        .any(|p| matches!(p, ShapePrim::Triangle { t, .. } if t[0] != Vec3::ZERO));
    if (has_tangents || !surfaces.tangents.is_empty()) && surfaces.tangents.len() < end {
        surfaces.tangents.resize(end, [Vec3::ZERO; 3]);
    }
    for (k, &i) in order.iter().enumerate() {
        let (j, i) = (base + k, i as usize);
        surfaces.material[j] = shading.material[i];
        surfaces.emitter[j] = shading.emitter[i];
        surfaces.emitter_prim[j] = shading.emitter_prim[i];
        match shading.prims[i] {
            ShapePrim::Triangle { v, n, uv, t } => {
                surfaces.normals[j] = n;
                surfaces.uvs[j] = uv;
                if let Some(slot) = surfaces.tangents.get_mut(j) {
                    *slot = t;
                }
                let ng = (v[1] - v[0]).cross(v[2] - v[0]).normalize_or_zero();
                surfaces.face_frames[j] = if shading.render_space {
                    Frame::from_normal(ng)
                } else {
                    Frame::from_normal(Vec3::Z)
                };
            }
            ShapePrim::Sphere { to_object, .. } => {
                // A sphere has no vertex normals: the slot holds the rows
                // of its rotation to object space (for its uv).
                surfaces.normals[j] = to_object;
                surfaces.uvs[j] = [Vec2::ZERO; 3];
                surfaces.face_frames[j] = Frame::from_normal(Vec3::Z);
            }
        }
    }
}

/// The intersector's view of `prims`.
fn geometric(prims: &[ShapePrim]) -> Vec<Primitive> {
    prims
        .iter()
        .map(|p| match *p {
            ShapePrim::Triangle { v, .. } => Primitive::Triangle(v),
            ShapePrim::Sphere { centre, radius, .. } => Primitive::Sphere(centre, radius),
        })
        .collect()
}

/// Per primitive of a shape, its index among the emitter shape's parts
/// (triangles first, then spheres), and the emitter shape itself.
fn emitter_parts(prims: &[ShapePrim]) -> (Vec<u32>, EmitterShape) {
    let mut shape = EmitterShape::default();
    for p in prims {
        match *p {
            ShapePrim::Triangle { v, .. } => shape.triangles.push(v),
            ShapePrim::Sphere { centre, radius, .. } => shape.spheres.push((centre, radius)),
        }
    }
    let tris = shape.triangles.len() as u32;
    let (mut t, mut s) = (0u32, 0u32);
    let parts = prims
        .iter()
        .map(|p| match p {
            ShapePrim::Triangle { .. } => {
                t += 1;
                t - 1
            }
            ShapePrim::Sphere { .. } => {
                s += 1;
                tris + s - 1
            }
        })
        .collect();
    (parts, shape)
}

/// The box around `prims`, if any has finite coordinates.
fn prims_box(prims: &[ShapePrim]) -> Option<(Vec3, Vec3)> {
    let (mut lo, mut hi) = (Vec3::INFINITY, Vec3::NEG_INFINITY);
    for p in prims {
        match *p {
            ShapePrim::Triangle { v, .. } => {
                for x in v {
                    lo = lo.min(x);
                    hi = hi.max(x);
                }
            }
            ShapePrim::Sphere { centre, radius, .. } => {
                lo = lo.min(centre - radius);
                hi = hi.max(centre + radius);
            }
        }
    }
    lo.cmple(hi).all().then_some((lo, hi))
}

/// A sphere around the box `(lo, hi)` (Mitsuba's convention, enlarged
/// slightly), with a positive radius even for an empty scene.
fn sphere_around(b: Option<(Vec3, Vec3)>) -> BoundingSphere {
    let Some((lo, hi)) = b else {
        return BoundingSphere {
            centre: Vec3::ZERO,
            radius: 1.0,
        };
    };
    let centre = 0.5 * (lo + hi);
    BoundingSphere {
        centre,
        radius: ((hi - centre).length() * (1.0 + 1e-3)).max(1e-3),
    }
}

/// The pose and object-to-world parts of a dynamic shape.
struct Parts {
    pose: Pose,
    /// The shape's own transform (its `transform:` when animated, else its
    /// whole transform).
    base: DMat4,
}

fn parts(scene: &Scene, entity: Entity) -> Parts {
    let world = &scene.world;
    match (
        world.get::<&Pose>(entity).ok(),
        world.get::<&BaseTransform>(entity).ok(),
    ) {
        (Some(pose), Some(base)) => Parts {
            pose: *pose,
            base: base.0,
        },
        _ => Parts {
            pose: Pose::default(),
            base: world
                .get::<&Transform>(entity)
                .map_or(DMat4::IDENTITY, |t| t.0),
        },
    }
}

impl SceneGeometry {
    /// Where the copy `copy` of a shape with `parts` lies in render space.
    fn place(
        &self,
        file: &std::path::Path,
        parts: &Parts,
        copy: &InstanceSpec,
        name: &str,
    ) -> Result<Place, SceneError> {
        let outer = DMat4::from_translation(-self.render_origin) * copy.transform;
        match parts.pose.shutter {
            Some((open, close)) if self.blur => Ok(Place::Moving(Box::new(Motion {
                outer,
                open,
                close,
                inner: parts.base,
            }))),
            _ => {
                let m = outer * parts.pose.frame.matrix() * parts.base;
                Placement::new(m).map(Place::Fixed).ok_or_else(|| {
                    SceneError::new(
                        file,
                        None,
                        format!(
                            "shape `{name}`: its transform is not invertible at this frame (a scale passing through zero?)"
                        ),
                    )
                })
            }
        }
    }

    /// Builds the geometry of `scene` as it stands: the accelerator, the
    /// shading data, the per-instance materials and the emitter shapes
    /// (light indices from 0 in the order of the shapes).
    pub(super) fn build(
        scene: &Scene,
        render_origin: DVec3,
        quality: Option<BuildQuality>,
        policy: UpdatePolicy,
        stats: &mut SceneStats,
    ) -> Result<Built, SceneError> {
        let blur = scene.timeline.shutter.is_some();
        let mut geometry = Self {
            render_origin,
            policy,
            blur,
            dynamic: Vec::new(),
            static_box: None,
        };
        let mut emitters = Vec::new();
        let mut blases = Vec::new();
        let mut instances = Vec::new();
        let mut instance_material = Vec::new();
        let mut surfaces = Surfaces::default();
        let mut next_light = 0u32;
        let mut light_of = |has: bool| {
            has.then(|| {
                next_light += 1;
                next_light - 1
            })
        };

        // Static shapes, merged in render space. Shapes are visited in the
        // world's order; a shape's light index is its rank among emitters.
        let world = &scene.world;
        let mut prims: Vec<ShapePrim> = Vec::new();
        let (mut material, mut emitter, mut emitter_prim) = (Vec::new(), Vec::new(), Vec::new());
        let mut dynamic_entities = Vec::new();
        let mut query = world.query::<(
            Entity,
            &Name,
            &Transform,
            &Geometry,
            &MaterialRef,
            Option<&EmitterSpec>,
            Option<&FlippedNormals>,
            Option<&Animation>,
            Option<&Instances>,
            Option<&MeshSequence>,
        )>();
        for (entity, name, transform, geom, mat, emitter_spec, flipped, anim, inst, seq) in
            query.iter()
        {
            let light = light_of(emitter_spec.is_some());
            if anim.is_some() || inst.is_some() || seq.is_some() {
                dynamic_entities.push((entity, light));
                continue;
            }
            let start = prims.len();
            let flip = flipped.is_some();
            let mut repairs = tessellate(geom, transform.0, render_origin, flip, false, &mut prims);
            let count = prims.len() - start;
            note_repairs(stats, name, geom, &mut repairs);
            material.extend(std::iter::repeat_n(mat.0, count));
            emitter.extend(std::iter::repeat_n(light.unwrap_or(NO_EMITTER), count));
            let (parts, shape) = emitter_parts(&prims[start..]);
            emitter_prim.extend(parts);
            if let Some(light) = light {
                stats.emissive_shapes += 1;
                emitters.push(EmitterSource {
                    entity,
                    shape,
                    light,
                });
            }
        }
        drop(query);
        geometry.static_box = prims_box(&prims);
        if !prims.is_empty() {
            check_bvh_memory(&scene.file, prims.len())?;
            let q = quality.unwrap_or_else(|| BuildQuality::default_for(prims.len()));
            let blas = Blas::build(&geometric(&prims), None, q);
            let shading = Shading {
                prims: &prims,
                material: &material,
                emitter: &emitter,
                emitter_prim: &emitter_prim,
                render_space: true,
            };
            lay_out(&mut surfaces, 0, blas.order(), &shading);
            count_prims(stats, &prims, 1);
            blases.push(blas);
            instances.push(Instance {
                blas: 0,
                place: Place::Identity,
            });
            instance_material.push(NO_MATERIAL);
        }

        // Dynamic shapes: a bottom level each, in object space.
        for (entity, light) in dynamic_entities {
            let geom = world
                .get::<&Geometry>(entity)
                .expect("queried above")
                .clone();
            let name = world.get::<&Name>(entity).expect("queried above").0.clone();
            let flip = world.get::<&FlippedNormals>(entity).is_ok();
            let mat = world.get::<&MaterialRef>(entity).expect("queried above").0;
            let animated = world.get::<&Animation>(entity).is_ok();
            let deforming = world.get::<&MeshSequence>(entity).is_ok();
            let copies: Arc<[InstanceSpec]> = match world.get::<&Instances>(entity) {
                Ok(i) => i.0.clone(),
                Err(_) => Arc::from([InstanceSpec {
                    transform: DMat4::IDENTITY,
                    material: None,
                }]),
            };
            let mut prims = Vec::new();
            let mut repairs = tessellate(
                &geom,
                DMat4::IDENTITY,
                DVec3::ZERO,
                flip,
                deforming,
                &mut prims,
            );
            note_repairs(stats, &Name(name.clone()), &geom, &mut repairs);
            let closing = closing_prims(world, entity, blur, deforming, flip);
            let meshes = deforming.then(|| mesh_pair(world, entity)).flatten();
            check_bvh_memory(&scene.file, prims.len())?;
            let q = quality.unwrap_or_else(|| BuildQuality::default_for(prims.len()));
            let blas = Blas::build(&geometric(&prims), closing.as_deref(), q);
            let base = surfaces.material.len();
            let n = prims.len();
            let (parts_of_emitter, _) = emitter_parts(&prims);
            let shading = Shading {
                prims: &prims,
                material: &vec![mat; n],
                emitter: &vec![light.unwrap_or(NO_EMITTER); n],
                emitter_prim: &parts_of_emitter,
                render_space: false,
            };
            lay_out(&mut surfaces, base, blas.order(), &shading);
            count_prims(stats, &prims, copies.len());
            let index = blases.len();
            blases.push(blas);
            let p = parts(scene, entity);
            let first_instance = instances.len();
            for copy in copies.iter() {
                instances.push(Instance {
                    blas: index as u32,
                    place: geometry.place(&scene.file, &p, copy, &name)?,
                });
                instance_material.push(copy.material.map_or(NO_MATERIAL, |m| m.0));
            }
            stats.animated_shapes += usize::from(animated);
            stats.deforming_meshes += usize::from(deforming);
            stats.instanced_shapes += usize::from(world.get::<&Instances>(entity).is_ok());
            if let Some(light) = light {
                stats.emissive_shapes += 1;
                emitters.push(geometry.emitter(scene, entity, light, &p, &name)?);
            }
            geometry.dynamic.push(DynamicShape {
                entity,
                blas: index,
                first_instance,
                copies,
                animated,
                deforming,
                light,
                meshes,
                pose: Some(p.pose),
            });
        }
        stats.instances = instances.len();
        let top_quality = quality.unwrap_or_else(|| BuildQuality::default_for(instances.len()));
        let accel = Accel::new(blases, instances, top_quality);
        stats.bvh_build = accel.build_time;
        Ok(Built {
            geometry,
            accel,
            surfaces,
            instance_material,
            emitters,
        })
    }

    /// The emitter shape of dynamic shape `entity` in render space at the
    /// frame; an error where it moves while the shutter is open (area
    /// lights do not blur, as in pbrt-v4).
    fn emitter(
        &self,
        scene: &Scene,
        entity: Entity,
        light: u32,
        parts: &Parts,
        name: &str,
    ) -> Result<EmitterSource, SceneError> {
        let world = &scene.world;
        let moving = self.blur
            && (parts.pose.shutter.is_some()
                || mesh_pair(world, entity).is_some_and(|(a, b)| !Arc::ptr_eq(&a, &b)));
        if moving {
            let at = world
                .get::<&EmitterSpec>(entity)
                .ok()
                .and_then(|e| e.0.location);
            return Err(SceneError::new(
                &scene.file,
                at,
                format!(
                    "shape `{name}` carries an emitter and moves while the shutter is open; \
                     emitters cannot be motion-blurred (as in pbrt-v4): keep it still during \
                     the shutter or remove the camera's `shutter`"
                ),
            ));
        }
        let geom = world.get::<&Geometry>(entity).expect("a shape").clone();
        let flip = world.get::<&FlippedNormals>(entity).is_ok();
        let to_world = parts.pose.frame.matrix() * parts.base;
        let mut prims = Vec::new();
        tessellate(&geom, to_world, self.render_origin, flip, true, &mut prims);
        Ok(EmitterSource {
            entity,
            shape: emitter_parts(&prims).1,
            light,
        })
    }

    /// Moves the geometry to the frame the scene's systems last wrote:
    /// new placements for animated shapes, refitted (or rebuilt) bottom
    /// levels for deforming meshes, the top level after them. Returns the
    /// emitter shapes that moved (their lights must be rebuilt) and what
    /// was done.
    pub(super) fn update(
        &mut self,
        scene: &Scene,
        accel: &mut Accel,
        surfaces: &mut Surfaces,
    ) -> Result<(Vec<EmitterSource>, GeometryUpdate), SceneError> {
        let start = Instant::now();
        let world = &scene.world;
        let mut report = GeometryUpdate {
            degradation: 1.0,
            ..GeometryUpdate::default()
        };
        let mut moved = Vec::new();
        let mut changed = false;
        for i in 0..self.dynamic.len() {
            let d = &self.dynamic[i];
            let (entity, name) = (
                d.entity,
                world
                    .get::<&Name>(d.entity)
                    .map(|n| n.0.clone())
                    .unwrap_or_default(),
            );
            let p = parts(scene, entity);
            let mut shape_moved = false;
            if d.deforming {
                let pair = mesh_pair(world, entity);
                let same = match (&d.meshes, &pair) {
                    (Some((a, b)), Some((c, e))) => Arc::ptr_eq(a, c) && Arc::ptr_eq(b, e),
                    _ => false,
                };
                if !same {
                    let geom = world.get::<&Geometry>(entity).expect("a shape").clone();
                    let flip = world.get::<&FlippedNormals>(entity).is_ok();
                    let mut prims = Vec::new();
                    tessellate(&geom, DMat4::IDENTITY, DVec3::ZERO, flip, true, &mut prims);
                    let closing = closing_prims(world, entity, self.blur, true, flip);
                    let blas_index = d.blas;
                    let blas = accel.blas_mut(blas_index);
                    let update = blas.update(&geometric(&prims), closing.as_deref(), self.policy);
                    report.bvh += update.time;
                    report.refitted += usize::from(!update.rebuilt);
                    report.rebuilt += usize::from(update.rebuilt);
                    report.degradation = report.degradation.max(update.degradation);
                    let order = accel.blases()[blas_index].order().to_vec();
                    let base = accel.base(blas_index) as usize;
                    let n = prims.len();
                    let mat = world.get::<&MaterialRef>(entity).expect("a shape").0;
                    let (emitter_prim, _) = emitter_parts(&prims);
                    let shading = Shading {
                        prims: &prims,
                        material: &vec![mat; n],
                        emitter: &vec![d.light.unwrap_or(NO_EMITTER); n],
                        emitter_prim: &emitter_prim,
                        render_space: false,
                    };
                    lay_out(surfaces, base, &order, &shading);
                    self.dynamic[i].meshes = pair;
                    shape_moved = true;
                }
            }
            let d = &self.dynamic[i];
            if d.animated && d.pose != Some(p.pose) {
                for (k, copy) in d.copies.iter().enumerate() {
                    accel.instances_mut()[d.first_instance + k].place =
                        self.place(&scene.file, &p, copy, &name)?;
                }
                self.dynamic[i].pose = Some(p.pose);
                shape_moved = true;
            }
            if shape_moved {
                changed = true;
                if let Some(light) = self.dynamic[i].light {
                    moved.push(self.emitter(scene, entity, light, &p, &name)?);
                }
            }
        }
        if changed {
            let top = accel.update_top_level(self.policy);
            report.top_rebuilt = top.rebuilt;
            report.bvh += top.time;
        }
        report.total = start.elapsed();
        Ok((moved, report))
    }

    /// A sphere around everything at the frame (lights at infinity place
    /// their samples outside it).
    pub(super) fn scene_sphere(&self, accel: &Accel) -> BoundingSphere {
        let mut b = self.static_box;
        for d in &self.dynamic {
            for k in 0..d.copies.len() {
                if let Some(boxed) = accel.instance_bounds(d.first_instance + k) {
                    let (lo, hi) = (Vec3::from(boxed.min), Vec3::from(boxed.max));
                    b = Some(match b {
                        None => (lo, hi),
                        Some((a, c)) => (a.min(lo), c.max(hi)),
                    });
                }
            }
        }
        sphere_around(b)
    }
}

/// Adds a shape's repairs to the statistics.
fn note_repairs(
    stats: &mut SceneStats,
    name: &Name,
    geom: &Geometry,
    repairs: &mut crate::world::MeshRepairs,
) {
    let mut label = name.0.clone();
    if let Geometry::Mesh(mesh) = geom {
        repairs.add(&mesh.repairs);
        label = format!("{label} ({})", mesh.source);
    }
    stats.repairs.add(repairs);
    if repairs.any() {
        stats.repaired_shapes.push((label, *repairs));
    }
}

/// Adds the triangles and spheres of `prims`, placed `copies` times.
fn count_prims(stats: &mut SceneStats, prims: &[ShapePrim], copies: usize) {
    let tris = prims
        .iter()
        .filter(|p| matches!(p, ShapePrim::Triangle { .. }))
        .count();
    stats.triangles += tris;
    stats.spheres += prims.len() - tris;
    stats.instanced_triangles += (tris * copies) as u64;
}

/// The meshes (at shutter open, at close) of a deforming shape.
fn mesh_pair(
    world: &hecs::World,
    entity: Entity,
) -> Option<(Arc<crate::world::MeshData>, Arc<crate::world::MeshData>)> {
    let open = match &*world.get::<&Geometry>(entity).ok()? {
        Geometry::Mesh(m) => m.clone(),
        _ => return None,
    };
    let close = world.get::<&ClosingMesh>(entity).ok()?.0.clone();
    Some((open, close))
}

/// The object-space primitives of a deforming mesh at shutter close, where
/// the scene has a shutter.
fn closing_prims(
    world: &hecs::World,
    entity: Entity,
    blur: bool,
    deforming: bool,
    flip: bool,
) -> Option<Vec<Primitive>> {
    if !(blur && deforming) {
        return None;
    }
    let close = world.get::<&ClosingMesh>(entity).ok()?.0.clone();
    let mut prims = Vec::new();
    tessellate(
        &Geometry::Mesh(close),
        DMat4::IDENTITY,
        DVec3::ZERO,
        flip,
        true,
        &mut prims,
    );
    Some(geometric(&prims))
}

/// Bytes a bottom-level BVH takes per primitive while it is built, at
/// most (an estimate: the binary tree and its build's bounds and codes,
/// the wide tree, the reordered primitive data and the surface tables).
const BVH_BYTES_PER_PRIM: u64 = 512;

/// An error, before anything is built, where the BVH of `prims`
/// primitives would not fit in the memory available.
fn check_bvh_memory(file: &std::path::Path, prims: usize) -> Result<(), SceneError> {
    radiant_core::memory::check(prims as u64 * BVH_BYTES_PER_PRIM, || {
        format!("the acceleration structure of {prims} primitives")
    })
    .map_err(|e| {
        SceneError::new(
            file,
            None,
            format!("{e}: render fewer or simpler shapes, or on a machine with more memory"),
        )
    })
}
