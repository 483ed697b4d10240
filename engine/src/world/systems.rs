//! Systems: plain functions over the scene's world that move it to a
//! frame. Each reads the animation components the loader attached and
//! writes the components extract reads — transforms and poses, the
//! camera's pose and motion, module parameters, deforming meshes.
//! [`animate`] runs them all.

use super::animation::{TransformTracks, Trs};
use super::components::{
    Animation, BaseTransform, CameraAnimation, CameraMotion, CameraPose, ClosingMesh, EmitterSpec,
    Geometry, LightSpec, MeshData, MeshSequence, ModuleSpec, ParamStep, Pose, Transform,
};
use super::resources::{FrameTimes, Scene, Timeline};
use crate::error::SceneError;
use glam::{DMat4, DVec3};
use hecs::World;
use marked_yaml::Node;
use marked_yaml::types::MarkedScalarNode;
use std::path::Path;
use std::sync::Arc;

/// Moves `scene` to frame `frame`: every system below, in order.
///
/// # Errors
///
/// When a deforming mesh's file for the frame cannot be read or does not
/// have the sequence's triangles.
pub fn animate(scene: &mut Scene, frame: i64) -> Result<(), SceneError> {
    let times = scene.timeline.times(frame);
    scene.frame = frame;
    animate_transforms(&mut scene.world, &times);
    animate_camera(&mut scene.world, &times);
    for spec in module_specs(scene) {
        animate_params(spec, times.time);
    }
    deform_meshes(&mut scene.world, &scene.file, &scene.timeline, &times)
}

/// Every module spec that may animate: the camera's, the lights' (free and
/// on shapes), the named textures' and the materials'.
fn module_specs(scene: &mut Scene) -> impl Iterator<Item = &mut ModuleSpec> {
    let world = &mut scene.world;
    let mut specs: Vec<&mut ModuleSpec> = Vec::new();
    for (camera, light, emitter) in world
        .query_mut::<(
            Option<&mut CameraPose>,
            Option<&mut LightSpec>,
            Option<&mut EmitterSpec>,
        )>()
        .into_iter()
    {
        specs.extend(camera.map(|c| &mut c.module));
        specs.extend(light.map(|l| &mut l.0));
        specs.extend(emitter.map(|e| &mut e.0));
    }
    specs.extend(scene.textures.iter_mut().map(|(_, s)| s));
    specs.extend(scene.materials.iter_mut().map(|(_, s)| s));
    specs.into_iter()
}

/// The pose of `tracks` at the frame and, where it moves while the shutter
/// is open, at shutter open and close.
fn pose(tracks: &TransformTracks, times: &FrameTimes) -> Pose {
    let shutter = times
        .shutter
        .map(|(open, close)| (tracks.at(open), tracks.at(close)))
        .filter(|(open, close)| open != close);
    Pose {
        frame: tracks.at(times.time),
        shutter,
    }
}

/// Writes the [`Pose`] and [`Transform`] of every entity with an
/// [`Animation`]: pose(t) · [`BaseTransform`].
pub fn animate_transforms(world: &mut World, times: &FrameTimes) {
    for (animation, base, transform, p) in
        world.query_mut::<(&Animation, &BaseTransform, &mut Transform, &mut Pose)>()
    {
        *p = pose(&animation.0, times);
        transform.0 = p.frame.matrix() * base.0;
    }
}

/// Mitsuba's look-at matrix (columns: left, up, forward, origin), `None`
/// where the target is the origin or `up` is parallel to the view.
pub fn look_at(origin: DVec3, target: DVec3, up: DVec3) -> Option<DMat4> {
    let dir = (target - origin).try_normalize()?;
    let left = up.cross(dir).try_normalize()?;
    let up = dir.cross(left);
    Some(DMat4::from_cols(
        left.extend(0.0),
        up.extend(0.0),
        dir.extend(0.0),
        origin.extend(1.0),
    ))
}

/// The camera's pose at `time` (`None` where a look-at degenerates).
fn camera_at(animation: &CameraAnimation, time: f64) -> Option<DMat4> {
    match animation {
        CameraAnimation::LookAt { origin, target, up } => {
            look_at(origin.at(time), target.at(time), up.at(time))
        }
        CameraAnimation::Tracks { base, tracks } => Some(tracks.at(time).matrix() * *base),
    }
}

