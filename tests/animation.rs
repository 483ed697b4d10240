//! Animation sequences: frames alone and in a sequence, animated module
//! parameters, instancing, deforming meshes, and the errors of animated
//! scenes.

use radiant::backend::cpu::{Progress, render};
use radiant::extract::{Overrides, Sequence, SequenceOptions};
use radiant::film::Image;
use radiant::scene::{SceneError, from_str};
use radiant_tests::write_grid;
use std::path::Path;

/// A small Cornell-like room with an animated cube, an animated colour, a
/// moving camera and instanced spheres.
const ROOM: &str = "
integrator: {type: path, max_depth: 4}
film: {width: 48, height: 48}
sampler: {type: independent, spp: 4}
animation: {fps: 24, frames: [1, 6]}
camera:
  type: perspective
  fov: {keyframes: [{frame: 1, value: 40}, {frame: 6, value: 30}], interpolation: smooth}
  look_at:
    origin: {keyframes: [{frame: 1, value: [0, 0, 3.9]}, {frame: 6, value: [0.4, 0.2, 3.6]}]}
    target: [0, 0, 0]
materials:
  white: {type: diffuse, reflectance: 0.7}
  tint: {type: diffuse, reflectance: {keyframes: [{frame: 1, value: [0.8, 0.1, 0.1]}, {frame: 6, value: [0.1, 0.1, 0.8]}]}}
shapes:
  - {type: rectangle, material: white, transform: [{translate: [0, -1, 0]}, {rotate: {axis: [1, 0, 0], angle: -90}}]}
  - {type: rectangle, material: white, transform: {translate: [0, 0, -1]}}
  - type: cube
    material: tint
    transform: {scale: 0.25}
    animation:
      translate: {keyframes: [{frame: 1, value: [-0.5, -0.5, 0]}, {frame: 6, value: [0.5, 0.2, 0]}]}
      rotate: {keyframes: [{frame: 1, value: {axis: [0, 1, 0], angle: 0}}, {frame: 6, value: {axis: [0, 1, 0], angle: 120}}]}
  - type: sphere
    radius: 0.12
    material: white
    transform: {translate: [-0.6, 0.5, 0]}
    instances: {grid: {count: [4, 1, 1], spacing: [0.4, 0, 0]}, materials: [white, tint]}
  - type: rectangle
    transform: [{translate: [0, 0.99, 0]}, {rotate: {axis: [1, 0, 0], angle: 90}}, {scale: 0.3}]
    emitter: {type: area, radiance: {keyframes: [{frame: 1, value: 8}, {frame: 6, value: 16}]}}
";

fn load(text: &str) -> Result<radiant::scene::Scene, SceneError> {
    from_str(
        text,
        Path::new("scenes/anim.yaml"),
        &radiant_tests::root().join("scenes"),
    )
}

/// Renders `frames` of `text` in one sequence.
fn sequence(text: &str, frames: &[i64], options: SequenceOptions) -> Vec<Image> {
    let mut scene = load(text).expect("the test scene parses");
    let registry = radiant::builtin_registry();
    let mut out = Vec::new();
    let mut state: Option<Sequence> = None;
    for &f in frames {
        match &mut state {
            None => {
                let (s, _) =
                    Sequence::new(&mut scene, &registry, &Overrides::default(), &options, f)
                        .expect("the first frame builds");
                state = Some(s);
            }
            Some(s) => {
                s.go_to(&mut scene, &registry, f)
                    .expect("the frame updates");
            }
        }
        let s = state.as_ref().expect("built");
        out.push(render(s.scene(), &Progress::none()).image);
    }
    out
}

#[test]
fn a_frame_in_a_sequence_is_the_frame_rendered_alone() {
    let all = sequence(ROOM, &[1, 2, 3, 4, 5, 6], SequenceOptions::default());
    for (i, frame) in [1i64, 4, 6].into_iter().enumerate() {
        let alone = sequence(ROOM, &[frame], SequenceOptions::default());
        assert!(
            alone[0].pixels == all[frame as usize - 1].pixels,
            "frame {frame} differs alone ({i})"
        );
    }
    // Frames differ from each other: the scene moves and the noise too.
    assert!(all[0].pixels != all[1].pixels);
}

