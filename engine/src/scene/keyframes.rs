//! Keyframes in scene files.
//!
//! A value that changes over time is written as a mapping with
//! `keyframes` (and optionally `interpolation`):
//!
//! ```yaml
//! fov:
//!   interpolation: smooth          # step | linear (default) | smooth
//!   keyframes:
//!     - {frame: 1, value: 40}      # or {time: 0.0, value: 40} in seconds
//!     - {frame: 48, value: 25}
//! ```
//!
//! Numbers and colours of cameras, lights, materials and textures may be
//! written so ([`KeyframeReader::module_tracks`]); so may the translate,
//! rotate and scale tracks of a shape's, light's or camera's `animation:`
//! and the points of a camera's `look_at`. Every `keyframes` mapping the
//! loader reads is recorded, and [`KeyframeReader::check_all_read`] reports
//! any other one as a value that cannot animate.

use super::SceneError;
use super::yaml::{Mapping, loc, parse_node};
use crate::world::{
    Interpolation, Key, Keyable, ModuleSpec, ParamStep, ParamTrack, Track, TrackError,
    TransformTracks,
};
use glam::{DQuat, DVec3};
use marked_yaml::Node;
use radiant_core::Numbers;
use serde::Deserialize;
use std::collections::HashSet;
use std::path::Path;

/// Whether `node` is a `keyframes` mapping.
pub(crate) fn is_keyframes(node: &Node) -> bool {
    node.as_mapping()
        .is_some_and(|m| m.get_node("keyframes").is_some())
}

/// Where a node starts, as a key for the set of read keyframes.
fn start_of(node: &Node) -> Option<(usize, usize)> {
    node.span().start().map(|m| (m.line(), m.column()))
}

/// Reads keyframes for one scene file.
pub(crate) struct KeyframeReader<'f> {
    file: &'f Path,
    fps: f64,
    /// Starts of the `keyframes` mappings read so far.
    read: HashSet<(usize, usize)>,
    /// The earliest and latest key, in frames.
    span: Option<(f64, f64)>,
}

impl<'f> KeyframeReader<'f> {
    /// A reader for `file` at `fps` frames per second.
    pub(crate) fn new(file: &'f Path, fps: f64) -> Self {
        Self {
            file,
            fps,
            read: HashSet::new(),
            span: None,
        }
    }

    /// The earliest and latest key seen, in frames.
    pub(crate) fn key_span(&self) -> Option<(f64, f64)> {
        self.span
    }

    fn error(&self, node: &Node, message: impl Into<String>) -> SceneError {
        SceneError::new(self.file, loc(node.span()), message)
    }

    /// Reads the track at `node`, whose key values `value` parses.
    pub(crate) fn track<T: Keyable>(
        &mut self,
        node: &Node,
        value: &mut dyn FnMut(&Node) -> Result<T, SceneError>,
    ) -> Result<Track<T>, SceneError> {
        let mut map = Mapping::new(self.file, node, "keyframes")?;
        let keys_node = map.require("keyframes")?;
        let interpolation = match map.get("interpolation") {
            None => Interpolation::default(),
            Some(n) => {
                let name = n.as_scalar().map(|s| s.as_str()).unwrap_or_default();
                Interpolation::from_name(name).ok_or_else(|| {
                    self.error(
                        n,
                        format!(
                            "unknown interpolation `{name}`; allowed: {}",
                            Interpolation::NAMES.join(", ")
                        ),
                    )
                })?
            }
        };
        map.finish(&["keyframes", "interpolation"])?;
        let seq = keys_node.as_sequence().ok_or_else(|| {
            self.error(
                keys_node,
                "`keyframes` must be a list of keys such as `- {frame: 1, value: 0.5}`",
            )
        })?;
        let mut keys = Vec::with_capacity(seq.len());
        for key in seq.iter() {
            let mut m = Mapping::new(self.file, key, "key")?;
            let time = match (m.get("frame"), m.get("time")) {
                (Some(f), None) => parse_node::<f64>(self.file, f)? / self.fps,
                (None, Some(t)) => parse_node::<f64>(self.file, t)?,
                _ => {
                    return Err(self.error(
                        key,
                        "a key needs either a `frame` or a `time` (seconds), not both",
                    ));
                }
            };
            let v = m.require("value")?;
            m.finish(&["frame", "time", "value"])?;
            if !time.is_finite() {
                return Err(self.error(key, "a key's time must be a finite number"));
            }
            let frame = time * self.fps;
            self.span = Some(match self.span {
                None => (frame, frame),
                Some((lo, hi)) => (lo.min(frame), hi.max(frame)),
            });
            keys.push(Key {
                time,
                value: value(v)?,
            });
        }
        let track = Track::new(keys, interpolation).map_err(|e| match e {
            TrackError::OutOfOrder { index, .. } => self.error(
                &seq[index],
                format!(
                    "keys must be in strictly increasing time order: key {} is at frame {} and the key before it at frame {}",
                    index + 1,
                    seq_frame(&seq[index], self),
                    seq_frame(&seq[index - 1], self)
                ),
            ),
            other => self.error(keys_node, other.to_string()),
        })?;
        if let Some(start) = start_of(node) {
            self.read.insert(start);
        }
        Ok(track)
    }

