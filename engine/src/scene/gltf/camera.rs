//! A glTF camera as the YAML of a Radiant `perspective` camera.

use super::asset::Asset;
use super::{generated, list};
use crate::scene::yaml::{Mapping, loc};
use glam::{DMat4, DVec3};
use marked_yaml::Node;
use std::path::Path;

/// The camera mapping that a `camera: {type: gltf, filename: …}` stands
/// for: the first perspective camera among the default scene's nodes, as
/// a `perspective` camera placed by its node (glTF cameras look down −z
/// with +x to the right; Radiant's look down +z with +x to the left).
pub(in crate::scene) fn camera_yaml(
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

/// A matrix as the `matrix:` rows of a transform.
fn matrix_yaml(m: DMat4) -> String {
    let rows: Vec<String> = (0..4).map(|r| list(&m.row(r).to_array())).collect();
    format!("{{matrix: [{}]}}", rows.join(", "))
}
