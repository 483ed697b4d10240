//! The outside module builds, registers and renders like a built-in one,
//! on the CPU and, through its own WGSL, on the GPU.

// `unwrap` in this test code is the assertion: the scene is the test's own,
// so a failure is a bug, and the panic reports it with the error.

use radiant::backend::cpu::{Progress, render};
use radiant::backend::{BackendKind, choose};
use radiant::core::glam::Vec2;
use radiant::core::{Effects, ModuleInfo, Params, Rgb, Texture};
use radiant::extract::{Overrides, extract};
use std::path::Path;

/// The scene the crate's binary renders too (`tests/cli.rs`).
const SCENE: &str = include_str!("../striped.yaml");

#[test]
fn outside_texture_renders() {
    let mut registry = radiant::builtin_registry();
    radiant_example_module::register(&mut registry);
    let scene = radiant::scene::from_str(SCENE, Path::new("inline.yaml"), Path::new(".")).unwrap();
    let r = extract(&scene, &registry, &Overrides::default()).unwrap();
    assert!(r.modules.iter().any(|(_, t)| t == "stripes"));
    let image = render(&r, &Progress::none()).image;
    // u runs left to right across the rectangle: stripes at u < 0.5 are
    // bright, the next half dark. Compare two columns inside the rectangle.
    let column = |x: u32| -> f32 {
        (12..20)
            .map(|y| image.pixels[(y * 32 + x) as usize].x)
            .sum()
    };
    let (left, right) = (column(12), column(19));
    assert!(left > 5.0 * right, "left {left}, right {right}");
}

#[test]
fn outside_texture_renders_on_the_gpu_with_its_own_wgsl() {
    let mut registry = radiant::builtin_registry();
    radiant_example_module::register(&mut registry);
    let scene = radiant::scene::from_str(SCENE, Path::new("inline.yaml"), Path::new(".")).unwrap();
    let r = extract(&scene, &registry, &Overrides::default()).unwrap();
    let plan = radiant::backend::gpu::Plan::new(&r).unwrap();
    assert!(plan.kernel.source.contains("fn texture_stripes("));
    // `expect` in this test code is the assertion: CI provides an adapter
    // (lavapipe), so one must be found.
    let mut gpu = radiant::backend::gpu::GpuBackend::new(&Default::default())
        .expect("a GPU adapter (lavapipe in CI)");
    let image = gpu.render(&r, &Progress::none()).unwrap().image;
    let cpu = render(&r, &Progress::none()).image;
    for (g, c) in image.pixels.iter().zip(&cpu.pixels) {
        assert!(
            (*g - *c).abs().max_element() <= 1e-3 * c.max_element().max(1.0),
            "{g} against {c}"
        );
    }
}

#[test]
fn builtin_registry_does_not_know_it() {
    let scene = radiant::scene::from_str(SCENE, Path::new("inline.yaml"), Path::new(".")).unwrap();
    let err = extract(&scene, &radiant::builtin_registry(), &Overrides::default())
        .err()
        .expect("unknown type");
    assert!(
        err.to_string().contains("unknown texture type `stripes`"),
        "{err}"
    );
}

/// A texture with no GPU side, as an outside crate may write one.
struct Flat;

impl Texture for Flat {
    fn eval(&self, _uv: &[Vec2], out: &mut [Rgb]) {
        out.fill(Rgb::splat(0.5));
    }

    fn mean(&self) -> Rgb {
        Rgb::splat(0.5)
    }

    fn effects(&self) -> Effects {
        Effects::TEXTURES
    }
}

/// A module without GPU code: `--backend gpu` refuses the scene naming
/// the module and its type, and `auto` renders it on the CPU, saying why.
#[test]
fn a_module_without_gpu_code_is_named_and_auto_falls_back_to_the_cpu() {
    let mut registry = radiant::builtin_registry();
    registry.register::<dyn Texture>(
        ModuleInfo {
            type_name: "flat",
            summary: "Mid grey, CPU only.",
            params: &[],
        },
        |_: &Params, _| Ok(Box::new(Flat) as Box<dyn Texture>),
    );
    let text = SCENE.replace(
        "{type: stripes, a: [0.9, 0.9, 0.9], b: [0.05, 0.05, 0.05], count: 2}",
        "{type: flat}",
    );
    let scene = radiant::scene::from_str(&text, Path::new("inline.yaml"), Path::new(".")).unwrap();
    let r = extract(&scene, &registry, &Overrides::default()).unwrap();
    let err = radiant::backend::gpu::Plan::new(&r)
        .err()
        .expect("no GPU code");
    let message = err.to_string();
    assert!(
        message.contains("texture `stripes`")
            && message.contains("type `flat`")
            && message.contains("no GPU code"),
        "{message}"
    );
    let options = Default::default();
    let refused = choose(BackendKind::Gpu, &options, &r, &mut |_| {});
    assert!(refused.is_err(), "--backend gpu must refuse the scene");
    let mut notes = Vec::new();
    let mut backend = choose(BackendKind::Auto, &options, &r, &mut |n| notes.push(n)).unwrap();
    assert!(
        notes
            .iter()
            .any(|n| n.contains("backend: cpu") && n.contains("`flat`")),
        "{notes:?}"
    );
    let image = backend.render(&r, &Progress::none()).unwrap().image;
    assert!(
        image.pixels.iter().any(|p| p.x > 0.0),
        "auto rendered nothing"
    );
}
