//! Mesh files in every format Radiant reads, and the normals it gives
//! meshes without them. The data in `tests/data/meshes/` are made by
//! `tests/reference/render_meshes.py`: one low-poly torus as OBJ, as ASCII
//! and binary (little- and big-endian) PLY and as glTF, each coordinate
//! the same float32 in every file.
//!
//! * The same mesh in any format renders the same image, bit for bit: the
//!   readers must produce the same vertices, triangles, normals and
//!   texture coordinates, and the renderer is deterministic for a seed, so
//!   any difference at all is a reader's bug (a float tolerance would hide
//!   a swapped axis on a symmetric mesh, or a v flipped on a symmetric
//!   texture).
//! * A mesh without normals gets smooth, angle-weighted vertex normals and
//!   matches Mitsuba 3's render of the same OBJ within noise; the same
//!   mesh with `face_normals: true` (flat) must fail that comparison.
//! * Broken files are located errors naming the file and the problem.

use radiant::extract::Overrides;
use radiant::film::Image;
use radiant::film::output::read_exr;
use radiant_tests::{Tolerances, check_against, render_edited};
use std::path::Path;

const SCENE: &str = "tests/data/meshes/smooth.yaml";
const MESH_LINE: &str = "filename: torus.obj";
const MATERIAL: &str = "material: {type: diffuse, reflectance: [0.7, 0.7, 0.7]}";

/// Renders the smooth-normal scene with `filename: torus.obj` replaced by
/// `mesh` (more keys may follow the file name; a `.gltf` or `.glb` file
/// makes the shape a `gltf` one) at `spp`.
fn render_with(mesh: &str, textured: bool, spp: u32) -> Image {
    let edit = |text: &str| {
        assert!(text.contains(MESH_LINE) && text.contains(MATERIAL));
        let mut text = text.replace(MESH_LINE, mesh);
        if mesh.contains(".gltf") || mesh.contains(".glb") {
            text = text.replace("type: mesh", "type: gltf");
        }
        if textured {
            // A checkerboard of 4 × 4 squares: wrong texture coordinates
            // (v flipped, u and v swapped) move its squares.
            text = text.replace(MATERIAL, "material: {type: diffuse, reflectance: checks}");
            text.push_str(
                "textures:\n  checks_plain: {type: checkerboard, color0: [0.9, 0.8, 0.2], color1: [0.1, 0.2, 0.6]}\n  \
                 checks: {type: uv_transform, texture: checks_plain, scale: [4, 2]}\n",
            );
        }
        text
    };
    let overrides = Overrides {
        spp: Some(spp),
        ..Overrides::default()
    };
    render_edited(SCENE, edit, overrides).image
}

/// The index and values of the first pixel where `a` and `b` differ.
fn first_difference(a: &Image, b: &Image) -> Option<(usize, [f32; 3], [f32; 3])> {
    assert_eq!((a.width, a.height), (b.width, b.height));
    a.pixels
        .iter()
        .zip(&b.pixels)
        .position(|(p, q)| p.to_array().map(f32::to_bits) != q.to_array().map(f32::to_bits))
        .map(|i| (i, a.pixels[i].to_array(), b.pixels[i].to_array()))
}

#[test]
fn ply_and_obj_without_normals_render_the_same_image() {
    let obj = render_with(MESH_LINE, false, 4);
    for ply in ["torus-ascii.ply", "torus-le.ply", "torus-be.ply"] {
        let image = render_with(&format!("filename: {ply}"), false, 4);
        assert_eq!(
            first_difference(&image, &obj),
            None,
            "{ply} renders differently from torus.obj"
        );
    }
}

#[test]
fn every_format_with_normals_and_uvs_renders_the_same_image() {
    let obj = render_with("filename: torus-uv.obj", true, 4);
    let files = [
        "filename: torus-uv-ascii.ply",
        "filename: torus-uv-le.ply",
        "filename: torus-uv-be.ply",
        "filename: torus-uv.gltf",
        "filename: torus-uv.glb",
    ];
    for file in files {
        let image = render_with(file, true, 4);
        assert_eq!(
            first_difference(&image, &obj),
            None,
            "`{file}` renders differently from torus-uv.obj"
        );
    }
    // The power of the comparison: the OBJ's v read unflipped moves the
    // checks.
    let flipped = render_with("filename: torus-uv.obj, flip_tex_coords: false", true, 4);
    assert!(first_difference(&flipped, &obj).is_some());
}

