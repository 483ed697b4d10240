//! `KHR_lights_punctual` lights as the YAML of Radiant's `point`, `spot`
//! and `directional` lights, placed by their nodes.

use super::list;
use glam::{DMat4, DVec3, DVec4};
use std::fmt::Write as _;

/// The light of a glTF node placed by `to_world`, as Radiant YAML. glTF's
/// photometric numbers are carried over as they are: candela as W/sr of
/// `intensity`, lux as W/m² of `irradiance` (see README).
pub(super) fn light_yaml(light: &gltf::khr_lights_punctual::Light<'_>, to_world: DMat4) -> String {
    use gltf::khr_lights_punctual::Kind;
    let power = f64::from(light.intensity());
    let color = light.color().map(|c| f64::from(c) * power);
    let position = to_world.transform_point3(DVec3::ZERO);
    let direction = (to_world * DVec4::new(0.0, 0.0, -1.0, 0.0))
        .truncate()
        .normalize_or(DVec3::NEG_Z);
    let mut text = String::new();
    match light.kind() {
        Kind::Point => {
            let _ = write!(
                text,
                "{{type: point, position: {}, intensity: {}}}",
                list(&position.to_array()),
                list(&color)
            );
        }
        Kind::Spot {
            inner_cone_angle,
            outer_cone_angle,
        } => {
            let _ = write!(
                text,
                "{{type: spot, position: {}, direction: {}, intensity: {}, cutoff_angle: {:?}, beam_width: {:?}}}",
                list(&position.to_array()),
                list(&direction.to_array()),
                list(&color),
                f64::from(outer_cone_angle).to_degrees(),
                f64::from(inner_cone_angle.min(outer_cone_angle)).to_degrees()
            );
        }
        Kind::Directional => {
            let _ = write!(
                text,
                "{{type: directional, direction: {}, irradiance: {}}}",
                list(&direction.to_array()),
                list(&color)
            );
        }
    }
    text
}
