//! Spot and directional lights end to end: `scenes/spot-directional.yaml`
//! against a converged Mitsuba 3 render
//! (`tests/data/spot-directional-mitsuba.exr`, 4096 spp, made by
//! `tests/reference/render_delta_lights.py`).

use radiant::extract::Overrides;
use radiant::film::output::read_exr;
use radiant_tests::{Tolerances, render_scene, root};

const SPP: u32 = 256;
/// Side of the blocks whose means are compared, in pixels.
const BLOCK: u32 = 16;
/// Measured: see the test output.
const TOLERANCES: Tolerances = Tolerances {
    channel_mean: 0.003,
    block: 0.015,
};

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
    TOLERANCES.assert_matches(&image, &reference, BLOCK);
}