/// Tolerances of the comparison with Mitsuba (8×8 blocks, 128 spp against
/// 4096). Measured: smooth normals' worst block 0.010 and channel mean
/// 0.0002; flat normals' worst block 0.31.
const SMOOTH: Tolerances = Tolerances {
    channel_mean: 0.01,
    block: 0.05,
};

#[test]
fn smooth_normals_match_mitsuba_and_flat_ones_do_not() {
    let reference = read_exr(radiant_tests::root().join("tests/data/meshes/smooth-mitsuba.exr"))
        .expect("the reference is committed");
    let smooth = render_with(MESH_LINE, false, 128);
    SMOOTH.assert_matches(&smooth, &reference, 8);
    let flat = render_with("filename: torus.obj, face_normals: true", false, 128);
    let check = check_against(&flat, &reference, 8);
    eprintln!("flat: {check:?}");
    assert!(
        !SMOOTH.passes(&check),
        "flat normals pass the comparison: {check:?}"
    );
}

/// Loads a scene with one mesh shape reading `contents` (written to a file
/// named `name`) and returns the error message.
fn mesh_error(name: &str, contents: &[u8]) -> String {
    let dir = tempfile::tempdir().expect("temporary folders can be made");
    std::fs::write(dir.path().join(name), contents).expect("temporary files are writable");
    let scene =
        format!("camera: {{type: perspective}}\nshapes:\n  - {{type: mesh, filename: {name}}}\n");
    let Err(err) = radiant::scene::from_str(&scene, Path::new("scene.yaml"), dir.path()) else {
        panic!("{name}: the broken mesh loads");
    };
    let message = err.to_string();
    assert!(message.contains("scene.yaml:3:"), "not located: {message}");
    assert!(message.contains(name), "the file is not named: {message}");
    message
}

const PLY_HEADER: &str = "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\n\
                          property float z\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n";

#[test]
fn broken_ply_files_are_located_errors() {
    let cases: &[(&str, Vec<u8>, &str)] = &[
        (
            "index.ply",
            format!("{PLY_HEADER}0 0 0\n1 0 0\n0 1 0\n3 0 1 7\n").into_bytes(),
            "face 1 refers to vertex 7 but the file has 3 vertices",
        ),
        (
            "negative.ply",
            format!("{PLY_HEADER}0 0 0\n1 0 0\n0 1 0\n3 0 1 -1\n").into_bytes(),
            "refers to vertex -1",
        ),
        (
            "two.ply",
            format!("{PLY_HEADER}0 0 0\n1 0 0\n0 1 0\n2 0 1\n").into_bytes(),
            "face 1 has 2 vertices; a face needs at least 3",
        ),
        (
            "truncated.ply",
            format!("{PLY_HEADER}0 0 0\n1 0 0\n").into_bytes(),
            "is not a valid PLY file",
        ),
        (
            "header.ply",
            b"ply\nformat ascii 1.0\nelement vertex 3\nproperty floot x\nend_header\n".to_vec(),
            "is not a valid PLY file",
        ),
        (
            "points.ply",
            b"ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\nproperty float y\nproperty float z\nend_header\n0 0 0\n"
                .to_vec(),
            "has no `face` element",
        ),
        (
            "noz.ply",
            b"ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\nproperty float y\nend_header\n0 0\n".to_vec(),
            "has no `z` property",
        ),
        (
            "short-binary.ply",
            [
                b"ply\nformat binary_little_endian 1.0\nelement vertex 3\nproperty float x\nproperty float y\n\
                  property float z\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n"
                    .as_slice(),
                &[0u8; 20],
            ]
            .concat(),
            "is not a valid PLY file",
        ),
    ];
    for (name, contents, expected) in cases {
        let message = mesh_error(name, contents);
        eprintln!("{name}: {message}");
        assert!(message.contains(expected), "{name}: {message}");
    }
}

/// The glTF scene's contents written in Radiant's YAML: the camera, the
/// lights (the spot and the sun shining along their nodes' turned −z), the
/// torus placed by the two nodes' transforms (parent translation, child
/// rotation and scale) and its material.
const GLTF_AS_YAML: &str = "\
camera: {type: perspective, fov: 30, fov_axis: y, look_at: {origin: [0, 0, 6], target: [0, 0, 0], up: [0, 1, 0]}}
textures: {checks: {type: image, filename: checks.png}}
materials: {torus: {type: principled, base_color: checks, metallic: 0.3, roughness: 0.6}}
shapes:
  - {type: mesh, filename: torus-uv.obj, material: torus, transform: [{translate: [0.3, -0.2, 0]}, {rotate: {axis: [1, 0, 0], angle: 90}}, {scale: 0.8}]}