/// The camera's pose (camera to world) at `time` seconds, `None` where the
/// world has no camera.
pub fn camera_to_world_at(world: &World, time: f64) -> Option<DMat4> {
    let mut query = world.query::<(&CameraPose, Option<&CameraAnimation>)>();
    let (pose, animation) = query.iter().next()?;
    Some(
        animation
            .and_then(|a| camera_at(a, time))
            .unwrap_or(pose.to_world),
    )
}

/// Writes the camera's [`CameraPose`] at the frame and its
/// [`CameraMotion`] over the shutter. A look-at whose target meets its
/// origin at some time keeps the pose it had before.
pub fn animate_camera(world: &mut World, times: &FrameTimes) {
    for (animation, pose, motion) in
        world.query_mut::<(&CameraAnimation, &mut CameraPose, &mut CameraMotion)>()
    {
        if let Some(m) = camera_at(animation, times.time) {
            pose.to_world = m;
        }
        let (open, close) = match times.shutter {
            Some((open, close)) => (
                camera_at(animation, open).unwrap_or(pose.to_world),
                camera_at(animation, close).unwrap_or(pose.to_world),
            ),
            None => (pose.to_world, pose.to_world),
        };
        *motion = CameraMotion { open, close };
    }
}

/// Evaluates the animated parameters of `spec` at `time` into its
/// parameters, and counts a revision where a value changed.
pub fn animate_params(spec: &mut ModuleSpec, time: f64) {
    let mut changed = false;
    for track in &spec.tracks {
        let node = track.node(&track.track.at(time));
        let Some(slot) = node_at(spec.params.node_mut(), &track.path) else {
            continue;
        };
        if *slot != node {
            *slot = node;
            changed = true;
        }
    }
    if changed {
        spec.revision += 1;
    }
}

/// The node at `path` below `node`.
fn node_at<'a>(node: &'a mut Node, path: &[ParamStep]) -> Option<&'a mut Node> {
    let Some((step, rest)) = path.split_first() else {
        return Some(node);
    };
    let child = match step {
        ParamStep::Key(key) => {
            let key = MarkedScalarNode::new(marked_yaml::Span::new_blank(), key.as_str());
            node.as_mapping_mut()?.get_mut(&key)?
        }
        ParamStep::Index(i) => node.as_sequence_mut()?.get_mut(*i)?,
    };
    node_at(child, rest)
}

/// The path of frame `frame` of a mesh sequence: the run of `#` in the
/// file name becomes the frame number, zero-padded to the run's length
/// (as in Blender).
pub fn sequence_path(pattern: &Path, frame: i64) -> std::path::PathBuf {
    let name = pattern
        .file_name()
        .map(|n| n.to_string_lossy().into_owned())
        .unwrap_or_default();
    pattern.with_file_name(substitute_frame(&name, frame))
}

/// `text` with its (first) run of `#` replaced by `frame`, zero-padded to
/// the run's length; `text` itself where it has no `#`.
pub fn substitute_frame(text: &str, frame: i64) -> String {
    let Some(start) = text.find('#') else {
        return text.to_string();
    };
    let len = text[start..].chars().take_while(|&c| c == '#').count();
    let number = if frame < 0 {
        format!("-{:0len$}", -frame, len = len.saturating_sub(1))
    } else {
        format!("{frame:0len$}")
    };
    format!("{}{number}{}", &text[..start], &text[start + len..])
}

/// The mesh of a sequence at frame position `at` (fractional between
/// files: positions and the file's normals blend linearly, computed
/// normals are computed from the blend), clamped to the
/// timeline's frames.
fn mesh_at(
    sequence: &MeshSequence,
    scene_file: &Path,
    timeline: &Timeline,
    at: f64,
) -> Result<Arc<MeshData>, SceneError> {
    let at = at.clamp(timeline.start as f64, timeline.end as f64);
    let (lo, hi) = (at.floor() as i64, at.ceil() as i64);
    let load = |frame: i64| load_frame(sequence, scene_file, frame);
    let a = load(lo)?;
    if hi == lo {
        return Ok(a);
    }
    let b = load(hi)?;
    let s = (at - lo as f64) as f32;
    let mut mesh = (*a).clone();
    for (p, q) in mesh.positions.iter_mut().zip(&b.positions) {
        *p = p.lerp(*q, s);
    }
    if mesh.computed_normals {
        // Normals computed from each file's positions are computed again
        // from the blend's, as the file between the two would have them.
        mesh.normals = None;
        crate::scene::mesh::shade(&mut mesh, false);
    } else if let (Some(n), Some(m)) = (&mut mesh.normals, &b.normals) {
        for (n, m) in n.iter_mut().zip(m) {
            *n = n.lerp(*m, s).normalize_or_zero();
        }
    }
    Ok(Arc::new(mesh))
}

