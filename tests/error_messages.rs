//! Errors and warnings that used to name the wrong problem, or none: each
//! now says the real one, where it is, and what would be accepted.

// `unwrap` in this test code is the assertion: the scenes are the test's
// own, so a failure is a bug, and the panic reports it with the error.

use radiant::extract::facing::back_facing;
use radiant::extract::{Overrides, RenderScene, extract};
use radiant::scene::{SceneError, from_str};
use std::path::Path;

const CAMERA: &str = "camera: {type: perspective, fov: 40}\n";

fn load(text: &str) -> Result<RenderScene, SceneError> {
    let file = Path::new("scenes/bad.yaml");
    let scene = from_str(text, file, &radiant_tests::root().join("scenes"))?;
    extract(&scene, &radiant::builtin_registry(), &Overrides::default())
}

/// The message of `text`'s error, checked to start with `line` and a column.
fn message_at(text: &str, line: usize) -> String {
    let err = load(text).err().expect("the scene should be rejected");
    let loc = err.location.unwrap_or_else(|| panic!("no location: {err}"));
    assert_eq!(loc.line, line, "{err}");
    let shown = err.to_string();
    let prefix = format!("scenes/bad.yaml:{}:{}: ", loc.line, loc.column);
    assert!(shown.starts_with(&prefix), "{shown}");
    shown
}

#[test]
fn a_negative_or_zero_spp_is_named_as_such_at_its_value() {
    for (spp, column) in [("-4", 35), ("0", 35)] {
        let text = format!("{CAMERA}sampler: {{type: independent, spp: {spp}}}\n");
        let err = load(&text).err().unwrap();
        assert_eq!(err.location.unwrap().column, column, "{err}");
        let shown = message_at(&text, 2);
        assert!(
            shown.contains(&format!(
                "spp must be a positive integer (samples per pixel, 1 or more), found {spp}"
            )),
            "{shown}"
        );
        assert!(!shown.contains("invalid digit"), "{shown}");
    }
}

#[test]
fn negative_and_fractional_counts_say_what_an_integer_key_needs() {
    let shown = message_at(&format!("{CAMERA}film: {{width: -64}}\n"), 2);
    assert!(
        shown.contains("expected a non-negative integer for `width`, found -64"),
        "{shown}"
    );
    let shown = message_at(&format!("{CAMERA}film: {{width: 64.5}}\n"), 2);
    assert!(shown.contains("expected a whole number"), "{shown}");
    assert!(shown.contains("found 64.5"), "{shown}");
    // Not a number at all: the parser's own words stay.
    let shown = message_at(&format!("{CAMERA}film: {{width: big}}\n"), 2);
    assert!(shown.contains("expected an integer"), "{shown}");
}

#[test]
fn a_point_light_on_a_shape_says_which_emitters_a_shape_can_carry() {
    for light in ["point", "spot", "directional", "environment"] {
        let text = format!(
            "{CAMERA}shapes:\n  - type: sphere\n    emitter: {{type: {light}, intensity: 3}}\n"
        );
        let shown = message_at(&text, 4);
        assert!(
            shown.contains(&format!("a `{light}` light cannot be attached to a shape")),
            "{shown}"
        );
        assert!(shown.contains("`area`"), "{shown}");
        assert!(shown.contains("under `lights:`"), "{shown}");
        assert!(!shown.contains("position"), "{shown}");
    }
}

#[test]
fn a_missing_mesh_file_carries_the_os_error() {
    let shown = message_at(
        &format!("{CAMERA}shapes:\n  - type: mesh\n    filename: nowhere/missing.obj\n"),
        4,
    );
    assert!(shown.contains("missing.obj"), "{shown}");
    assert!(shown.contains("No such file or directory"), "{shown}");
}

/// A unit rectangle (normal +z) seen by a camera on the z axis at `z`.
fn rectangle_seen_from(z: f32, material: &str) -> String {
    format!(
        "film: {{width: 32, height: 32}}\n\
         camera: {{type: perspective, fov: 40, look_at: {{origin: [0, 0, {z}], target: [0, 0, 0]}}}}\n\
         materials:\n  wall: {material}\n\
         shapes:\n  - {{type: rectangle, material: wall}}\n"
    )
}

#[test]
fn the_back_of_a_one_sided_surface_is_reported_by_material() {
    let behind = load(&rectangle_seen_from(-3.0, "{type: diffuse}")).unwrap();
    let found = back_facing(&behind);
    assert_eq!(found.len(), 1, "{found:?}");
    assert_eq!(found[0].material, "wall");
    assert_eq!(found[0].module, "diffuse");
    assert_eq!(found[0].front, 0.0);
    // The square's half-width 1 against the view's 3·tan 20° ≈ 1.09 at
    // its distance: (1/1.09)² ≈ 84 % of the image.
    assert!((0.75..0.92).contains(&found[0].back), "{found:?}");
    let said = found[0].to_string();
    assert!(said.contains("material `wall`"), "{said}");
    assert!(said.contains("black from behind"), "{said}");
    // From the front, nothing to report.
    let front = load(&rectangle_seen_from(3.0, "{type: diffuse}")).unwrap();
    assert_eq!(back_facing(&front), Vec::new());
    // Glass transmits from both sides: its back is no mistake.
    let glass = load(&rectangle_seen_from(-3.0, "{type: dielectric}")).unwrap();
    assert_eq!(back_facing(&glass), Vec::new());
}