lights:
  - {type: point, position: [3, 3, 2], intensity: [25, 22.5, 20]}
  - {type: spot, position: [-1, 2, 4], direction: [0, -0.5, -0.8660254037844387], intensity: [20, 20, 40], cutoff_angle: 28.64788975654116, beam_width: 17.188733853924695}
  - {type: directional, direction: [-0.7071067811865475, 0, -0.7071067811865475], irradiance: 0.5}
";

/// What both glTF comparisons render: a dim environment (glTF has none).
const SETTINGS: &str = "\
integrator: {type: path, max_depth: 3}
film: {width: 96, height: 64, filter: {type: gaussian, stddev: 0.5}}
sampler: {type: independent, spp: 16}
";

/// Renders `body` (after [`SETTINGS`], with an environment light added
/// where it has a `lights:` list) in `tests/data/meshes/`.
fn render_text(body: &str) -> Result<Image, String> {
    render_text_in(&radiant_tests::root().join("tests/data/meshes"), body)
}

/// As [`render_text`], with files relative to `dir`.
fn render_text_in(dir: &Path, body: &str) -> Result<Image, String> {
    use radiant::backend::cpu::{Progress, render};
    let text = format!("{SETTINGS}{body}  - {{type: environment, radiance: 0.1}}\n");
    let scene = radiant::scene::from_str(&text, &dir.join("gltf-test.yaml"), dir)
        .map_err(|e| e.to_string())?;
    let r = radiant::extract::extract(&scene, &radiant::builtin_registry(), &Overrides::default())
        .map_err(|e| e.to_string())?;
    Ok(render(&r, &Progress::none()).image)
}

/// The mean of |a − b| over all channels, relative to the mean of `b`.
fn relative_difference(a: &Image, b: &Image) -> f64 {
    assert_eq!((a.width, a.height), (b.width, b.height));
    let (mut diff, mut sum) = (0.0f64, 0.0f64);
    for (p, q) in a.pixels.iter().zip(&b.pixels) {
        diff += f64::from((*p - *q).abs().element_sum());
        sum += f64::from(q.element_sum());
    }
    diff / sum
}

/// The same difference allowed between the glTF scene and its YAML twin:
/// they trace the same sample sequence, so what differs is the rounding of
/// the transforms (the node's float quaternion against the YAML's rotation
/// by 90°). Measured: below 10⁻⁵; a node transform left out costs 0.095
/// or more, metalness 0.9 instead of 0.3 costs 0.0099.
const SAME_SCENE: f64 = 0.001;

#[test]
fn gltf_nodes_material_texture_camera_and_lights_are_imported() {
    let gltf = render_text(
        "camera: {type: gltf, filename: scene.gltf}\nshapes:\n  - {type: gltf, filename: scene.gltf}\nlights:\n",
    )
    .expect("the glTF scene renders");
    let yaml = |from: &str, to: &str| {
        assert!(GLTF_AS_YAML.contains(from), "{from}");
        render_text(&GLTF_AS_YAML.replace(from, to)).expect("the YAML twin renders")
    };
    let same = relative_difference(&gltf, &yaml("", ""));
    eprintln!("glTF against YAML: {same:.2e}");
    assert!(
        same < SAME_SCENE,
        "the glTF scene differs from its YAML twin: {same}"
    );
    // The comparison's power: without the parent's translation or the
    // child's rotation, with another metalness, or with a light turned
    // or left out, the images differ.
    let wrong = [
        ("{translate: [0.3, -0.2, 0]}, ", ""),
        ("{rotate: {axis: [1, 0, 0], angle: 90}}, ", ""),
        ("metallic: 0.3", "metallic: 0.9"),
        ("direction: [0, -0.5,", "direction: [0, 0.5,"),
        (
            "direction: [-0.7071067811865475,",
            "direction: [0.7071067811865475,",
        ),
        (POINT_LIGHT_LINE, ""),
    ];
    for (from, to) in wrong {
        let d = relative_difference(&gltf, &yaml(from, to));
        eprintln!("`{from}` → `{to}`: {d:.5}");
        assert!(d > 5.0 * SAME_SCENE, "`{from}` → `{to}`: only {d}");
    }
    // With `lights: false` the glTF's lights stay out: the image is the
    // YAML twin's without them.
    let unlit = render_text(
        "camera: {type: gltf, filename: scene.gltf}\nshapes:\n  - {type: gltf, filename: scene.gltf, lights: false}\nlights:\n",
    )
    .expect("the glTF scene renders");
    let lights = GLTF_AS_YAML.find("lights:\n").expect("a light list") + "lights:\n".len();
    let twin = render_text(&GLTF_AS_YAML[..lights]).expect("the YAML twin renders");
    let d = relative_difference(&unlit, &twin);
    assert!(
        d < SAME_SCENE,
        "lights: false differs from the scene without the lights: {d}"
    );
}