#[test]
fn noise_changes_from_frame_to_frame_unless_locked() {
    // A still scene: only the noise can change between frames.
    let still = ROOM
        .replace("keyframes: [{frame: 1, value: [-0.5, -0.5, 0]}, {frame: 6, value: [0.5, 0.2, 0]}]", "keyframes: [{frame: 1, value: [0, -0.5, 0]}]")
        .replace("{keyframes: [{frame: 1, value: 40}, {frame: 6, value: 30}], interpolation: smooth}", "40")
        .replace("{keyframes: [{frame: 1, value: [0, 0, 3.9]}, {frame: 6, value: [0.4, 0.2, 3.6]}]}", "[0, 0, 3.9]")
        .replace("{keyframes: [{frame: 1, value: [0.8, 0.1, 0.1]}, {frame: 6, value: [0.1, 0.1, 0.8]}]}", "[0.8, 0.1, 0.1]")
        .replace("{keyframes: [{frame: 1, value: 8}, {frame: 6, value: 16}]}", "8")
        .replace("{keyframes: [{frame: 1, value: {axis: [0, 1, 0], angle: 0}}, {frame: 6, value: {axis: [0, 1, 0], angle: 120}}]}", "{axis: [0, 1, 0], angle: 0}");
    let free = sequence(&still, &[2, 3], SequenceOptions::default());
    assert!(free[0].pixels != free[1].pixels, "noise froze");
    let locked = SequenceOptions {
        lock_noise: true,
        ..SequenceOptions::default()
    };
    let frozen = sequence(&still, &[2, 3], locked);
    assert!(frozen[0].pixels == frozen[1].pixels, "locked noise moved");
}

#[test]
fn only_modules_whose_parameters_changed_are_rebuilt() {
    let text = "
animation: {fps: 24, frames: [1, 10]}
sampler: {type: independent, spp: 1}
film: {width: 8, height: 8}
camera: {type: perspective, look_at: {origin: [0, 0, 4], target: [0, 0, 0]}}
textures:
  checks: {type: checkerboard, color0: {keyframes: [{frame: 1, value: 0.2}, {frame: 5, value: 0.6}], interpolation: step}}
materials:
  a: {type: diffuse, reflectance: checks}
  b: {type: diffuse, reflectance: 0.5}
shapes:
  - {type: rectangle, material: a}
  - {type: rectangle, material: b, transform: {translate: [0, 0, -1]}}
lights:
  - {type: point, position: [0, 0, 3], intensity: 5}
";
    let mut scene = load(text).expect("parses");
    let registry = radiant::builtin_registry();
    let options = SequenceOptions {
        lock_noise: true,
        ..SequenceOptions::default()
    };
    let (mut s, _) =
        Sequence::new(&mut scene, &registry, &Overrides::default(), &options, 1).expect("builds");
    // Frames 2–4 hold the first key (step): nothing is rebuilt.
    for f in 2..=4 {
        let u = s.go_to(&mut scene, &registry, f).expect("updates");
        assert_eq!(u.modules_rebuilt, 0, "frame {f}");
    }
    // Frame 5 changes the texture: it and the material naming it, only.
    let u = s.go_to(&mut scene, &registry, 5).expect("updates");
    assert_eq!(u.modules_rebuilt, 2);
    let table = s.scene().textures.len();
    for f in 6..=10 {
        assert_eq!(
            s.go_to(&mut scene, &registry, f)
                .expect("updates")
                .modules_rebuilt,
            0
        );
    }
    // Going back and forth rebuilds, but the texture table does not grow.
    for f in [1, 5, 1, 5, 1] {
        s.go_to(&mut scene, &registry, f).expect("updates");
    }
    assert_eq!(s.scene().textures.len(), table);
}

#[test]
fn animated_parameters_and_instance_materials_reach_the_image() {
    let frames = sequence(ROOM, &[1, 6], SequenceOptions::default());
    let mean = |img: &Image| radiant_tests::channel_means(img);
    let (first, last) = (mean(&frames[0]), mean(&frames[1]));
    // The tinted surfaces turn from red to blue, and the light doubles.
    assert!(first[0] > first[2], "{first:?}");
    assert!(last[2] > last[0], "{last:?}");
    let total = |m: [f64; 3]| m.iter().sum::<f64>();
    assert!(total(last) > 1.3 * total(first), "{first:?} → {last:?}");
}

fn mesh_scene(pattern: &str, shutter: &str) -> String {
    format!(
        "
animation: {{fps: 24, frames: [1, 4]}}
film: {{width: 32, height: 32}}
sampler: {{type: independent, spp: 4}}
camera: {{type: perspective, look_at: {{origin: [0, 0, 4], target: [0, 0, 0]}}{shutter}}}
shapes:
  - {{type: mesh, filename: '{pattern}', material: {{type: diffuse, reflectance: 0.8}}}}
lights:
  - {{type: point, position: [0, 1, 3], intensity: 10}}
"
    )
}

