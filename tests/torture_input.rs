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
