//! Spot and directional lights end to end: `scenes/spot-directional.yaml`
//! against a converged Mitsuba 3 render
//! (`tests/data/spot-directional-mitsuba.exr`, 4096 spp, made by
//! `tests/reference/render_delta_lights.py`).

use radiant::extract::Overrides;
use radiant::film::Image;
use radiant::film::output::read_exr;
use radiant_tests::{ReferenceCheck, check_against, render_scene, root};

const SPP: u32 = 256;
/// Side of the blocks whose means are compared, in pixels.
const BLOCK: u32 = 16;
/// Allowed |mean ratio − 1| per colour channel (see the measured values
/// below); a 3 % energy error must fail.
const CHANNEL_MEAN_TOLERANCE: f64 = 0.003;
/// Allowed relative error of a 16×16 block mean.
const BLOCK_TOLERANCE: f64 = 0.015;

fn passes(check: &ReferenceCheck) -> bool {
    check.worst_channel_mean_error < CHANNEL_MEAN_TOLERANCE
        && check.worst_block_error < BLOCK_TOLERANCE
}

#[test]
fn spot_and_directional_scene_matches_mitsuba() {
    let reference =
        read_exr(root().join("tests/data/spot-directional-mitsuba.exr")).expect("reference EXR");
    let image = render_scene(
        "scenes/spot-directional.yaml",
        Overrides {
            spp: Some(SPP),
            seed: Some(5),
            ..Default::default()
        },
    );
    let check = check_against(&image, &reference, BLOCK);
    eprintln!("{check:?}");
    assert!(passes(&check), "render differs from Mitsuba: {check:?}");
    for scale in [0.97f32, 1.03] {
        let scaled = Image {
            pixels: image.pixels.iter().map(|p| *p * scale).collect(),
            ..image.clone()
        };
        assert!(!passes(&check_against(&scaled, &reference, BLOCK)));
    }
}
