//! Every kind of scene error is reported with the file, line and column,
//! what was expected and what is allowed — never a panic.

use radiant::extract::{Overrides, extract};
use radiant::scene::{SceneError, from_str};
use std::path::Path;

const CAMERA: &str = "camera: {type: perspective, fov: 40}\n";

fn load(text: &str) -> Result<(), SceneError> {
    let file = Path::new("scenes/bad.yaml");
    let scene = from_str(text, file, &radiant_tests::root().join("scenes"))?;
    extract(&scene, &radiant::builtin_registry(), &Overrides::default()).map(|_| ())
}

/// Asserts that `text` fails at `line` with a message containing `needles`.
fn fails_at(text: &str, line: usize, needles: &[&str]) -> SceneError {
    let err = load(text).expect_err("the scene should be rejected");
    let loc = err
        .location
        .unwrap_or_else(|| panic!("no location in: {err}"));
    assert_eq!(loc.line, line, "wrong line in: {err}");
    assert!(loc.column >= 1);
    let shown = err.to_string();
    assert!(
        shown.starts_with(&format!("scenes/bad.yaml:{}:{}: ", loc.line, loc.column)),
        "{shown}"
    );
    for n in needles {
        assert!(shown.contains(n), "`{n}` missing from: {shown}");
    }
    err
}

#[test]
fn invalid_yaml_syntax() {
    fails_at(
        "camera: {type: perspective\nshapes: [\n",
        2,
        &["invalid YAML", "flow mapping"],
    );
    fails_at(
        "camera:\n  type: perspective\n   fov: 3\n",
        3,
        &["invalid YAML"],
    );
}

#[test]
fn unknown_module_type_lists_the_known_ones_and_suggests_the_closest() {
    let err = fails_at(
        "camera: {type: perspectiv}\n",
        1,
        &[
            "unknown camera type `perspectiv`",
            "did you mean `perspective`",
            "known camera types: orthographic, perspective, spherical, thin_lens",
        ],
    );
    assert_eq!(err.location.unwrap().column, 16);
    fails_at(
        &format!("{CAMERA}materials:\n  m: {{type: difuse}}\n"),
        3,
        &["unknown shader type `difuse`", "did you mean `diffuse`"],
    );
    fails_at(
        &format!("{CAMERA}film:\n  filter: {{type: gauss}}\n"),
        3,
        &["unknown filter type `gauss`", "box, gaussian"],
    );
    fails_at(
        &format!("{CAMERA}shapes:\n  - type: cub\n"),
        3,
        &[
            "unknown shape type `cub`",
            "did you mean `cube`",
            "rectangle, cube, sphere, mesh",
        ],
    );
    fails_at(
        &format!("{CAMERA}integrator: {{type: photon_map}}\n"),
        2,
        &["unknown integrator type `photon_map`", "path"],
    );
}

#[test]
fn unknown_or_misspelled_keys() {
    fails_at(
        &format!("{CAMERA}materials:\n  m:\n    type: diffuse\n    reflectanse: 0.5\n"),
        5,
        &["reflectanse", "reflectance"],
    );
    fails_at(
        &format!("{CAMERA}shapse: []\n"),
        2,
        &["unknown key `shapse`", "did you mean `shapes`"],
    );
    fails_at(
        &format!("{CAMERA}shapes:\n  - type: cube\n    materail: m\n"),
        4,
        &[
            "unknown key `materail` in the shape",
            "did you mean `material`",
        ],
    );
    fails_at(
        "camera:\n  type: perspective\n  fov_axis: x\n  fvo: 40\n",
        4,
        &["fvo", "fov"],
    );
    fails_at(
        &format!("{CAMERA}film: {{width: 64, heigth: 64}}\n"),
        2,
        &["heigth", "height"],
    );
}

