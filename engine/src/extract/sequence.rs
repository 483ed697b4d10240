//! A scene rendered frame by frame: built once, then moved from frame to
//! frame by the world's systems and the per-frame half of extract.
//!
//! A frame's render data depend only on the scene and the frame — not on
//! which frames came before — so frame N of a sequence renders the same
//! image as frame N alone: render space is anchored at the camera's
//! position at the scene's first frame (whichever frame is rendered
//! first), and each frame's seed derives from the base seed and the frame
//! number ([`RenderSettings::frame_seed`]).

use super::geometry::{GeometryUpdate, SceneGeometry};
use super::modules::ModuleState;
use super::{Overrides, RenderScene, SceneStats};
use crate::accel::{Motion, Place, UpdatePolicy};
use crate::error::SceneError;
use crate::settings::RenderSettings;
use crate::world::{CameraMotion, Scene, Trs, systems};
use glam::{DMat4, DVec3};
use radiant_core::{Effects, ModuleKind, Registry};
use std::collections::BTreeSet;
use std::time::{Duration, Instant};

/// How a sequence renders its frames.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct SequenceOptions {
    /// Every frame uses the base seed (the same noise pattern in every
    /// frame, for A/B comparisons); otherwise each frame has its own.
    pub lock_noise: bool,
    /// When refitted hierarchies are rebuilt.
    pub policy: UpdatePolicy,
}

/// What moving to a frame took.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct FrameUpdate {
    /// The frame.
    pub frame: i64,
    /// Time spent in the systems and in extract, the BVH update included.
    pub update: Duration,
    /// Of which updating bottom and top levels.
    pub bvh: Duration,
    /// What the geometry update did.
    pub geometry: GeometryUpdate,
    /// Modules built again for the frame.
    pub modules_rebuilt: usize,
}

/// A scene's render data, kept from frame to frame.
pub struct Sequence {
    render: RenderScene,
    geometry: SceneGeometry,
    modules: ModuleState,
    /// The settings with overrides, before the frame's seed.
    settings: RenderSettings,
    options: SequenceOptions,
    start: i64,
    render_origin: DVec3,
}

/// The error for a frame outside the scene's range.
fn outside(scene: &Scene, frame: i64) -> SceneError {
    let t = &scene.timeline;
    SceneError::new(
        &scene.file,
        None,
        format!(
            "frame {frame} is outside the scene's frames {}..{} (set them with `animation: {{frames: [first, last]}}`)",
            t.start, t.end
        ),
    )
}

impl Sequence {
    /// Moves `scene` to `frame` and builds its render data.
    ///
    /// # Errors
    ///
    /// Where the frame is outside the scene's frames, a file cannot be
    /// read, or a module rejects its parameters.
    pub fn new(
        scene: &mut Scene,
        registry: &Registry,
        overrides: &Overrides,
        options: &SequenceOptions,
        frame: i64,
    ) -> Result<(Self, FrameUpdate), SceneError> {
        if !scene.timeline.contains(frame) {
            return Err(outside(scene, frame));
        }
        let start = Instant::now();
        systems::animate(scene, frame)?;
        let sequence = build(scene, registry, overrides, options)?;
        let update = FrameUpdate {
            frame,
            update: start.elapsed(),
            bvh: sequence.render.stats.bvh_build,
            ..FrameUpdate::default()
        };
        Ok((sequence, update))
    }

    /// Moves `scene` and the render data to `frame`, rebuilding only what
    /// changed.
    ///
    /// # Errors
    ///
    /// As [`Sequence::new`].
    pub fn go_to(
        &mut self,
        scene: &mut Scene,
        registry: &Registry,
        frame: i64,
    ) -> Result<FrameUpdate, SceneError> {
        if !scene.timeline.contains(frame) {
            return Err(outside(scene, frame));
        }
        let start = Instant::now();
        systems::animate(scene, frame)?;
        let render = &mut self.render;
        render.frame = frame;
        render.settings.seed = self
            .settings
            .frame_seed(frame - self.start, self.options.lock_noise);
        let (moved, geometry) =
            self.geometry
                .update(scene, &mut render.accel, &mut render.surfaces)?;
        let sphere = self.geometry.scene_sphere(&render.accel);
        let modules_rebuilt = self
            .modules
            .update(scene, registry, render, moved, sphere)?;
        render.camera_motion = camera_motion(scene, self.render_origin);
        render.effects = effects(render);
        render.stats.bvh_build = geometry.bvh;
        Ok(FrameUpdate {
            frame,
            update: start.elapsed(),
            bvh: geometry.bvh,
            geometry,
            modules_rebuilt,
        })
    }

    /// The render data of the current frame.
    pub fn scene(&self) -> &RenderScene {
        &self.render
    }

    /// The render data of the current frame, to change settings that need
    /// no rebuild (tools that compare settings).
    pub fn scene_mut(&mut self) -> &mut RenderScene {
        &mut self.render
    }

    /// The render data, for a render of this frame alone.
    pub fn into_render_scene(self) -> RenderScene {
        self.render
    }
}

