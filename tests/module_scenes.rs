//! The camera, filter, sampler and texture modules used from scene files:
//! errors name the scene's file, line and column.

use radiant::extract::{Overrides, extract};
use radiant::scene::{SceneError, from_str};
use std::path::Path;

fn load(text: &str) -> Result<(), SceneError> {
    let file = Path::new("scenes/textured.yaml");
    let scene = from_str(text, file, &radiant_tests::root().join("scenes"))?;
    extract(&scene, &radiant::builtin_registry(), &Overrides::default()).map(|_| ())
}

#[test]
fn a_missing_image_is_reported_at_its_filename_in_the_scene() {
    let text = "camera: {type: perspective}\ntextures:\n  wood:\n    type: image\n    filename: textures/wood.png\n";
    let err = load(text).expect_err("a missing image must be an error");
    let shown = err.to_string();
    assert!(shown.starts_with("scenes/textured.yaml:5:15: "), "{shown}");
    assert!(
        shown.contains("cannot read image") && shown.contains("wood.png"),
        "{shown}"
    );
}

#[test]
fn bad_camera_filter_and_sampler_parameters_are_located() {
    for (text, prefix, needle) in [
        (
            "camera: {type: thin_lens, aperture_radius: -1, focus_distance: 2}\n",
            "scenes/textured.yaml:1:44: ",
            "aperture_radius",
        ),
        (
            "camera:\n  type: thin_lens\n  aperture_radius: 0.1\n",
            "scenes/textured.yaml:2:",
            "focus_distance",
        ),
        (
            "camera: {type: orthographic, width: 0}\n",
            "scenes/textured.yaml:1:37: ",
            "width",
        ),
        (
            "camera: {type: spherical, fov: 90}\n",
            "scenes/textured.yaml:1:",
            "fov",
        ),
        (
            "camera: {type: perspective}\nfilm: {width: 8, height: 8, filter: {type: lanczos, lobes: 0}}\n",
            "scenes/textured.yaml:2:",
            "lobes",
        ),
        (
            "camera: {type: perspective}\nsampler: {type: sobol, spp: 4, scramble: none}\n",
            "scenes/textured.yaml:2:",
            "scramble",
        ),
    ] {
        let shown = load(text).expect_err(text).to_string();
        assert!(
            shown.starts_with(prefix) && shown.contains(needle),
            "{text}: {shown}"
        );
    }
}
