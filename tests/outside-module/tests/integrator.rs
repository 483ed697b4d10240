//! An outside crate's integrator registers, renders and is listed like a
//! built-in one.

// `unwrap` in this test code is the assertion: the scenes are the test's
// own, so a failure is a bug, and the panic reports it with the error.

use radiant::backend::cpu::{Progress, render};
use radiant::core::ModuleKind;
use radiant::extract::{Overrides, extract};
use std::path::Path;

/// A camera looking down −z at nothing, rendered by `integrator`.
fn scene(integrator: &str) -> String {
    format!(
        "film: {{width: 33, height: 33, filter: {{type: box}}}}\n\
         sampler: {{type: independent, spp: 8}}\n\
         integrator: {integrator}\n\
         camera: {{type: perspective, fov: 90, look_at: {{origin: [0, 0, 0], target: [0, 0, -1]}}}}\n"
    )
}

#[test]
fn an_outside_integrator_renders_what_it_computes() {
    let mut registry = radiant::builtin_registry();
    radiant_example_module::register(&mut registry);
    assert!(
        registry
            .modules()
            .iter()
            .any(|(k, i)| *k == ModuleKind::Integrator && i.type_name == "directions")
    );
    let text = scene("{type: directions, max_depth: 3}");
    let s = radiant::scene::from_str(&text, Path::new("inline.yaml"), Path::new(".")).unwrap();
    let r = extract(&s, &registry, &Overrides::default()).unwrap();
    let image = render(&r, &Progress::none()).image;
    // The centre pixel looks down −z: (0.5, 0.5, 0); the corners lean
    // out by 45° on each axis at fov 90.
    let centre = image.pixels[16 * 33 + 16];
    assert!(
        (centre - radiant::core::Rgb::new(0.5, 0.5, 0.0))
            .abs()
            .max_element()
            < 0.02,
        "{centre}"
    );
    let top_left = image.pixels[0];
    assert!(top_left.x < 0.3 && top_left.y > 0.7, "{top_left}");
    // It refuses the GPU by name.
    let err = radiant::backend::gpu::Plan::check(&r)
        .err()
        .unwrap()
        .to_string();
    assert!(err.contains("directions"), "{err}");
}

#[test]
fn unknown_integrators_and_keys_are_located_errors() {
    let registry = radiant::builtin_registry();
    let text = scene("{type: directions}");
    let s = radiant::scene::from_str(&text, Path::new("inline.yaml"), Path::new(".")).unwrap();
    let err = extract(&s, &registry, &Overrides::default())
        .err()
        .unwrap()
        .to_string();
    assert!(
        err.contains("inline.yaml:3:")
            && err.contains("unknown integrator type `directions`")
            && err.contains("path"),
        "{err}"
    );
    let text = scene("{type: path, bounces: 3}");
    let s = radiant::scene::from_str(&text, Path::new("inline.yaml"), Path::new(".")).unwrap();
    let err = extract(&s, &registry, &Overrides::default())
        .err()
        .unwrap()
        .to_string();
    assert!(err.contains("bounces"), "{err}");
}