/// Builds the render data of `scene` at the frame its systems last moved
/// it to.
pub(super) fn build(
    scene: &Scene,
    registry: &Registry,
    overrides: &Overrides,
    options: &SequenceOptions,
) -> Result<Sequence, SceneError> {
    let base = scene
        .settings
        .with(overrides)
        .map_err(|e| SceneError::new(&scene.file, None, e.to_string()))?;
    let timeline = &scene.timeline;
    let frame = scene.frame;
    let mut settings = base;
    settings.seed = base.frame_seed(frame - timeline.start, options.lock_noise);
    // Render space: the camera's position at the scene's first frame.
    let first = timeline.times(timeline.start).time;
    let render_origin = systems::camera_to_world_at(&scene.world, first)
        .ok_or_else(|| SceneError::new(&scene.file, None, "the scene has no camera"))?
        .w_axis
        .truncate();
    let mut stats = SceneStats::default();
    let super::geometry::Built {
        geometry,
        accel,
        surfaces,
        instance_material,
        emitters,
    } = SceneGeometry::build(
        scene,
        render_origin,
        overrides.bvh,
        options.policy,
        &mut stats,
    )?;
    let sphere = geometry.scene_sphere(&accel);
    let (modules, mut initial) =
        ModuleState::build(scene, registry, &settings, render_origin, emitters, sphere)?;
    let media = super::MediaTable::build(
        scene,
        registry,
        render_origin,
        &initial.shaders,
        &mut initial.modules,
    )?;
    let integrator = build_integrator(scene, registry, &mut initial.modules)?;
    let mut render = RenderScene {
        settings,
        frame,
        accel,
        surfaces,
        instance_material,
        shaders: initial.shaders,
        material_names: scene.materials.iter().map(|(n, _)| n.clone()).collect(),
        material_types: scene
            .materials
            .iter()
            .map(|(_, spec)| spec.type_name.clone())
            .collect(),
        light_types: modules.light_types(scene),
        texture_names: modules.texture_names(scene),
        lights: initial.lights,
        camera: initial.camera,
        camera_motion: camera_motion(scene, render_origin),
        render_origin,
        filter: initial.filter,
        sampler: initial.sampler,
        integrator,
        textures: initial.textures,
        media,
        effects: Effects::empty(),
        modules: initial.modules,
        stats,
    };
    render.effects = effects(&render);
    render
        .integrator
        .check(&render)
        .map_err(|m| SceneError::new(&scene.file, scene.integrator.location, m))?;
    Ok(Sequence {
        render,
        geometry,
        modules,
        settings: base,
        options: *options,
        start: timeline.start,
        render_origin,
    })
}

/// The scene's integrator, built through the registry (an unknown type
/// is an error listing the registered ones, at the `type`'s location).
fn build_integrator(
    scene: &Scene,
    registry: &Registry,
    modules: &mut BTreeSet<(ModuleKind, String)>,
) -> Result<Box<dyn crate::integrators::Integrator>, SceneError> {
    let spec = &scene.integrator;
    let mut textures = radiant_core::TextureTable::default();
    let names = std::collections::HashMap::new();
    let mut ctx = radiant_core::BuildContext::standalone(&scene.dir, &mut textures, &names);
    let integrator = registry
        .build::<dyn crate::integrators::Integrator>(&spec.type_name, &spec.params, &mut ctx)
        .map_err(|e| crate::error::module_error(&scene.file, spec, e))?;
    modules.insert((ModuleKind::Integrator, spec.type_name.clone()));
    Ok(integrator)
}

/// The frame's effect set: what its modules declare, and motion blur where
/// anything moves while the shutter is open.
fn effects(render: &RenderScene) -> Effects {
    let mut effects = render.camera.effects();
    for s in &render.shaders {
        effects |= s.effects();
    }
    for l in render.lights.lights() {
        effects |= l.effects();
    }
    let moving = render.camera_motion.is_some()
        || render
            .accel
            .instances()
            .iter()
            .any(|i| matches!(i.place, Place::Moving(_)))
        || render.accel.blases().iter().any(|b| b.deforms());
    if moving {
        effects |= Effects::MOTION_BLUR;
    }
    if render.media.in_use() {
        effects |= Effects::MEDIA;
    }
    effects
}

/// The camera's motion over the shutter in render space, as the transform
/// from its pose at the frame to its pose at shutter time τ.
fn camera_motion(scene: &Scene, render_origin: DVec3) -> Option<Motion> {
    let mut query = scene
        .world
        .query::<(&CameraMotion, &crate::world::CameraPose)>();
    let (motion, pose) = query.iter().next()?;
    if motion.open == motion.close || scene.timeline.shutter.is_none() {
        return None;
    }
    let decompose = |m: DMat4| {
        let (scale, rotate, translate) = m.to_scale_rotation_translation();
        Trs {
            translate,
            rotate,
            scale,
        }
    };
    let shift = DMat4::from_translation(-render_origin);
    Some(Motion {
        outer: shift,
        open: decompose(motion.open),
        close: decompose(motion.close),
        inner: pose.to_world.inverse() * shift.inverse(),
    })
}
