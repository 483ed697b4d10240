//! The GPU backend chooses lights as the CPU does: `light_selection:
//! spatial` (each light's bounds' importance at the shading point, every
//! light evaluated up to 16 bounded lights, the light tree beyond), and
//! `power`, rendered by both backends and compared by channel means and
//! block means.
//!
//! Both backends run the same estimator with the same sampler dimensions,
//! so their paths coincide sample for sample and the images differ only
//! where float rounding sends a path elsewhere. The choice among lights of
//! very different power and placement is the largest part of these
//! scenes' noise, so a GPU whose probabilities drift from the CPU's
//! renders a different image. Mutations of `wgsl/light_selection.wgsl`,
//! one at a time (worst 8×8 block error against the CPU's image; the
//! tolerance is 0.3 %): the next-event probability 2 % high for the area
//! light (1.5 %) or the spot (1.8 %) of [`THREE_LIGHTS`], for one spot of
//! the 24 lights in the tree (0.61 %); the emitter hits' MIS probability
//! 2 % high, every light (0.59 % over the glossy floor) or every light in
//! the tree (0.36 % over the glossy floor); a 2 % scale of the image. All
//! fail. (Over the diffuse floors the MIS probability hardly matters: the
//! small rectangles are reached by light sampling, where the BSDF
//! strategy's weight is near 0.)

// `unwrap`/`expect` in this test code are the assertions: the scenes are
// the test's own, so a failure is a bug, and the panic reports it.

use radiant::extract::{FLAT_LIMIT, Overrides, RenderScene, extract};
use radiant::scene::LightSelection;
use radiant_tests::gpu::{assert_agrees, render_extracted};
use radiant_tests::{Tolerances, root};
use std::fmt::Write;

/// A floor and a ball lit directly by a spot light, a point light and a
/// small rectangle light of very different power and placement (issue
/// 23's spot + point kind of scene), seen at depth 3 so that emitter hits
/// are weighted by MIS.
const THREE_LIGHTS: &str = "integrator: {type: path, max_depth: 3}
film: {width: 48, height: 48, filter: {type: box}}
sampler: {type: independent, spp: 64}
camera: {type: perspective, fov: 50, look_at: {origin: [0, 3, 4], target: [0, 0, 0], up: [0, 1, 0]}}
materials:
  grey: {type: diffuse, reflectance: 0.6}
shapes:
  - {type: rectangle, material: grey, transform: [{rotate: {axis: [1, 0, 0], angle: -90}}, {scale: 3}]}
  - {type: sphere, center: [0.3, 0.4, 0], radius: 0.4, material: grey}
  - type: rectangle
    material: grey
    transform: [{translate: [-1, 2, -0.5]}, {rotate: {axis: [1, 0, 0], angle: 90}}, {scale: 0.2}]
    emitter: {type: area, radiance: [40, 40, 40]}
lights:
  - {type: spot, position: [1, 3, 1], target: [0, 0, 0], intensity: [30, 28, 25], cutoff_angle: 30}
  - {type: point, position: [-3, 2, -3], intensity: [20, 20, 22]}
";

/// A floor under 24 lights of every bounded kind (points, spots, small
/// rectangle emitters facing down) spread over it with powers spanning
/// 40×, and the sky: more than [`FLAT_LIMIT`] bounded lights, so the GPU
/// walks the light tree, and one unbounded light with its fixed share.
fn many_lights() -> String {
    let mut s = String::from(
        "integrator: {type: path, max_depth: 3}
film: {width: 48, height: 48, filter: {type: box}}
sampler: {type: independent, spp: 64}
camera: {type: perspective, fov: 60, look_at: {origin: [0, 5, 6], target: [0, 0, 0], up: [0, 1, 0]}}
materials:
  grey: {type: diffuse, reflectance: 0.6}
shapes:
  - {type: rectangle, material: grey, transform: [{rotate: {axis: [1, 0, 0], angle: -90}}, {scale: 5}]}
  - {type: sphere, center: [0.5, 0.6, 0.5], radius: 0.6, material: grey}
",
    );
    let mut lights = String::from(
        "lights:
  - {type: environment, filename: environment-sky.exr, scale: 0.05}
",
    );
    for i in 0..24 {
        let f = i as f32;
        let (x, z) = (
            (f * 0.37).fract() * 8.0 - 4.0,
            (f * 0.61).fract() * 8.0 - 4.0,
        );
        let y = 0.5 + (f * 0.23).fract() * 2.0;
        let power = 0.5 + 20.0 * (f * 0.77).fract();
        match i % 3 {
            0 => writeln!(
                lights,
                "  - {{type: point, position: [{x}, {y}, {z}], intensity: [{power}, {power}, {power}]}}"
            ),
            1 => writeln!(
                lights,
                "  - {{type: spot, position: [{x}, {y}, {z}], target: [{}, 0, {}], intensity: [{p}, {p}, {p}], cutoff_angle: 35}}",
                x * 0.5,
                z * 0.5,
                p = power * 2.0
            ),
            _ => writeln!(
                s,
                "  - type: rectangle
    material: grey
    transform: [{{translate: [{x}, {y}, {z}]}}, {{rotate: {{axis: [1, 0, 0], angle: 90}}}}, {{scale: 0.15}}]
    emitter: {{type: area, radiance: [{r}, {r}, {r}]}}",
                r = power * 4.0
            ),
        }
        .expect("writing to a String");
    }
    s + &lights
}

