//! `scenes/veach-gap.yaml`, light through a door left ajar: the path
//! tracer renders it finite at low spp, and the light reaches the camera's
//! room through the gap alone (a closed door leaves it black).

use radiant::extract::Overrides;
use radiant_tests::render_edited;

const SCENE: &str = "scenes/veach-gap.yaml";

fn small() -> Overrides {
    Overrides {
        width: Some(32),
        height: Some(24),
        ..Overrides::default()
    }
}

#[test]
fn the_open_door_lets_light_through_and_renders_finite() {
    let r = render_edited(SCENE, str::to_string, small());
    assert_eq!(r.invalid_samples, 0);
    assert!(r.image.pixels.iter().all(|p| p.is_finite()));
    assert!(r.image.mean() > 0.0, "light comes through the gap");
}

#[test]
fn a_closed_door_leaves_the_room_black() {
    // The door swung shut fills the doorway: no light path is left.
    let closed = |text: &str| {
        assert!(text.contains("angle: -4}"));
        text.replace("angle: -4}", "angle: 0}")
    };
    let r = render_edited(SCENE, closed, small());
    assert!(
        r.image
            .pixels
            .iter()
            .all(|p| *p == radiant::core::Rgb::ZERO),
        "a pixel is lit through a closed door"
    );
}