#[test]
fn deforming_meshes_follow_their_files_and_refit() {
    let dir = tempfile::tempdir().expect("a temporary folder");
    for f in 1..=4 {
        write_grid(
            &dir.path().join(format!("wave_{f:03}.obj")),
            24,
            f as f32 * 0.7,
            false,
        );
    }
    let pattern = dir.path().join("wave_###.obj");
    let text = mesh_scene(&pattern.to_string_lossy(), "");
    let mut scene = load(&text).expect("parses");
    let registry = radiant::builtin_registry();
    let options = SequenceOptions::default();
    let (mut s, _) =
        Sequence::new(&mut scene, &registry, &Overrides::default(), &options, 1).expect("builds");
    assert_eq!(s.scene().stats.deforming_meshes, 1);
    let first = render(s.scene(), &Progress::none()).image;
    for f in 2..=4 {
        let u = s.go_to(&mut scene, &registry, f).expect("updates");
        assert_eq!(
            u.geometry.refitted + u.geometry.rebuilt,
            1,
            "frame {f}: {u:?}"
        );
    }
    let moved = render(s.scene(), &Progress::none()).image;
    assert!(first.pixels != moved.pixels);
    // Frame 4 of the sequence is frame 4 rendered alone (a fresh build).
    let mut again = load(&text).expect("parses");
    let (alone, _) =
        Sequence::new(&mut again, &registry, &Overrides::default(), &options, 4).expect("builds");
    assert!(render(alone.scene(), &Progress::none()).image.pixels == moved.pixels);

    // Under a shutter, the mesh blurs between its frames.
    let blurred = mesh_scene(&pattern.to_string_lossy(), ", shutter: [0, 0.5]");
    let mut scene = load(&blurred).expect("parses");
    let (s, _) =
        Sequence::new(&mut scene, &registry, &Overrides::default(), &options, 2).expect("builds");
    assert!(s.scene().motion_blur());
}

#[test]
fn a_frame_with_other_triangles_is_an_error_naming_the_file() {
    let dir = tempfile::tempdir().expect("a temporary folder");
    for f in 1..=4 {
        write_grid(&dir.path().join(format!("wave_{f:03}.obj")), 8, 0.0, f == 3);
    }
    let text = mesh_scene(&dir.path().join("wave_###.obj").to_string_lossy(), "");
    let mut scene = load(&text).expect("parses");
    let registry = radiant::builtin_registry();
    let options = SequenceOptions::default();
    let (mut s, _) =
        Sequence::new(&mut scene, &registry, &Overrides::default(), &options, 1).expect("builds");
    s.go_to(&mut scene, &registry, 2).expect("frame 2 is fine");
    let err = s
        .go_to(&mut scene, &registry, 3)
        .expect_err("frame 3 lost a face");
    let shown = err.to_string();
    assert!(shown.contains("wave_003.obj"), "{shown}");
    assert!(
        shown.contains("96 triangles") && shown.contains("98"),
        "{shown}"
    );
    assert!(err.location.is_some_and(|l| l.line == 7), "{shown}");
    // A missing frame names its file too.
    std::fs::remove_file(dir.path().join("wave_004.obj")).expect("removable");
    let err = s
        .go_to(&mut scene, &registry, 4)
        .expect_err("frame 4 is missing");
    assert!(err.to_string().contains("wave_004.obj"), "{err}");
}

/// Asserts that `text` fails at `line` with a message containing `needles`.
fn fails_at(text: &str, line: usize, needles: &[&str]) {
    let err = match load(text) {
        Err(e) => e,
        Ok(mut scene) => {
            let registry = radiant::builtin_registry();
            let start = scene.timeline.start;
            match Sequence::new(
                &mut scene,
                &registry,
                &Overrides::default(),
                &SequenceOptions::default(),
                start,
            ) {
                Err(e) => e,
                Ok(_) => panic!("the scene should be rejected:\n{text}"),
            }
        }
    };
    let shown = err.to_string();
    assert_eq!(
        err.location.map(|l| l.line),
        Some(line),
        "wrong line in: {shown}"
    );
    for n in needles {
        assert!(shown.contains(n), "`{n}` missing from: {shown}");
    }
}

const CAMERA: &str =
    "camera: {type: perspective, look_at: {origin: [0, 0, 4], target: [0, 0, 0]}}\n";

#[test]
fn keys_out_of_order_or_at_equal_times_are_errors() {
    fails_at(
        &format!(
            "{CAMERA}shapes:\n  - type: cube\n    animation:\n      translate:\n        keyframes:\n          - {{frame: 5, value: [0, 0, 0]}}\n          - {{frame: 5, value: [1, 0, 0]}}\n"
        ),
        8,
        &["strictly increasing", "key 2", "frame 5"],
    );
    fails_at(
        &format!(
            "{CAMERA}materials:\n  m: {{type: diffuse, reflectance: {{keyframes: [{{time: 1, value: 0.5}}, {{time: 0.5, value: 0.2}}]}}}}\n"
        ),
        3,
        &["strictly increasing", "key 2"],
    );
}