    /// A track at `node`, or a constant where `node` is a plain value.
    pub(crate) fn value_or_track<T: Keyable>(
        &mut self,
        node: &Node,
        value: &mut dyn FnMut(&Node) -> Result<T, SceneError>,
    ) -> Result<Track<T>, SceneError> {
        if is_keyframes(node) {
            self.track(node, value)
        } else {
            Ok(Track::constant(value(node)?))
        }
    }

    /// The `animation:` tracks of a shape, light or camera at `node`.
    pub(crate) fn transform_tracks(&mut self, node: &Node) -> Result<TransformTracks, SceneError> {
        let file = self.file;
        let mut map = Mapping::new(file, node, "animation")?;
        let (t, r, s) = (map.get("translate"), map.get("rotate"), map.get("scale"));
        map.finish(&["translate", "rotate", "scale"])?;
        let mut tracks = TransformTracks::default();
        if let Some(n) = t {
            tracks.translate = Some(self.value_or_track(n, &mut |v| point(file, v))?);
        }
        if let Some(n) = r {
            tracks.rotate = Some(self.value_or_track(n, &mut |v| rotation(file, v))?);
        }
        if let Some(n) = s {
            tracks.scale = Some(self.value_or_track(n, &mut |v| scale(file, v))?);
        }
        Ok(tracks)
    }

    /// Takes the animated parameters out of `spec`: every `keyframes`
    /// mapping among its parameters becomes a [`ParamTrack`], and the node
    /// its first key's value (the animation system writes the value of
    /// each frame there).
    pub(crate) fn module_tracks(&mut self, spec: &mut ModuleSpec) -> Result<(), SceneError> {
        let mut tracks = Vec::new();
        let mut path = Vec::new();
        self.find_tracks(spec.params.node_mut(), &mut path, &mut tracks)?;
        spec.tracks = tracks;
        Ok(())
    }

    fn find_tracks(
        &mut self,
        node: &mut Node,
        path: &mut Vec<ParamStep>,
        out: &mut Vec<ParamTrack>,
    ) -> Result<(), SceneError> {
        if is_keyframes(node) && !path.is_empty() {
            let file = self.file;
            let mut scalar = None;
            let track = self.track(node, &mut |v| numbers(file, v, &mut scalar))?;
            let span = *node.span();
            let track = ParamTrack {
                path: path.clone(),
                track,
                scalar: scalar.unwrap_or(true),
                span,
            };
            *node = track.node(&track.track.keys()[0].value);
            out.push(track);
            return Ok(());
        }
        match node {
            Node::Mapping(m) => {
                for (k, v) in m.iter_mut() {
                    path.push(ParamStep::Key(k.as_str().to_string()));
                    self.find_tracks(v, path, out)?;
                    path.pop();
                }
            }
            Node::Sequence(s) => {
                for (i, v) in s.iter_mut().enumerate() {
                    path.push(ParamStep::Index(i));
                    self.find_tracks(v, path, out)?;
                    path.pop();
                }
            }
            Node::Scalar(_) => {}
        }
        Ok(())
    }

    /// Fails on the first `keyframes` mapping in `doc` that was not read:
    /// one at a place that cannot animate.
    pub(crate) fn check_all_read(&self, doc: &Node) -> Result<(), SceneError> {
        if is_keyframes(doc) && !start_of(doc).is_some_and(|s| self.read.contains(&s)) {
            return Err(cannot_animate(self.file, doc));
        }
        match doc {
            Node::Mapping(m) => m.values().try_for_each(|v| self.check_all_read(v)),
            Node::Sequence(s) => s.iter().try_for_each(|v| self.check_all_read(v)),
            Node::Scalar(_) => Ok(()),
        }
    }
}

/// The error for `keyframes` at `node`, a place that cannot animate.
pub(crate) fn cannot_animate(file: &Path, node: &Node) -> SceneError {
    SceneError::new(
        file,
        loc(node.span()),
        "this value cannot animate: `keyframes` may give the numbers and colours of \
         cameras, lights, materials and textures, the points of a camera's `look_at`, \
         and the `translate`, `rotate` and `scale` tracks of an `animation:` on a shape, \
         light or camera",
    )
}

