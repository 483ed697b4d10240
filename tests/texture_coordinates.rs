//! Texture coordinates as Mitsuba 3 defines them, on every shape: each
//! scene of `tests/data/uv/` (made with its reference by
//! `tests/reference/render_uv.py`) shows two turned copies of a shape, one
//! with an asymmetric letter image, one with a checkerboard, lit so that a
//! pixel shows the texture's value. Radiant's render must match Mitsuba's
//! block by block, and the same scene with the letter or the checkerboard
//! flipped or turned a quarter must not.

use radiant::backend::cpu::{Progress, render};
use radiant::extract::{Overrides, extract};
use radiant::film::Image;
use radiant::film::output::read_exr;
use radiant_tests::block_channel_means;

/// Renders `tests/data/uv/<shape>.yaml` with the texture line `from`
/// replaced by `to`.
fn render_uv(shape: &str, from: &str, to: &str) -> Image {
    let dir = radiant_tests::root().join("tests/data/uv");
    let path = dir.join(format!("{shape}.yaml"));
    let text = std::fs::read_to_string(&path).expect("the scene is committed");
    assert!(text.contains(from), "{shape}.yaml lost `{from}`");
    let scene =
        radiant::scene::from_str(&text.replace(from, to), &path, &dir).expect("the scene parses");
    let r = extract(&scene, &radiant::builtin_registry(), &Overrides::default())
        .expect("the scene extracts");
    render(&r, &Progress::none()).image
}

/// The largest difference of an 8×8 block's mean (any channel) between
/// `a` and `b`.
fn worst_block(a: &Image, b: &Image) -> f64 {
    assert_eq!((a.width, a.height), (b.width, b.height));
    let (ma, mb) = (block_channel_means(a, 8), block_channel_means(b, 8));
    let mut worst: f64 = 0.0;
    for (x, r) in ma.iter().zip(&mb) {
        for c in 0..3 {
            worst = worst.max((x[c] - r[c]).abs());
        }
    }
    worst
}

/// The block error that passes (measured: at most 0.004 for every shape;
/// a flipped or turned texture is off by 0.1 or more).
const TOLERANCE: f64 = 0.02;

const LETTER: &str = "letter: {type: uv_transform, texture: letter_image}";
const CHECKS: &str = "checks: {type: uv_transform, texture: checks_plain}";

/// Asserts that `shape` matches Mitsuba and that its textures flipped in v
/// or turned a quarter do not.
fn check(shape: &str) {
    let reference =
        read_exr(radiant_tests::root().join(format!("tests/data/uv/{shape}-mitsuba.exr")))
            .expect("the reference is committed");
    let error = worst_block(&render_uv(shape, LETTER, LETTER), &reference);
    eprintln!("{shape}: worst block {error:.4}");
    assert!(error < TOLERANCE, "{shape} differs from Mitsuba: {error}");
    let wrong = [
        (
            LETTER,
            "letter: {type: uv_transform, texture: letter_image, scale: [1, -1], offset: [0, 1]}",
        ),
        (
            LETTER,
            "letter: {type: uv_transform, texture: letter_image, rotate: 90}",
        ),
        (
            CHECKS,
            "checks: {type: uv_transform, texture: checks_plain, scale: [1, -1], offset: [0, 1]}",
        ),
        (
            CHECKS,
            "checks: {type: uv_transform, texture: checks_plain, rotate: 90}",
        ),
    ];
    for (from, to) in wrong {
        let error = worst_block(&render_uv(shape, from, to), &reference);
        eprintln!("{shape}: {to}: worst block {error:.4}");
        assert!(
            error > TOLERANCE,
            "{shape}: `{to}` went unnoticed ({error})"
        );
    }
}

#[test]
fn rectangles_are_textured_as_in_mitsuba() {
    check("rectangle");
}

#[test]
fn turned_spheres_carry_their_texture_coordinates() {
    check("sphere");
}

#[test]
fn turned_cubes_lay_out_their_faces_as_in_mitsuba() {
    check("cube");
}

#[test]
fn meshes_read_obj_texture_coordinates_as_mitsuba_does() {
    // The left copy reads the file with Mitsuba's default 1 − v, the right
    // one with `flip_tex_coords: false`.
    check("mesh");
}
