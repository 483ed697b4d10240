//! Transforms written in scenes.
//!
//! A `transform` is one operation or a list of them:
//! `translate: [x, y, z]`, `rotate: {axis: [x, y, z], angle: degrees}`,
//! `scale: s | [x, y, z]`, `matrix: [[row], [row], [row](, [0, 0, 0, 1])]`
//! (row-major, 3×4 or 4×4) and `look_at: {origin, target, up}`.
//! A list composes like Mitsuba's `T().translate(..).rotate(..).scale(..)`:
//! the matrices multiply left to right, so the *last* operation is applied
//! to points first.

use super::SceneError;
use super::yaml::{Mapping, loc, parse_node, unknown_key};
use glam::{DMat4, DVec3, DVec4};
use marked_yaml::Node;
use radiant_core::Numbers;
use serde::Deserialize;
use std::path::Path;

const OPS: &[&str] = &["translate", "rotate", "scale", "matrix", "look_at"];

#[derive(Deserialize)]
#[serde(
    deny_unknown_fields,
    expecting = "a rotation `{axis: [x, y, z], angle: degrees}`"
)]
struct Rotate {
    axis: Numbers<3>,
    angle: f64,
}

/// The camera-style `look_at` pose.
#[derive(Deserialize, Debug, Clone, Copy)]
#[serde(deny_unknown_fields)]
pub(crate) struct LookAt {
    origin: Numbers<3>,
    target: Numbers<3>,
    #[serde(default = "y_up")]
    up: Numbers<3>,
}

fn y_up() -> Numbers<3> {
    Numbers([0.0, 1.0, 0.0])
}

impl LookAt {
    /// Mitsuba's look-at matrix: columns (left, up, forward, origin).
    pub(crate) fn matrix(&self) -> Option<DMat4> {
        crate::world::systems::look_at(self.origin.into(), self.target.into(), self.up.into())
    }
}

/// Parses a `look_at` mapping.
pub(crate) fn parse_look_at(file: &Path, node: &Node) -> Result<DMat4, SceneError> {
    let look: LookAt = parse_node(file, node)?;
    look.matrix().ok_or_else(|| {
        SceneError::new(
            file,
            loc(node.span()),
            "look_at needs a target different from the origin and an `up` not parallel to the view direction",
        )
    })
}

/// Parses a `transform` value: one operation or a list of them.
pub(crate) fn parse_transform(file: &Path, node: &Node) -> Result<DMat4, SceneError> {
    match node {
        Node::Sequence(seq) => seq
            .iter()
            .try_fold(DMat4::IDENTITY, |m, op| Ok(m * parse_op(file, op)?)),
        _ => parse_op(file, node),
    }
}

fn parse_op(file: &Path, node: &Node) -> Result<DMat4, SceneError> {
    let map = Mapping::new(file, node, "transform operation")?;
    let entries: Vec<_> = node
        .as_mapping()
        .map(|m| m.iter().collect())
        .unwrap_or_default();
    if entries.len() != 1 {
        return Err(SceneError::new(
            file,
            map.location(),
            format!(
                "each transform operation is a mapping with one key, one of: {}",
                OPS.join(", ")
            ),
        ));
    }
    let (key, value) = entries[0];
    let m = match key.as_str() {
        "translate" => {
            let t: Numbers<3> = parse_node(file, value)?;
            DMat4::from_translation(t.into())
        }
        "rotate" => {
            let r: Rotate = parse_node(file, value)?;
            let axis = DVec3::from(r.axis).try_normalize().ok_or_else(|| {
                SceneError::new(
                    file,
                    loc(value.span()),
                    "the rotation axis must not be zero",
                )
            })?;
            DMat4::from_axis_angle(axis, r.angle.to_radians())
        }
        "scale" => {
            let s = match value.as_scalar() {
                Some(_) => DVec3::splat(parse_node::<f64>(file, value)?),
                None => parse_node::<Numbers<3>>(file, value)?.into(),
            };
            DMat4::from_scale(s)
        }
        "matrix" => parse_matrix(file, value)?,
        "look_at" => parse_look_at(file, value)?,
        other => {
            return Err(unknown_key(
                file,
                other,
                loc(key.span()),
                "transform operation",
                OPS,
            ));
        }
    };
    if !m.is_finite() || m.determinant() == 0.0 {
        return Err(SceneError::new(
            file,
            loc(value.span()),
            "the transform must be finite and invertible",
        ));
    }
    Ok(m)
}

fn parse_matrix(file: &Path, node: &Node) -> Result<DMat4, SceneError> {
    let rows: Vec<Numbers<4>> = parse_node(file, node)?;
    let last = DVec4::new(0.0, 0.0, 0.0, 1.0);
    let rows: Vec<DVec4> = rows.into_iter().map(DVec4::from).collect();
    match rows.len() {
        3 => {}
        4 if rows[3] == last => {}
        _ => {
            return Err(SceneError::new(
                file,
                loc(node.span()),
                "a matrix is 3 or 4 rows of 4 numbers, row-major; a 4th row must be [0, 0, 0, 1]",
            ));
        }
    }
    Ok(DMat4::from_cols(rows[0], rows[1], rows[2], last).transpose())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scene::yaml::parse_document;

    fn transform(text: &str) -> Result<DMat4, SceneError> {
        let doc = parse_document(Path::new("t.yaml"), text).unwrap();
        let node = doc
            .as_mapping()
            .unwrap()
            .get_node("transform")
            .unwrap()
            .clone();
        parse_transform(Path::new("t.yaml"), &node)
    }

    #[test]
    fn list_composes_like_mitsuba() {
        let m = transform(
            "transform:\n  - translate: [1, 2, 3]\n  - rotate: {axis: [0, 1, 0], angle: 90}\n  - scale: 2\n",
        )
        .unwrap();
        // The point (1,0,0) is scaled to (2,0,0), rotated to (0,0,-2), then translated.
        let p = m.transform_point3(DVec3::X);
        assert!((p - DVec3::new(1.0, 2.0, 1.0)).length() < 1e-12, "{p}");
    }

    #[test]
    fn matrix_is_row_major() {
        let m =
            transform("transform:\n  matrix: [[0.3, 0, 0, 0.5], [0, 1, 0, -1], [0, 0, 2, 3]]\n")
                .unwrap();
        assert_eq!(m.transform_point3(DVec3::ONE), DVec3::new(0.8, 0.0, 5.0));
    }

    #[test]
    fn bad_operations_are_reported_with_their_line() {
        let err = transform(
            "transform:\n  - translate: [1, 2, 3]\n  - rotat: {axis: [0, 1, 0], angle: 90}\n",
        )
        .unwrap_err();
        assert_eq!(err.location.unwrap().line, 3);
        assert!(
            err.message.contains("did you mean `rotate`"),
            "{}",
            err.message
        );
        let err = transform("transform:\n  scale: 0\n").unwrap_err();
        assert!(err.message.contains("invertible"));
        let err = transform("transform:\n  translate: [1, x, 3]\n").unwrap_err();
        assert_eq!(err.location.unwrap().line, 2);
    }
}