#[test]
fn wrong_value_types() {
    fails_at(
        "camera:\n  type: perspective\n  fov: wide\n",
        3,
        &["expected a number"],
    );
    fails_at(
        &format!("{CAMERA}film:\n  width: big\n"),
        3,
        &["expected an integer"],
    );
    fails_at(
        &format!("{CAMERA}sampler: {{type: independent, spp: -4}}\n"),
        2,
        &["integer"],
    );
    fails_at(
        &format!("{CAMERA}materials:\n  m: {{type: diffuse, reflectance: [1, 2]}}\n"),
        3,
        &["3 colour channels"],
    );
    fails_at(
        &format!("{CAMERA}shapes:\n  - type: cube\n    transform: {{translate: [1, 2]}}\n"),
        4,
        &["expected a list of 3 numbers, found 2"],
    );
    // Fixed-length lists reject extra elements too (the YAML deserializer
    // alone would drop them unnoticed).
    fails_at(
        &format!("{CAMERA}shapes:\n  - type: cube\n    transform: {{translate: [1, 2, 3, 4]}}\n"),
        4,
        &["expected a list of 3 numbers, found 4"],
    );
    fails_at(
        &format!(
            "{CAMERA}shapes:\n  - type: cube\n    transform:\n      rotate: {{axis: [0, 1, 0, 0], angle: 9}}\n"
        ),
        5,
        &["axis", "3 numbers, found 4"],
    );
    fails_at(
        "camera:\n  type: perspective\n  look_at: {origin: [0, 0, 4, [1]], target: [0, 0, 0]}\n",
        3,
        &["origin"],
    );
    fails_at(
        &format!(
            "{CAMERA}shapes:\n  - type: cube\n    transform:\n      matrix: [[1, 0, 0, 0, 9], [0, 1, 0, 0], [0, 0, 1, 0]]\n"
        ),
        5,
        &["4 numbers, found 5"],
    );
    fails_at(
        &format!("{CAMERA}lights:\n  - {{type: point, position: [0, 1, 2, 3]}}\n"),
        3,
        &["3 numbers, found 4"],
    );
    fails_at(
        "camera:\n  type: perspective\n  fov: 180\n",
        3,
        &["between 0 and 180"],
    );
    fails_at(
        &format!("{CAMERA}integrator: {{type: path, max_depth: -2}}\n"),
        2,
        &["max_depth"],
    );
}

#[test]
fn missing_mesh_file() {
    fails_at(
        &format!("{CAMERA}shapes:\n  - type: mesh\n    filename: nowhere/missing.obj\n"),
        4,
        &["cannot open mesh file", "missing.obj"],
    );
}

#[test]
fn undefined_references() {
    fails_at(
        &format!(
            "{CAMERA}materials:\n  white: {{type: diffuse}}\nshapes:\n  - type: cube\n    material: whte\n"
        ),
        6,
        &["undefined material `whte`", "did you mean `white`", "white"],
    );
    fails_at(
        &format!("{CAMERA}materials:\n  m: {{type: diffuse, reflectance: wood}}\n"),
        3,
        &["undefined texture `wood`"],
    );
}

#[test]
fn misplaced_modules() {
    fails_at(
        &format!("{CAMERA}lights:\n  - {{type: area, radiance: 1}}\n"),
        3,
        &["must be attached to a shape"],
    );
    for light in [
        "{type: point, position: [0, 1, 0], intensity: 1}",
        "{type: environment, radiance: 5}",
    ] {
        fails_at(
            &format!("{CAMERA}shapes:\n  - type: cube\n    emitter: {light}\n"),
            4,
            &["a shape's `emitter` must be a light that emits from the shape's surface"],
        );
    }
    fails_at(
        &format!("{CAMERA}shapes:\n  - type: sphere\n    transform: {{scale: [1, 2, 1]}}\n"),
        3,
        &["sphere", "uniformly"],
    );
}

#[test]
fn a_scene_without_camera_is_an_error() {
    let err = load("shapes: []\n").unwrap_err();
    assert!(err.to_string().contains("needs a `camera`"), "{err}");
}

#[test]
fn bad_light_parameters_are_located_and_explained() {
    let light = |l: &str| format!("{CAMERA}lights:\n  - {l}\n");
    fails_at(
        &light("{type: environment, radiance: 1, filename: sky.exr}"),
        3,
        &["either a `filename`", "or a constant `radiance`"],
    );
    fails_at(&light("{type: environment}"), 3, &["either a `filename`"]);
    fails_at(
        &light("{type: environment, filename: missing.exr}"),
        3,
        &["missing.exr", "cannot read the environment map"],
    );
    fails_at(
        &light("{type: environment, filename: cornell-box.yaml}"),
        3,
        &["must end in .exr or .hdr"],
    );
    fails_at(
        &light("{type: environment, radiance: 1, transform: {scale: 2}}"),
        3,
        &["must be a rotation"],
    );
    fails_at(
        &light("{type: environment, radiance: [1, -1, 1]}"),
        3,
        &["`radiance` must be finite and non-negative"],
    );
    fails_at(
        &light("{type: environment, radiance: 1, scale: -2}"),
        3,
        &["`scale` must be finite and non-negative"],
    );
    fails_at(
        &light("{type: spot, intensity: 1, cutoff_angle: 20, beam_width: 30}"),
        3,
        &["`beam_width` must be in [0, cutoff_angle = 20]"],
    );
    fails_at(
        &light("{type: spot, intensity: 1, cutoff_angle: 0}"),
        3,
        &["`cutoff_angle` must be in (0, 180]"],
    );
    fails_at(
        &light("{type: spot, intensity: 1, position: [1, 1, 1], target: [1, 1, 1]}"),
        3,
        &["`target` must differ from `position`"],
    );
    fails_at(
        &light("{type: spot, intensity: 1, direction: [0, 0, 1], target: [1, 1, 1]}"),
        3,
        &["either `direction` or `target`"],
    );
    fails_at(
        &light("{type: directional, irradiance: 1, direction: [0, 0, 0]}"),
        3,
        &["`direction` must be a finite, non-zero vector"],
    );
    fails_at(&light("{type: directional}"), 3, &["irradiance"]);
    fails_at(
        &light("{type: point, intensity: 1, position: [0, 0, 0], transform: {rotate: 5}}"),
        3,
        &["expected a rotation `{axis: [x, y, z], angle: degrees}`"],
    );
}

