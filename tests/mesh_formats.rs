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
//!
//! glTF scenes (nodes, materials, cameras, lights) are tested in `gltf.rs`.

use radiant::extract::Overrides;
use radiant::film::Image;
use radiant::film::output::read_exr;
use radiant_tests::{Tolerances, check_against, relative_difference, render_edited};
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

/// The difference allowed between a frame reached through a sequence and
/// the same file loaded as a still: they trace the same samples.
const SAME_SCENE: f64 = 0.001;

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
