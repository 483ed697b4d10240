//! Every sampler's GPU side against its Rust implementation: each built-in
//! sampler extracted from a small scene, a few thousand (pixel, index,
//! dimension) triples through `Sampler::fill_1d` and `fill_2d` and through
//! the WGSL (the GPU backend's probe: `sample_1d_T`, and `sample_2d_T`
//! where the type has one, else two 1D values, as the kernel draws pairs),
//! compared value by value. Samplers are integer
//! maths, so the values must be bit-identical; only `halton`, whose Rust
//! sums its digits in f64 where the WGSL divides two integers exactly, may
//! differ by one ulp (where the f64 sum rounds the other way). Then the
//! Cornell box rendered with each sampler on both backends, compared by
//! channel means.

use radiant::backend::cpu::{Progress, render};
use radiant::backend::gpu::probe::{Probe, ProbeKind};
use radiant::extract::{Overrides, RenderScene, extract};
use radiant_core::SampleId;
use radiant_tests::SplitMix as Rng;
use std::path::Path;

/// Records per comparison.
const RECORDS: usize = 4096;

/// The Cornell box with its sampler replaced by `sampler` (inline YAML),
/// extracted with `overrides`.
fn cornell_box(sampler: &str, overrides: &Overrides) -> RenderScene {
    let dir = radiant_tests::root().join("scenes");
    // `expect` in this test code is the assertion: the repository's scene
    // must be readable, and must load and extract with the sampler swapped.
    let text = std::fs::read_to_string(dir.join("cornell-box.yaml")).expect("the scene reads");
    let original = "sampler:\n  type: independent\n  spp: 64\n";
    assert!(text.contains(original), "the Cornell box's sampler moved");
    let text = text.replace(original, &format!("sampler: {sampler}\n"));
    let scene =
        radiant::scene::from_str(&text, Path::new("t.yaml"), &dir).expect("the scene loads");
    extract(&scene, &radiant::builtin_registry(), overrides).expect("the scene extracts")
}

/// The triples: pixels anywhere in a large film (kept below the float NaN
/// patterns, as they travel as float bits), indices within the spp and
/// beyond, dimensions 0..40.
fn triples(spp: u32) -> Vec<[u32; 3]> {
    let mut rng = Rng(0x5eed ^ spp as u64);
    (0..RECORDS)
        .map(|r| {
            let pixel = match r % 4 {
                0 => rng.below(64 * 64),
                1 => rng.below(4096 * 4096),
                _ => rng.below(0x7f00_0000),
            };
            let index = match r % 3 {
                0 => rng.below(spp),
                1 => rng.below(4 * spp + 3),
                _ => rng.below(1 << 20),
            };
            [pixel, index, rng.below(40)]
        })
        .collect()
}