/// A glTF material's normal texture becomes a `normal_map` around its
/// `principled` material (the image read raw), and its emissive factor an
/// `area` emitter on its meshes.
#[test]
fn gltf_normal_textures_and_emission_are_imported() {
    let data = radiant_tests::root().join("tests/data/meshes");
    let dir = tempfile::tempdir().expect("temporary folders can be made");
    for file in ["checks.png", "torus-uv.obj"] {
        std::fs::copy(data.join(file), dir.path().join(file)).expect("copyable");
    }
    let text = std::fs::read_to_string(data.join("scene.gltf")).expect("the glTF is committed");
    let from = "\"name\": \"checked metal\",";
    assert!(text.contains(from));
    let edited = text.replace(
        from,
        "\"name\": \"checked metal\", \"normalTexture\": {\"index\": 0}, \"emissiveFactor\": [0.2, 0.1, 0.05],",
    );
    std::fs::write(dir.path().join("scene.gltf"), edited).expect("writable");
    let gltf = render_text_in(
        dir.path(),
        "camera: {type: gltf, filename: scene.gltf}\nshapes:\n  - {type: gltf, filename: scene.gltf}\nlights:\n",
    )
    .expect("the glTF scene renders");
    let twin = |material: &str, emitter: &str| {
        let yaml = GLTF_AS_YAML
            .replace(
                "textures: {checks: {type: image, filename: checks.png}}",
                "textures: {checks: {type: image, filename: checks.png}, \
                 raw: {type: image, filename: checks.png, raw: true}}",
            )
            .replace(
                "materials: {torus: {type: principled, base_color: checks, metallic: 0.3, roughness: 0.6}}",
                &format!("materials: {{torus: {material}}}"),
            )
            .replace("material: torus,", &format!("material: torus, {emitter}"));
        render_text_in(dir.path(), &yaml).expect("the YAML twin renders")
    };
    let principled = "{type: principled, base_color: checks, metallic: 0.3, roughness: 0.6}";
    let mapped = format!("{{type: normal_map, normals: raw, material: {principled}}}");
    let glow = "emitter: {type: area, radiance: [0.2, 0.1, 0.05]},";
    let same = relative_difference(&gltf, &twin(&mapped, glow));
    eprintln!("glTF against YAML: {same:.2e}");
    assert!(same < SAME_SCENE, "differs from its YAML twin: {same}");
    for (material, emitter) in [(principled, glow), (mapped.as_str(), "")] {
        let d = relative_difference(&gltf, &twin(material, emitter));
        eprintln!("{material} {emitter}: {d:.5}");
        assert!(d > 5.0 * SAME_SCENE, "{material} {emitter}: only {d}");
    }
}

const POINT_LIGHT_LINE: &str =
    "  - {type: point, position: [3, 3, 2], intensity: [25, 22.5, 20]}\n";

/// Loads the glTF scene with its text changed by `edit` (written beside a
/// copy of `checks.png`) and returns the error.
fn gltf_error(edit: impl Fn(&str) -> String, camera: bool) -> String {
    let data = radiant_tests::root().join("tests/data/meshes");
    let text = std::fs::read_to_string(data.join("scene.gltf")).expect("the glTF is committed");
    let dir = tempfile::tempdir().expect("temporary folders can be made");
    std::fs::write(dir.path().join("broken.gltf"), edit(&text)).expect("writable");
    std::fs::copy(data.join("checks.png"), dir.path().join("checks.png")).expect("copyable");
    let scene = if camera {
        "camera: {type: gltf, filename: broken.gltf}\n".to_string()
    } else {
        "camera: {type: perspective}\nshapes:\n  - {type: gltf, filename: broken.gltf}\n"
            .to_string()
    };
    let Err(err) = radiant::scene::from_str(&scene, Path::new("scene.yaml"), dir.path()) else {
        panic!("the broken glTF loads");
    };
    let message = err.to_string();
    assert!(message.contains("scene.yaml:"), "not located: {message}");
    assert!(
        message.contains("broken.gltf"),
        "the file is not named: {message}"
    );
    message
}

/// A change to the glTF file's text.
type Edit = Box<dyn Fn(&str) -> String>;

