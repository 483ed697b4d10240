//! Torture suite, scale: the Cornell box scaled by 1e-4 and by 1e5, and
//! translated to 1e6 from the origin (`scenes/hard/cornell-*.yaml`, written
//! by `make_cornell_variants.py`), renders the same image as the original.
//!
//! Both renders use the same seed, so the same camera samples start the
//! same paths; they part only where rounding differs, which keeps the noise
//! between the two far below that of independent renders. Self-intersection
//! acne would darken the image and light leaking through the box's edges
//! would change its brightness: both move block means systematically.

use radiant::extract::Overrides;
use radiant::film::Image;
use radiant_tests::{ReferenceCheck, check_against, render_checked};

const SIZE: u32 = 64;
const SPP: u32 = 64;
/// Side of the blocks whose means are compared, in pixels.
const BLOCK: u32 = 8;
/// Allowed |mean ratio − 1| per channel. Measured: at most 3e-7 between the
/// original and any variant (the paths hardly part); a 3 % energy error
/// must fail.
const CHANNEL_MEAN_TOLERANCE: f64 = 0.002;
/// Allowed relative error of an 8×8 block mean. Measured: at most 1e-6.
const BLOCK_TOLERANCE: f64 = 0.01;

fn render(scene: &str, seed: u64) -> Image {
    render_checked(
        scene,
        Overrides {
            spp: Some(SPP),
            seed: Some(seed),
            width: Some(SIZE),
            height: Some(SIZE),
            ..Default::default()
        },
    )
}

fn passes(check: &ReferenceCheck) -> bool {
    check.worst_channel_mean_error < CHANNEL_MEAN_TOLERANCE
        && check.worst_block_error < BLOCK_TOLERANCE
}

fn matches_the_original(variant: &str) {
    let seed = 1;
    let original = render("scenes/cornell-box.yaml", seed);
    let image = render(variant, seed);
    let check = check_against(&image, &original, BLOCK);
    eprintln!("{variant}: {check:?}");
    assert!(passes(&check), "{variant} differs: {check:?}");
    // Black speckles: a pixel much darker than the original's.
    let dark = image
        .pixels
        .iter()
        .zip(&original.pixels)
        .filter(|(a, b)| a.element_sum() < 0.5 * b.element_sum())
        .count();
    assert!(dark <= 8, "{variant}: {dark} pixels under half as bright");
    // The comparison catches a 3 % energy error.
    let scaled = Image {
        pixels: image.pixels.iter().map(|p| *p * 0.97).collect(),
        ..image.clone()
    };
    assert!(!passes(&check_against(&scaled, &original, BLOCK)));
}

#[test]
fn cornell_box_scaled_by_1e_minus_4_matches() {
    matches_the_original("scenes/hard/cornell-scaled-1e-4.yaml");
}

#[test]
fn cornell_box_scaled_by_1e5_matches() {
    matches_the_original("scenes/hard/cornell-scaled-1e5.yaml");
}

#[test]
fn cornell_box_translated_to_1e6_matches() {
    matches_the_original("scenes/hard/cornell-translated-1e6.yaml");
}