/// Checks `sampler` (inline YAML, `spp` samples) on the GPU against the
/// CPU; `ulps` is the largest allowed difference in units in the last place.
fn agrees(sampler: &str, spp: u32, ulps: u32) {
    let overrides = Overrides {
        seed: Some(0x1234_5678_9abc_def0),
        ..Overrides::default()
    };
    let scene = cornell_box(sampler, &overrides);
    let module = scene
        .sampler
        .gpu()
        .unwrap_or_else(|| panic!("{sampler}: no GPU side"));
    let triples = triples(spp);
    // Per triple: the 1D value, then the 2D pair.
    let cpu: Vec<f32> = triples
        .iter()
        .flat_map(|&[pixel, index, dim]| {
            let id = [SampleId { pixel, index }];
            let mut one = [0.0f32];
            scene.sampler.fill_1d(&id, dim, &mut one);
            let mut two = [glam::Vec2::ZERO];
            scene.sampler.fill_2d(&id, dim, &mut two);
            [one[0], two[0].x, two[0].y]
        })
        .collect();
    let inputs: Vec<f32> = triples
        .iter()
        .flatten()
        .map(|&w| f32::from_bits(w))
        .collect();
    let t = &module.ident;
    let pair = if module.wgsl.contains(&format!("fn sample_2d_{t}(")) {
        format!("sample_2d_{t}(P, pixel, index, dim)")
    } else {
        format!(
            "vec2f(sample_1d_{t}(P, pixel, index, dim), sample_1d_{t}(P, pixel, index, dim + 1u))"
        )
    };
    let body = format!(
        "let pixel = bitcast<u32>(input(i, 0u));
let index = bitcast<u32>(input(i, 1u));
let dim = bitcast<u32>(input(i, 2u));
output(i, 0u, sample_1d_{t}(P, pixel, index, dim));
let pair = {pair};
output(i, 1u, pair.x);
output(i, 2u, pair.y);"
    );
    let probe = Probe {
        module,
        kind: ProbeKind::Sampler,
        textures: &scene.textures,
        body: &body,
        inputs_per_record: 3,
        outputs_per_record: 3,
    };
    let gpu = radiant_tests::gpu::backend()
        .probe(&probe, &inputs)
        .unwrap_or_else(|e| panic!("{sampler}: the probe failed: {e}"));
    assert_eq!(gpu.len(), cpu.len());
    let mut off = 0;
    let mut worst = Vec::new();
    let per_value = triples.iter().flat_map(|t| [t; 3]);
    for ((t, c), g) in per_value.zip(&cpu).zip(&gpu) {
        assert!((0.0..1.0).contains(c), "{sampler}: CPU value {c} for {t:?}");
        if c.to_bits() != g.to_bits() {
            off += 1;
            let d = c.to_bits().abs_diff(g.to_bits());
            if d > ulps || !(0.0..1.0).contains(g) {
                worst.push(format!("{t:?}: CPU {c:?}, GPU {g:?}"));
            }
        }
    }
    eprintln!(
        "{sampler}: {off} of {} values differ (by at most {ulps} ulp)",
        cpu.len()
    );
    assert!(
        worst.is_empty(),
        "{sampler}: {} values differ by more than {ulps} ulp:\n{}",
        worst.len(),
        worst[..worst.len().min(10)].join("\n")
    );
    assert!(off * 100 < cpu.len(), "{sampler}: {off} values differ");
}

#[test]
fn independent_matches_the_cpu() {
    agrees("{type: independent, spp: 16}", 16, 0);
}

#[test]
fn stratified_matches_the_cpu() {
    agrees("{type: stratified, spp: 16}", 16, 0);
    agrees("{type: stratified, spp: 7}", 7, 0);
    agrees("{type: stratified, spp: 1}", 1, 0);
}

#[test]
fn halton_matches_the_cpu() {
    agrees("{type: halton, spp: 16}", 16, 1);
}

#[test]
fn sobol_matches_the_cpu() {
    agrees("{type: sobol, spp: 16}", 16, 0);
}

/// The Cornell box rendered with each sampler by both backends: the GPU
/// draws the CPU's 1D values and 2D pairs, so the paths coincide up to
/// float rounding and channel means agree within 0.5 %, 8×8 blocks within
/// 6 %.
#[test]
fn renders_match_the_cpu() {
    for sampler in ["halton", "stratified", "sobol"] {
        let size = 48;
        let overrides = Overrides {
            width: Some(size),
            height: Some(size),
            ..Overrides::default()
        };
        let scene = cornell_box(&format!("{{type: {sampler}, spp: 64}}"), &overrides);
        let gpu = radiant_tests::gpu::backend()
            .render(&scene, &Progress::none())
            .unwrap_or_else(|e| panic!("{sampler}: the GPU render failed: {e}"));
        assert_eq!(gpu.invalid_samples, 0, "{sampler}: invalid GPU samples");
        let cpu = render(&scene, &Progress::none());
        let (g, c) = (
            radiant_tests::channel_means(&gpu.image),
            radiant_tests::channel_means(&cpu.image),
        );
        eprintln!("{sampler}: GPU means {g:?}, CPU means {c:?}");
        for k in 0..3 {
            assert!(
                (g[k] / c[k] - 1.0).abs() < 0.005,
                "{sampler}: channel {k} GPU {} vs CPU {}",
                g[k],
                c[k]
            );
        }
        let check = radiant_tests::check_against(&gpu.image, &cpu.image, 8);
        assert!(check.worst_block_error < 0.06, "{sampler}: {check:?}");
    }
}