/// The first `keyframes` mapping in `node`, if any.
pub(crate) fn find_keyframes(node: &Node) -> Option<&Node> {
    if is_keyframes(node) {
        return Some(node);
    }
    match node {
        Node::Mapping(m) => m.values().find_map(find_keyframes),
        Node::Sequence(s) => s.iter().find_map(find_keyframes),
        Node::Scalar(_) => None,
    }
}

/// The frame a key was written at, for messages.
fn seq_frame(key: &Node, reader: &KeyframeReader<'_>) -> String {
    let m = key.as_mapping();
    if let Some(f) = m.and_then(|m| m.get_scalar("frame")) {
        return f.as_str().to_string();
    }
    if let Some(t) = m
        .and_then(|m| m.get_scalar("time"))
        .and_then(|t| t.as_str().parse::<f64>().ok())
    {
        return format!("{} (time {t} s)", t * reader.fps);
    }
    "?".into()
}

/// A key value of a module parameter: a number or a list of numbers, the
/// same kind and length in every key (`scalar` remembers which).
fn numbers(file: &Path, node: &Node, scalar: &mut Option<bool>) -> Result<Vec<f64>, SceneError> {
    let cannot = || {
        SceneError::new(
            file,
            loc(node.span()),
            "this parameter cannot animate: keyframe values must be numbers or lists of numbers",
        )
    };
    let (values, is_scalar) = match node {
        Node::Scalar(s) => (vec![s.as_str().parse::<f64>().map_err(|_| cannot())?], true),
        Node::Sequence(seq) => {
            let values = seq
                .iter()
                .map(|v| {
                    v.as_scalar()
                        .and_then(|s| s.as_str().parse::<f64>().ok())
                        .ok_or_else(cannot)
                })
                .collect::<Result<Vec<f64>, _>>()?;
            (values, false)
        }
        Node::Mapping(_) => return Err(cannot()),
    };
    if values.iter().any(|v| !v.is_finite()) {
        return Err(SceneError::new(
            file,
            loc(node.span()),
            "keyframe values must be finite numbers",
        ));
    }
    match scalar {
        Some(s) if *s != is_scalar => {
            return Err(SceneError::new(
                file,
                loc(node.span()),
                "every key of a track must hold the same kind of value (all numbers or all lists)",
            ));
        }
        _ => *scalar = Some(is_scalar),
    }
    Ok(values)
}

/// A point `[x, y, z]`.
pub(crate) fn point(file: &Path, node: &Node) -> Result<DVec3, SceneError> {
    Ok(parse_node::<Numbers<3>>(file, node)?.into())
}

/// A scale: one number or `[x, y, z]`, none of them zero.
fn scale(file: &Path, node: &Node) -> Result<DVec3, SceneError> {
    let s = match node.as_scalar() {
        Some(_) => DVec3::splat(parse_node::<f64>(file, node)?),
        None => point(file, node)?,
    };
    if !(s.is_finite() && s.x * s.y * s.z != 0.0) {
        return Err(SceneError::new(
            file,
            loc(node.span()),
            "a scale must be finite and not zero",
        ));
    }
    Ok(s)
}

#[derive(Deserialize)]
#[serde(
    deny_unknown_fields,
    expecting = "a rotation `{axis: [x, y, z], angle: degrees}` or a quaternion `[x, y, z, w]`"
)]
struct AxisAngle {
    axis: Numbers<3>,
    angle: f64,
}

/// A rotation: `{axis: [x, y, z], angle: degrees}` or a quaternion
/// `[x, y, z, w]` (normalised).
fn rotation(file: &Path, node: &Node) -> Result<DQuat, SceneError> {
    let at = |message: &str| SceneError::new(file, loc(node.span()), message);
    if node.as_sequence().is_some() {
        let q: Numbers<4> = parse_node(file, node)?;
        let [x, y, z, w] = q.0;
        let q = DQuat::from_xyzw(x, y, z, w);
        let length = q.length();
        if !(length > 0.0 && length.is_finite()) {
            return Err(at("a quaternion must be finite and not zero"));
        }
        return Ok(q / length);
    }
    let r: AxisAngle = parse_node(file, node)?;
    let axis = DVec3::from(r.axis)
        .try_normalize()
        .ok_or_else(|| at("the rotation axis must not be zero"))?;
    if !r.angle.is_finite() {
        return Err(at("the rotation angle must be finite"));
    }
    Ok(DQuat::from_axis_angle(axis, r.angle.to_radians()))
}