/// Reads frame `frame` of `sequence` and checks its triangles.
fn load_frame(
    sequence: &MeshSequence,
    scene_file: &Path,
    frame: i64,
) -> Result<Arc<MeshData>, SceneError> {
    let path = sequence_path(&sequence.pattern, frame);
    let at = |message: String| SceneError::new(scene_file, sequence.location, message);
    let mesh = crate::scene::mesh::load_frame(&path, sequence.options).map_err(at)?;
    crate::scene::mesh::check_topology(&sequence.topology, &mesh).map_err(at)?;
    Ok(Arc::new(mesh))
}

/// The files every deforming mesh reads for `frames` (with the frames
/// around them that a shutter reaches), clamped to the timeline.
fn sequence_frames(timeline: &Timeline, frames: &[i64]) -> Vec<i64> {
    let mut needed: Vec<i64> = Vec::new();
    for &f in frames {
        let times = timeline.times(f);
        let (open, close) = times.shutter.unwrap_or((times.time, times.time));
        let lo = (open * timeline.fps).floor() as i64;
        let hi = (close * timeline.fps).ceil() as i64;
        needed.extend((lo..=hi).map(|g| g.clamp(timeline.start, timeline.end)));
    }
    needed.sort_unstable();
    needed.dedup();
    needed
}

/// Checks, before anything is rendered, that every file the deforming
/// meshes read for `frames` exists.
///
/// # Errors
///
/// For the first missing file, at the mesh's `filename`.
pub fn check_mesh_files(scene: &Scene, frames: &[i64]) -> Result<(), SceneError> {
    let needed = sequence_frames(&scene.timeline, frames);
    for sequence in scene.world.query::<&MeshSequence>().iter() {
        for &f in &needed {
            let path = sequence_path(&sequence.pattern, f);
            if !path.is_file() {
                return Err(SceneError::new(
                    &scene.file,
                    sequence.location,
                    format!(
                        "the deforming mesh's file for frame {f}, `{}`, does not exist",
                        path.display()
                    ),
                ));
            }
        }
    }
    Ok(())
}

/// Writes the [`Geometry`] of every deforming mesh (a [`MeshSequence`]) at
/// the frame — at shutter open where the shutter is open, with the mesh at
/// shutter close in its [`ClosingMesh`].
///
/// # Errors
///
/// When a frame's file cannot be read or lacks the sequence's triangles.
pub fn deform_meshes(
    world: &mut World,
    scene_file: &Path,
    timeline: &Timeline,
    times: &FrameTimes,
) -> Result<(), SceneError> {
    let frame_of = |t: f64| t * timeline.fps;
    for (sequence, geometry, closing) in
        world.query_mut::<(&MeshSequence, &mut Geometry, &mut ClosingMesh)>()
    {
        match times.shutter {
            None => {
                let mesh = mesh_at(sequence, scene_file, timeline, frame_of(times.time))?;
                *geometry = Geometry::Mesh(mesh.clone());
                *closing = ClosingMesh(mesh);
            }
            Some((open, close)) => {
                let a = mesh_at(sequence, scene_file, timeline, frame_of(open))?;
                let b = mesh_at(sequence, scene_file, timeline, frame_of(close))?;
                *geometry = Geometry::Mesh(a);
                *closing = ClosingMesh(b);
            }
        }
    }
    Ok(())
}

/// The pose an entity without animation has.
impl Default for Pose {
    fn default() -> Self {
        Pose {
            frame: Trs::IDENTITY,
            shutter: None,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn frame_numbers_fill_the_run_of_hashes() {
        assert_eq!(substitute_frame("frame_####.png", 7), "frame_0007.png");
        assert_eq!(substitute_frame("f#.exr", 123), "f123.exr");
        assert_eq!(substitute_frame("a_##_b.obj", 5), "a_05_b.obj");
        assert_eq!(substitute_frame("###", -4), "-04");
        assert_eq!(substitute_frame("plain.png", 3), "plain.png");
        assert_eq!(
            sequence_path(Path::new("sim/x_###.obj"), 12),
            Path::new("sim/x_012.obj")
        );
    }
}
