//! Torture suite, materials at their limits: roughness 0, 1e-6 and 1, index
//! of refraction 1 (glass must vanish), 1.0001 and 10, total internal
//! reflection, and shading normals that point below the geometric surface.
//!
//! - `scenes/hard/furnace-lossless.yaml`: spheres that neither absorb nor
//!   lose energy in a white furnace must vanish (every pixel 1).
//! - `scenes/hard/furnace-lossy.yaml`: single-scattering microfacet models
//!   at roughness 1 and the bent-normal mesh may lose energy, never gain it.
//! - `scenes/hard/glass-ior-1.yaml`: a ball of index-matched glass
//!   leaves the image of its scene unchanged.
//! - `scenes/hard/rough-limits.yaml`: GGX at α = 1e-6 matches the smooth
//!   (delta) mirror and glass.

use radiant::extract::Overrides;
use radiant::film::Image;
use radiant_tests::{Tolerances, check_against, render_checked, render_edited};

fn seeded(seed: u64) -> Overrides {
    Overrides {
        seed: Some(seed),
        ..Default::default()
    }
}

/// Renders the scene file `scene` with every `from` in its text replaced by
/// `to` (which must occur `count` times), checked like `render_checked`.
fn render_variant(scene: &str, from: &str, to: &str, count: usize, overrides: Overrides) -> Image {
    let edit = |text: &str| {
        assert_eq!(text.matches(from).count(), count, "{scene}: `{from}`");
        text.replace(from, to)
    };
    let rendered = render_edited(scene, edit, overrides);
    assert_eq!(
        rendered.invalid_samples, 0,
        "{scene}: NaN or infinite samples"
    );
    rendered.image
}

/// Worst |pixel − 1| over all channels.
fn worst_deviation_from_one(image: &Image) -> f32 {
    image
        .pixels
        .iter()
        .map(|p| (*p - 1.0).abs().max_element())
        .fold(0.0, f32::max)
}

/// Allowed |pixel − 1| in the lossless furnace. Measured at 64 spp, seeds
/// 1–3: at most 0.008 (the α = 1e-6 mirror, whose lobe light sampling
/// still sees); every smooth sphere is exactly 1. Before Russian roulette
/// took refraction's 1/η² out of the throughput, glass pixels reached 2.5.
const LOSSLESS_PIXEL: f32 = 0.05;

#[test]
fn lossless_materials_vanish_in_a_white_furnace() {
    for seed in 1..=3 {
        let image = render_checked("scenes/hard/furnace-lossless.yaml", seeded(seed));
        let worst = worst_deviation_from_one(&image);
        eprintln!("lossless furnace, seed {seed}: worst pixel off by {worst}");
        assert!(worst < LOSSLESS_PIXEL, "worst pixel off by {worst}");
    }
}

/// Allowed excess of any pixel over 1 in the lossy furnace. Measured: none
/// (the maximum is 1.0000, the background), except on the Oren–Nayar
/// sphere (column 3).
const LOSSY_EXCESS: f32 = 0.01;
/// Oren–Nayar is not energy conserving: up to 2.6 % over 1 near grazing
/// incidence (tests/shaders_energy.rs); measured here 2.3 %.
const OREN_NAYAR_EXCESS: f32 = 0.05;
/// Least mean of each object's column of the lossy furnace: none may turn
/// black. Measured: 0.77 (rough glass) to 0.94 (Oren–Nayar); the bent
/// normals' mesh 0.80 (0.60 with black regions before bending).
const LOSSY_LEAST_COLUMN_MEAN: f64 = 0.7;

#[test]
fn lossy_materials_never_gain_energy_in_a_white_furnace() {
    for seed in 1..=2 {
        let image = render_checked("scenes/hard/furnace-lossy.yaml", seeded(seed));
        // Eight objects, one per 12-pixel column.
        let column_max: Vec<f32> = (0..8)
            .map(|c| {
                let mut m = 0.0f32;
                for y in 0..image.height {
                    for x in c * 12..(c + 1) * 12 {
                        m = m.max(image.pixels[(y * image.width + x) as usize].max_element());
                    }
                }
                m
            })
            .collect();
        eprintln!("lossy furnace, seed {seed}: column maxima {column_max:?}");
        for (c, m) in column_max.iter().enumerate() {
            let excess = if c == 3 {
                OREN_NAYAR_EXCESS
            } else {
                LOSSY_EXCESS
            };
            assert!(*m <= 1.0 + excess, "column {c} reached {m}");
        }
        let columns: Vec<f64> = (0..8)
            .map(|c| {
                let mut sum = 0.0;
                for y in 0..image.height {
                    for x in c * 12..(c + 1) * 12 {
                        let p = image.pixels[(y * image.width + x) as usize];
                        sum += p.element_sum() as f64 / 3.0;
                    }
                }
                sum / (12 * image.height) as f64
            })
            .collect();
        eprintln!("lossy furnace, seed {seed}: column means {columns:.3?}");
        for (c, m) in columns.iter().enumerate() {
            assert!(*m > LOSSY_LEAST_COLUMN_MEAN, "column {c} mean {m}");
        }
    }
}

/// Renders `scene`'s text cut at the line that contains `marker`.
fn render_cut(scene: &str, marker: &str, overrides: Overrides) -> Image {
    let cut = |text: &str| text[..text.find(marker).expect("marker present")].to_string();
    render_edited(scene, cut, overrides).image
}

/// A high-spp render for comparisons.
fn converged(seed: u64) -> Overrides {
    Overrides {
        spp: Some(1024),
        seed: Some(seed),
        ..Default::default()
    }
}

/// Side of the compared blocks, pixels.
const BLOCK: u32 = 8;
/// Tolerances of both comparisons below (128 spp against 1024 spp, 8×8
/// blocks). Measured: channel means within 0.07 % (index 1) and 0.04 %
/// (α = 1e-6), worst blocks 1.5 % and 1.5 %; a water ball is 101 % off
/// in its worst block, α = 0.5 balls 59 %.
const LIMITS: Tolerances = Tolerances {
    channel_mean: 0.01,
    block: 0.05,
};

#[test]
fn glass_of_index_1_vanishes() {
    let scene = "scenes/hard/glass-ior-1.yaml";
    let reference = render_cut(scene, "# The index-matched ball", converged(2));
    let image = render_checked(scene, seeded(1));
    LIMITS.assert_matches(&image, &reference, BLOCK);
    // The same check sees a ball of water.
    let water = render_variant(
        scene,
        "int_ior: 1, ext_ior: 1",
        "int_ior: 1.33, ext_ior: 1",
        1,
        seeded(1),
    );
    let check = check_against(&water, &reference, BLOCK);
    eprintln!("water ball: {check:?}");
    assert!(!LIMITS.passes(&check), "a water ball passed as invisible");
}

#[test]
fn roughness_1e_6_matches_smooth_mirror_and_glass() {
    let scene = "scenes/hard/rough-limits.yaml";
    let smooth = render_checked(scene, converged(2));
    let rough = render_variant(scene, "alpha: 0}", "alpha: 1e-6}", 2, seeded(1));
    LIMITS.assert_matches(&rough, &smooth, BLOCK);
    // The check sees visibly rough balls.
    let blurred = render_variant(scene, "alpha: 0}", "alpha: 0.5}", 2, seeded(1));
    let check = check_against(&blurred, &smooth, BLOCK);
    eprintln!("alpha 0.5: {check:?}");
    assert!(!LIMITS.passes(&check), "α = 0.5 passed as smooth");
}