/// `text` (a scene in `scenes/`, for the sky's file) extracted with
/// `selection` at `spp`.
fn extract_text(text: &str, selection: LightSelection, spp: u32) -> RenderScene {
    let dir = root().join("scenes");
    let scene = radiant::scene::from_str(text, &dir.join("light-selection.yaml"), &dir)
        .expect("scene parses");
    let overrides = Overrides {
        light_selection: Some(selection),
        spp: Some(spp),
        ..Overrides::default()
    };
    extract(&scene, &radiant::builtin_registry(), &overrides).expect("scene extracts")
}

/// Channel means within 0.2 %, 8×8 blocks within 0.3 %: twelve times the
/// float rounding that separates the two backends' paths on lavapipe (at
/// most 2e-6 and 2.5e-4 in these scenes), below what the mutations listed
/// above do (0.36 % and more).
const SAME_CHOICE: Tolerances = Tolerances {
    channel_mean: 0.002,
    block: 0.003,
};

#[test]
fn spatial_selection_among_three_lights() {
    let scene = extract_text(THREE_LIGHTS, LightSelection::Spatial, 64);
    assert!(scene.lights.is_spatial());
    let name = "three lights, spatial";
    assert_agrees(name, render_extracted(name, &scene), SAME_CHOICE);
}

/// [`THREE_LIGHTS`] with a rough aluminium floor (GGX α 0.15) and the
/// rectangle light twice as wide: the rectangle's highlight on the floor is
/// reached by light and BSDF sampling with comparable densities, so the
/// emitter hits' MIS probability (`light_pmf_at`) weighs as much as the
/// next-event one there.
fn glossy_three_lights() -> String {
    THREE_LIGHTS
        .replacen(
            "{type: rectangle, material: grey,",
            "{type: rectangle, material: metal,",
            1,
        )
        .replace(
            "  grey: {type: diffuse, reflectance: 0.6}\n",
            "  grey: {type: diffuse, reflectance: 0.6}\n  metal: {type: conductor, material: Al, alpha: 0.15}\n",
        )
        .replace("{scale: 0.2}]", "{scale: 0.4}]")
        .replace("radiance: [40, 40, 40]", "radiance: [10, 10, 10]")
}

#[test]
fn spatial_selection_over_a_glossy_floor() {
    let text = glossy_three_lights();
    assert!(text.contains("material: metal") && text.contains("{scale: 0.4}"));
    let scene = extract_text(&text, LightSelection::Spatial, 64);
    let name = "three lights over metal, spatial";
    assert_agrees(name, render_extracted(name, &scene), SAME_CHOICE);
}

#[test]
fn power_selection_among_three_lights() {
    let scene = extract_text(THREE_LIGHTS, LightSelection::Power, 64);
    assert!(!scene.lights.is_spatial());
    let name = "three lights, power";
    assert_agrees(name, render_extracted(name, &scene), SAME_CHOICE);
}

#[test]
fn spatial_selection_through_the_light_tree_over_a_glossy_floor() {
    // The rectangles' highlights weigh their emitter hits' MIS probability
    // (the tree's `light_pmf_at`) as much as their next-event one.
    let text = many_lights().replacen(
        "{type: rectangle, material: grey,",
        "{type: rectangle, material: metal,",
        1,
    );
    let text = text.replace(
        "  grey: {type: diffuse, reflectance: 0.6}\n",
        "  grey: {type: diffuse, reflectance: 0.6}\n  metal: {type: conductor, material: Al, alpha: 0.15}\n",
    );
    assert!(text.contains("material: metal"));
    let scene = extract_text(&text, LightSelection::Spatial, 64);
    let name = "24 lights and the sky over metal, spatial";
    assert_agrees(name, render_extracted(name, &scene), SAME_CHOICE);
}

#[test]
fn spatial_selection_through_the_light_tree() {
    let scene = extract_text(&many_lights(), LightSelection::Spatial, 64);
    assert!(scene.lights.len() > FLAT_LIMIT + 1);
    assert!(scene.lights.is_spatial());
    let name = "24 lights and the sky, spatial";
    assert_agrees(name, render_extracted(name, &scene), SAME_CHOICE);
}
