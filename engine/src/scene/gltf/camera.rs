//! A glTF camera as the YAML of a Radiant `perspective` or `orthographic`
//! camera.

use super::asset::Asset;
use super::{generated, list};
use crate::scene::yaml::{Mapping, loc};
use glam::{DMat4, DVec3};
use marked_yaml::Node;
use std::path::Path;

/// The camera mapping that a `camera: {type: gltf, filename: …}` stands
/// for: the first camera among the default scene's nodes, as a
/// `perspective` camera with its vertical field of view or an
/// `orthographic` one `2 · xmag` wide, placed by its node (glTF cameras
/// look down −z with +x to the right; Radiant's look down +z with +x to
/// the left). Clipping planes are not carried over.
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
    let flip = DMat4::from_scale(DVec3::new(-1.0, 1.0, -1.0));
    let pose = matrix_yaml(to_world * flip);
    let text = match camera.projection() {
        gltf::camera::Projection::Perspective(p) => format!(
            "{{type: perspective, fov: {:?}, fov_axis: y, transform: {pose}}}",
            f64::from(p.yfov()).to_degrees()
        ),
        // xmag is half the view's width; the height follows the film.
        gltf::camera::Projection::Orthographic(o) => format!(
            "{{type: orthographic, width: {:?}, transform: {pose}}}",
            2.0 * f64::from(o.xmag())
        ),
    };
    generated(&asset.path, &text)
}

/// A matrix as the `matrix:` rows of a transform.
fn matrix_yaml(m: DMat4) -> String {
    let rows: Vec<String> = (0..4).map(|r| list(&m.row(r).to_array())).collect();
    format!("{{matrix: [{}]}}", rows.join(", "))
}