#[test]
fn broken_gltf_files_are_located_errors() {
    let data_uri = "\"uri\": \"data:application/octet-stream;base64,";
    let cases: Vec<(Edit, bool, &str)> = vec![
        (
            Box::new(|t| t[..t.len() / 2].to_string()),
            false,
            "is not valid glTF 2.0",
        ),
        (
            Box::new(move |t| {
                let start = t.find(data_uri).expect("an embedded buffer");
                let body = start + data_uri.len();
                let end = body + t[body..].find('"').expect("its end") + 1;
                format!("{}\"uri\": \"torus.bin\"{}", &t[..start], &t[end..])
            }),
            false,
            "buffer 0 is the file `torus.bin`, which cannot be read",
        ),
        (
            Box::new(|t| t.replacen("\"count\": 128", "\"count\": 4000", 1)),
            false,
            "accessor 0 needs 48000 bytes of buffer view 0, which has 1536",
        ),
        (
            Box::new(|t| t.replace("\"mode\": 4", "\"mode\": 0")),
            false,
            "draws Points, which Radiant does not render",
        ),
        (
            Box::new(|t| t.replace("\"uri\": \"checks.png\"", "\"uri\": \"missing.png\"")),
            false,
            "image 0 is the file `missing.png`, which cannot be read",
        ),
        (
            Box::new(|t| {
                t.replace(
                    "\"uri\": \"checks.png\"",
                    "\"uri\": \"data:image/png;base64,AAAA\"",
                )
            }),
            false,
            "image 0 is embedded",
        ),
        (
            Box::new(|t| t.replace("\"camera\": 0,", "")),
            true,
            "has no camera in its scene",
        ),
    ];
    for (edit, camera, expected) in cases {
        let message = gltf_error(edit, camera);
        eprintln!("{message}");
        assert!(
            message.contains(expected),
            "expected `{expected}` in: {message}"
        );
    }
}

/// A deforming mesh without normals (an OBJ per frame, as a simulation
/// writes them) gets at every frame the smooth normals of that frame's
/// positions: frame 4 reached through frames 1 to 3 renders as frame 4's
/// file loaded as a still mesh, and not as that file with flat normals.
#[test]
fn a_deforming_mesh_gets_the_smooth_normals_of_each_frame() {
    use radiant::backend::cpu::{Progress, render};
    use radiant::extract::{Sequence, SequenceOptions};
    let dir = tempfile::tempdir().expect("temporary folders can be made");
    for f in 1..=4 {
        let path = dir.path().join(format!("wave_{f:03}.obj"));
        radiant_tests::write_grid(&path, 12, f as f32 * 0.9, false);
    }
    let scene = |filename: &str, frames: &str| {
        format!(
            "animation: {{fps: 24, frames: {frames}}}\nfilm: {{width: 48, height: 48}}\n\
             sampler: {{type: independent, spp: 8}}\n\
             camera: {{type: perspective, look_at: {{origin: [0, -2, 3], target: [0, 0, 0]}}}}\n\
             shapes:\n  - {{type: mesh, filename: {filename}, material: {{type: diffuse, reflectance: 0.8}}}}\n\
             lights:\n  - {{type: point, position: [1, -1, 2], intensity: 5}}\n"
        )
    };
    let registry = radiant::builtin_registry();
    let load = |text: &str| {
        radiant::scene::from_str(text, Path::new("wave.yaml"), dir.path())
            .expect("the scene parses")
    };
    let mut animated = load(&scene("wave_###.obj", "[1, 4]"));
    // Locked noise: every frame draws the samples of a still render.
    let options = SequenceOptions {
        lock_noise: true,
        ..SequenceOptions::default()
    };
    let (mut s, _) = Sequence::new(&mut animated, &registry, &Overrides::default(), &options, 1)
        .expect("the first frame builds");
    for f in 2..=4 {
        s.go_to(&mut animated, &registry, f)
            .expect("the frame updates");
    }
    let frame4 = render(s.scene(), &Progress::none()).image;
    let still = |filename: &str| {
        let scene = load(&scene(filename, "[1, 1]"));
        let r = radiant::extract::extract(&scene, &registry, &Overrides::default())
            .expect("the scene extracts");
        render(&r, &Progress::none()).image
    };
    let smooth = relative_difference(&frame4, &still("wave_004.obj"));
    let flat = relative_difference(&frame4, &still("wave_004.obj, face_normals: true"));
    let first = relative_difference(&frame4, &still("wave_001.obj"));
    eprintln!(
        "frame 4 against its file: smooth {smooth:.2e}, flat {flat:.2e}, frame 1 {first:.2e}"
    );
    assert!(
        smooth < SAME_SCENE,
        "frame 4 differs from its file: {smooth}"
    );
    assert!(flat > 5.0 * SAME_SCENE && first > 5.0 * SAME_SCENE);
}