#[test]
fn unknown_light_selection_lists_the_allowed_ones() {
    fails_at(
        &format!("{CAMERA}integrator:\n  type: path\n  light_selection: powr\n"),
        4,
        &["powr", "power", "uniform"],
    );
}

#[test]
fn unknown_filter_sampling_lists_the_allowed_ones() {
    fails_at(
        &format!("{CAMERA}film:\n  filter_sampling: importnce\n"),
        3,
        &["importnce", "splat", "importance"],
    );
}

#[test]
fn out_of_range_values_are_rejected_where_written() {
    for value in ["2", "-0.5", "[0.5, 1.5, 0.5]", "1e39"] {
        fails_at(
            &format!("{CAMERA}materials:\n  m: {{type: diffuse, reflectance: {value}}}\n"),
            3,
            &["`reflectance` must lie in [0, 1]"],
        );
    }
    for value in ["-1", "[1, -2, 1]", "1e39"] {
        fails_at(
            &format!(
                "{CAMERA}shapes:\n  - type: rectangle\n    emitter: {{type: area, radiance: {value}}}\n"
            ),
            4,
            &["`radiance` must be finite and non-negative"],
        );
    }
    fails_at(
        &format!("{CAMERA}film:\n  filter: {{type: box, radius: 1e12}}\n"),
        3,
        &["`radius` must be from 0.5 to 32 pixels"],
    );
}

#[test]
fn deeply_nested_named_materials_are_an_error_not_a_stack_overflow() {
    let mut text = format!("{CAMERA}materials:\n");
    for i in 0..200 {
        text += &format!(
            "  m{i}: {{type: bump, height: 0.5, material: m{}}}\n",
            i + 1
        );
    }
    text += "  m200: {type: diffuse}\nshapes:\n  - {type: cube, material: m0}\n";
    // m0 → … → m31 are 32 levels; m31's reference to m32 (line 34) is one
    // too many.
    fails_at(&text, 34, &["nested more than 32 materials deep"]);
}

#[test]
fn overrides_outside_the_allowed_ranges_are_errors() {
    let scene = from_str(CAMERA, Path::new("scenes/bad.yaml"), &radiant_tests::root())
        .expect("the scene parses");
    let registry = radiant::builtin_registry();
    for (overrides, needle) in [
        (
            Overrides {
                width: Some(40_000),
                ..Default::default()
            },
            "width override must be between 1 and 32768",
        ),
        (
            Overrides {
                height: Some(0),
                ..Default::default()
            },
            "height override must be between 1 and 32768",
        ),
        (
            Overrides {
                spp: Some(0),
                ..Default::default()
            },
            "spp override",
        ),
        (
            Overrides {
                max_depth: Some(-2),
                ..Default::default()
            },
            "max_depth override",
        ),
    ] {
        let Err(err) = extract(&scene, &registry, &overrides) else {
            panic!("{overrides:?} should be rejected");
        };
        assert!(err.to_string().contains(needle), "{err}");
    }
}

#[test]
fn text_the_yaml_parser_would_drop_is_an_error() {
    fails_at(
        &format!("{CAMERA}film: {{width: 8}}\0\nshapes: [{{type: cube}}]\n"),
        2,
        &["NUL character"],
    );
    fails_at(
        &format!("{CAMERA}---\nshapes: [{{type: cube}}]\n"),
        2,
        &["one YAML document", "second one starts here"],
    );
    // One document with explicit start and end markers is fine.
    load(&format!("# a scene\n---\n{CAMERA}...\n# the end\n")).expect("a single document");
}
