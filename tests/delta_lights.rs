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
/// Measured over seeds 1–6 at 256 spp: channel means within 0.04–0.30 %,
/// worst 16×16 block 1.3–3.4 %. The channel tolerance still rejects a 3 %
/// energy error (asserted by `assert_matches`).
const TOLERANCES: Tolerances = Tolerances {
    channel_mean: 0.01,
    block: 0.06,
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