#[test]
fn unknown_interpolations_list_the_allowed_ones() {
    fails_at(
        &format!(
            "{CAMERA}shapes:\n  - type: cube\n    animation:\n      scale: {{interpolation: cubic, keyframes: [{{frame: 1, value: 1}}]}}\n"
        ),
        5,
        &["unknown interpolation `cubic`", "step, linear, smooth"],
    );
}

#[test]
fn parameters_that_cannot_animate_are_errors() {
    // A filter, a shape's radius, a transform operation, a module's string.
    fails_at(
        &format!(
            "{CAMERA}film: {{filter: {{type: gaussian, stddev: {{keyframes: [{{frame: 1, value: 0.5}}]}}}}}}\n"
        ),
        2,
        &["cannot animate"],
    );
    fails_at(
        &format!(
            "{CAMERA}shapes:\n  - type: sphere\n    radius: {{keyframes: [{{frame: 1, value: 1}}]}}\n"
        ),
        4,
        &["cannot animate"],
    );
    fails_at(
        &format!(
            "{CAMERA}shapes:\n  - type: cube\n    transform: {{translate: {{keyframes: [{{frame: 1, value: [0, 0, 0]}}]}}}}\n"
        ),
        4,
        &["cannot animate"],
    );
    fails_at(
        &format!(
            "{CAMERA}textures:\n  t: {{type: image, filename: {{keyframes: [{{frame: 1, value: a.png}}]}}}}\n"
        ),
        3,
        &["cannot animate", "numbers"],
    );
}

#[test]
fn bad_animation_settings_are_errors() {
    fails_at(
        &format!("{CAMERA}animation: {{fps: 0}}\n"),
        2,
        &["fps must be a positive number"],
    );
    fails_at(
        &format!("{CAMERA}animation: {{frames: [10, 1]}}\n"),
        2,
        &["first ≤ last"],
    );
    fails_at(
        "camera: {type: perspective, shutter: [0.5, 0]}\n",
        1,
        &["shutter", "open < close"],
    );
    fails_at(
        &format!(
            "{CAMERA}shapes:\n  - type: cube\n    instances: {{grid: {{count: [0, 1, 1], spacing: [1, 1, 1]}}}}\n"
        ),
        4,
        &["whole numbers of at least 1"],
    );
    fails_at(
        &format!(
            "{CAMERA}shapes:\n  - type: cube\n    instances: [{{transform: {{translate: [1, 0, 0]}}}}]\n    emitter: {{type: area, radiance: 1}}\n"
        ),
        5,
        &["instanced shape cannot carry an `emitter`"],
    );
}

#[test]
fn a_glowing_shape_that_moves_while_the_shutter_is_open_is_an_error() {
    fails_at(
        "camera: {type: perspective, look_at: {origin: [0, 0, 4], target: [0, 0, 0]}, shutter: [0, 0.5]}
animation: {frames: [1, 3]}
shapes:
  - type: sphere
    emitter: {type: area, radiance: 1}
    animation:
      translate: {keyframes: [{frame: 1, value: [0, 0, 0]}, {frame: 3, value: [1, 0, 0]}]}
",
        5,
        &["moves while the shutter is open", "cannot be motion-blurred"],
    );
}

#[test]
fn frames_outside_the_scene_are_errors() {
    let mut scene = load(ROOM).expect("parses");
    let registry = radiant::builtin_registry();
    let err = Sequence::new(
        &mut scene,
        &registry,
        &Overrides::default(),
        &SequenceOptions::default(),
        7,
    )
    .err()
    .expect("frame 7 is outside 1..6");
    assert!(
        err.to_string().contains("outside the scene's frames 1..6"),
        "{err}"
    );
}

#[test]
fn the_frame_range_spans_the_keys_when_not_given() {
    let scene = load(&format!(
        "{CAMERA}shapes:\n  - type: cube\n    animation: {{translate: {{keyframes: [{{frame: 3, value: [0, 0, 0]}}, {{frame: 40.5, value: [1, 0, 0]}}]}}}}\n"
    ))
    .expect("parses");
    assert_eq!((scene.timeline.start, scene.timeline.end), (3, 41));
    let still = load(CAMERA).expect("parses");
    assert_eq!((still.timeline.start, still.timeline.end), (1, 1));
}
