//! Torture suite, degenerate input: OBJ meshes with zero-area and needle
//! triangles, repeated vertices, NaN and infinite coordinates, a
//! zero-length normal, a NaN texture coordinate and no texture coordinates
//! at all (`scenes/hard/meshes/degenerate*.obj`). The loader drops or
//! repairs each case, counts it, and the render is finite.

use radiant::extract::{Overrides, extract};
use radiant::world::MeshRepairs;
use radiant_tests::{render_checked, root};

const SCENE: &str = "scenes/hard/degenerate-mesh.yaml";

#[test]
fn degenerate_meshes_are_repaired_counted_and_render_finite() {
    let scene = radiant::scene::load(root().join(SCENE)).expect("scene loads");
    let r = extract(&scene, &radiant::builtin_registry(), &Overrides::default())
        .expect("scene extracts");
    let stats = &r.stats;
    // degenerate.obj: 8 faces. Dropped: 2 non-finite (NaN, inf vertex), 3
    // of zero area (collinear, the same index twice, two vertices at the
    // same position); kept: the quad's 2 triangles and the needle (30 long,
    // 1e-7 high). degenerate-uv.obj: 1 kept, 1 of zero area dropped.
    // The light is a rectangle: 2 more.
    assert_eq!(stats.triangles, 3 + 1 + 2);
    let bad = MeshRepairs {
        non_finite: 2,
        degenerate: 3,
        bad_normals: 1,
        bad_uvs: 0,
        missing_uvs: true,
    };
    let bad_uv = MeshRepairs {
        degenerate: 1,
        bad_uvs: 1,
        ..Default::default()
    };
    let shapes: Vec<_> = stats.repaired_shapes.iter().map(|(_, m)| *m).collect();
    assert_eq!(shapes, [bad, bad_uv]);
    assert!(stats.repaired_shapes[0].0.contains("degenerate.obj"));
    assert_eq!(
        bad.describe(),
        "dropped 2 triangles with non-finite coordinates and 3 triangles of zero area, \
         replaced 1 vertex normal of zero length or non-finite by the face normal"
    );
    let mut total = bad;
    total.add(&bad_uv);
    assert_eq!(stats.repairs, total);

    let image = render_checked(
        SCENE,
        Overrides {
            seed: Some(3),
            ..Default::default()
        },
    );
    assert!(image.mean() > 0.0, "the repaired meshes are lit and seen");
}

#[test]
fn a_mesh_with_nothing_usable_is_an_error_with_its_location() {
    let dir = tempfile::tempdir().expect("temp dir");
    std::fs::write(
        dir.path().join("bad.obj"),
        "v 0 0 0\nv nan 0 0\nv 1 1 1\nf 1 2 3\nf 1 1 3\n",
    )
    .expect("written");
    let text = "camera: {type: perspective}\nshapes:\n  - {type: mesh, filename: bad.obj}\n";
    let err = radiant::scene::from_str(text, std::path::Path::new("bad.yaml"), dir.path())
        .err()
        .expect("rejected");
    let shown = err.to_string();
    assert!(shown.starts_with("bad.yaml:3:"), "{shown}");
    assert!(
        shown.contains(
            "no usable triangles (1 dropped as degenerate, 1 for non-finite coordinates)"
        ),
        "{shown}"
    );
}

/// Loads (and, past the scene file, extracts) `text` from `dir` and
/// returns the error it must give.
fn scene_error(text: &str, dir: &std::path::Path) -> String {
    let path = std::path::Path::new("bad.yaml");
    match radiant::scene::from_str(text, path, dir) {
        Err(e) => e.to_string(),
        Ok(scene) => extract(&scene, &radiant::builtin_registry(), &Overrides::default())
            .err()
            .expect("rejected")
            .to_string(),
    }
}

/// `/dev/zero`, a FIFO and a folder named as a mesh, a texture or an
/// environment map: each is a located error that says what the path is,
/// at once (a FIFO would block a reader forever, `/dev/zero` never ends).
#[test]
fn special_files_are_located_errors_at_once() {
    let dir = tempfile::tempdir().expect("temp dir");
    let fifo = dir.path().join("pipe.exr");
    let made = std::process::Command::new("mkfifo")
        .arg(&fifo)
        .status()
        .expect("mkfifo runs");
    assert!(made.success(), "mkfifo failed");
    let folder = dir.path().join("folder.exr");
    std::fs::create_dir(&folder).expect("folder");
    let cases = [
        ("/dev/zero", "a character device"),
        (fifo.to_str().expect("utf-8"), "a FIFO"),
        (folder.to_str().expect("utf-8"), "a folder"),
    ];
    let head = "camera: {type: perspective}\n";
    for (path, kind) in cases {
        let uses = [
            (
                format!("{head}shapes:\n  - {{type: mesh, filename: '{path}'}}\n"),
                3,
            ),
            (
                format!(
                    "{head}textures:\n  t: {{type: image, filename: '{path}'}}\nshapes:\n  - {{type: sphere, material: {{type: diffuse, reflectance: t}}}}\n"
                ),
                3,
            ),
            (
                format!("{head}lights:\n  - {{type: environment, filename: '{path}'}}\n"),
                3,
            ),
        ];
        for (text, line) in uses {
            let start = std::time::Instant::now();
            let shown = scene_error(&text, dir.path());
            let took = start.elapsed();
            assert!(took.as_secs_f64() < 1.0, "{path}: took {took:?}");
            assert!(
                shown.starts_with(&format!("bad.yaml:{line}:")),
                "{path}: {shown}"
            );
            assert!(shown.contains(kind), "{path}: {shown}");
            assert!(shown.contains("not a regular file"), "{path}: {shown}");
        }
    }
}

/// A 100 MB OBJ "line" (a file with no line breaks) is a located error
/// after the first megabyte, not a 100 MB string.
#[test]
fn an_obj_without_line_breaks_is_a_located_error() {
    let dir = tempfile::tempdir().expect("temp dir");
    let file = std::fs::File::create(dir.path().join("long.obj")).expect("created");
    file.set_len(100 << 20).expect("100 MB of zero bytes");
    let text = "camera: {type: perspective}\nshapes:\n  - {type: mesh, filename: long.obj}\n";
    let start = std::time::Instant::now();
    let shown = scene_error(text, dir.path());
    assert!(
        start.elapsed().as_secs_f64() < 1.0,
        "took {:?}",
        start.elapsed()
    );
    assert!(shown.starts_with("bad.yaml:3:"), "{shown}");
    assert!(
        shown.contains("line 1 is longer than 1048576 bytes"),
        "{shown}"
    );
}
