//! The README's examples are the files that build and run here: its module
//! example is this crate's `src/lib.rs` and `src/main.rs` as they compile,
//! and its example scene renders with the files the repository ships.

// `unwrap` in this test code is the assertion: the README and the scenes
// are the repository's own, so a failure is a bug the panic reports.

use radiant::backend::cpu::{Progress, render};
use radiant::extract::{Overrides, extract};
use std::path::Path;

const README: &str = include_str!("../../../README.md");

/// The text of `file` from the line that starts with `from` on.
fn from_line<'a>(file: &'a str, from: &str) -> &'a str {
    &file[file.find(from).unwrap()..]
}

/// The README's fenced blocks in `lang`.
fn blocks(lang: &str) -> Vec<&'static str> {
    let fence = format!("```{lang}\n");
    README
        .split(fence.as_str())
        .skip(1)
        .map(|rest| &rest[..rest.find("```").unwrap()])
        .collect()
}

#[test]
fn the_readme_module_example_is_the_crate_that_compiles() {
    let lib = from_line(include_str!("../src/lib.rs"), "use radiant::");
    let main = from_line(include_str!("../src/main.rs"), "/// Allocation failure");
    let rust = blocks("rust");
    assert!(
        rust.contains(&lib),
        "README's module example differs from tests/outside-module/src/lib.rs"
    );
    assert!(
        rust.contains(&main),
        "README's binary differs from tests/outside-module/src/main.rs"
    );
}

#[test]
fn the_readme_scene_renders_with_files_the_repository_ships() {
    let text = from_line(README, "## Scenes");
    let yaml = text.split("```yaml\n").nth(1).unwrap();
    let yaml = &yaml[..yaml.find("```").unwrap()];
    let scenes = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../scenes");
    let scene =
        radiant::scene::from_str(yaml, &scenes.join("readme-example.yaml"), &scenes).unwrap();
    let overrides = Overrides {
        width: Some(24),
        height: Some(24),
        spp: Some(4),
        ..Overrides::default()
    };
    let r = extract(&scene, &radiant::builtin_registry(), &overrides).unwrap();
    assert!(r.stats.triangles >= 20 + 12 + 2, "{:?}", r.stats);
    let image = render(&r, &Progress::none()).image;
    assert!(image.pixels.iter().all(|p| p.is_finite()));
    let mean = image.pixels.iter().map(|p| p.x).sum::<f32>() / image.pixels.len() as f32;
    assert!(mean > 0.0, "the scene is lit: mean {mean}");
}
