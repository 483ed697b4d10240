//! The outside crate's own binary (`src/main.rs`: the built-in registry,
//! its `stripes` texture and `radiant::cli::run`) run end to end: it
//! renders a striped scene, and `info`, `modules` and a scene error behave
//! as in the `radiant` binary.

// `unwrap` in this test code is the assertion: the inputs are the test's
// own, so a failure is a bug, and the panic reports it with the error.

use std::path::Path;
use std::process::{Command, Output};

/// A rectangle in stripes along u, lit by a point light in front.
const SCENE: &str = include_str!("../striped.yaml");

fn run(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_radiant-example-module"))
        .args(args)
        .output()
        .unwrap()
}

fn text(bytes: &[u8]) -> String {
    String::from_utf8_lossy(bytes).into_owned()
}

fn scene(dir: &Path, name: &str, yaml: &str) -> String {
    let path = dir.join(name);
    std::fs::write(&path, yaml).unwrap();
    path.to_str().unwrap().to_owned()
}

#[test]
fn renders_a_scene_with_its_own_texture() {
    let dir = tempfile::tempdir().unwrap();
    let yaml = scene(dir.path(), "striped.yaml", SCENE);
    let out = dir.path().join("striped.exr");
    let o = run(&[
        "render",
        &yaml,
        "-o",
        out.to_str().unwrap(),
        "--backend",
        "cpu",
        "--threads",
        "2",
    ]);
    assert!(o.status.success(), "{}", text(&o.stderr));
    assert!(
        text(&o.stderr).contains("rendered 32x32, 16 spp"),
        "{}",
        text(&o.stderr)
    );
    let image = radiant::film::output::read_exr(&out).unwrap();
    // u runs left to right across the rectangle: the half at u < 0.5 is
    // the bright stripe, the other the dark one.
    let column = |x: u32| -> f32 {
        (12..20)
            .map(|y| image.pixels[(y * 32 + x) as usize].x)
            .sum()
    };
    let (left, right) = (column(12), column(19));
    assert!(left > 5.0 * right, "left {left}, right {right}");
    assert!(right > 0.0, "the dark stripe is lit too: {right}");
}

#[test]
fn info_and_modules_know_the_texture() {
    let dir = tempfile::tempdir().unwrap();
    let yaml = scene(dir.path(), "striped.yaml", SCENE);
    let info = run(&["info", &yaml]);
    assert!(info.status.success(), "{}", text(&info.stderr));
    assert!(
        text(&info.stdout).contains("stripes"),
        "{}",
        text(&info.stdout)
    );
    let modules = run(&["modules"]);
    assert!(modules.status.success(), "{}", text(&modules.stderr));
    let listing = text(&modules.stdout);
    assert!(listing.contains("stripes"), "{listing}");
    assert!(listing.contains("Stripes along u"), "{listing}");
    // The built-in modules are there too.
    assert!(listing.contains("checkerboard"), "{listing}");
}

#[test]
fn a_scene_error_is_located_not_a_panic() {
    let dir = tempfile::tempdir().unwrap();
    let bad = SCENE.replace("count: 2", "count: many");
    let yaml = scene(dir.path(), "bad.yaml", &bad);
    let out = dir.path().join("bad.exr");
    let o = run(&["render", &yaml, "-o", out.to_str().unwrap()]);
    let err = text(&o.stderr);
    assert_eq!(o.status.code(), Some(1), "{err}");
    assert!(!err.contains("panicked"), "{err}");
    // `count` is on line 8 of the scene.
    assert!(err.contains("bad.yaml:8:"), "{err}");
    assert!(err.contains("count"), "{err}");
    assert!(!out.exists());
}
