//! Adaptive sampling (`sampler: {adaptive: …}`): flat pixels stop early,
//! noisy ones take more, and the image is unbiased — its mean over a noisy
//! region matches a fixed-spp render at high spp within the noise, a test
//! that fails when the decision is made on the image's own samples (checked
//! by mutation: deciding on the image's samples made the region's mean 5 %
//! low, 4.386 ± 0.017 against 4.617 ± 0.013, 10.7 standard errors).

// `expect` in this test code is the assertion: the scene is the test's
// own, so a failure is a bug, and the panic reports it.

use radiant::backend::cpu::{Progress, render_samples, try_render_counted};
use radiant::extract::{Overrides, extract};
use radiant::film::{Film, Image};
use std::path::Path;

/// 32×16 pixels: the left half sees an emitting panel with a black
/// material (every sample the same radiance: flat), the right half a white
/// wall lit only through a glass ball with a light inside (every path to
/// the light is found by BSDF sampling through the glass: rare and bright,
/// heavy-tailed noise).
fn scene(sampler: &str) -> String {
    format!(
        "integrator: {{type: path, max_depth: 6}}
film: {{width: 32, height: 16, filter: {{type: box}}}}
sampler: {sampler}
camera: {{type: perspective, fov: 50, look_at: {{origin: [0, 0, 2.5], target: [0, 0, 0]}}}}
materials:
  white: {{type: diffuse, reflectance: 0.7}}
  black: {{type: diffuse, reflectance: 0}}
  glass: {{type: dielectric, int_ior: 1.5, ext_ior: 1}}
shapes:
  - {{type: rectangle, material: black, emitter: {{type: area, radiance: 1}}, transform: [{{translate: [-0.65, 0, 0]}}, {{scale: [0.6, 1, 1]}}]}}
  - {{type: rectangle, material: white, transform: [{{translate: [0.65, 0, 0]}}, {{scale: [0.6, 1, 1]}}]}}
  - {{type: sphere, center: [0.6, 0, 0.45], radius: 0.3, material: glass}}
  - {{type: sphere, center: [0.6, 0, 0.45], radius: 0.1, material: black, emitter: {{type: area, radiance: 20}}}}
"
    )
}

/// Renders `sampler`'s variant of the scene with `seed`: the image and each
/// pixel's image samples.
fn render(sampler: &str, seed: u64) -> (Image, Vec<u32>) {
    let text = scene(sampler);
    let loaded = radiant::scene::from_str(&text, Path::new("adaptive.yaml"), Path::new("."))
        .expect("the scene parses");
    let overrides = Overrides {
        seed: Some(seed),
        ..Overrides::default()
    };
    let r = extract(&loaded, &radiant::builtin_registry(), &overrides).expect("extracts");
    let (rendered, counts) = try_render_counted(&r, &Progress::none()).expect("fits");
    (rendered.image, counts.expect("a tile integrator counts"))
}

/// The pixels (x, y) of the flat panel, away from its edges.
fn flat(x: u32, y: u32) -> bool {
    (3..13).contains(&x) && (3..13).contains(&y)
}

/// The pixels of the lit wall (and the ball before it).
fn noisy(x: u32, y: u32) -> bool {
    (18..30).contains(&x) && (2..14).contains(&y)
}

/// The mean luminance-like sum (r + g + b) of `image` over the pixels
/// `inside` picks.
fn region_mean(image: &Image, inside: fn(u32, u32) -> bool) -> f64 {
    let (mut sum, mut n) = (0.0f64, 0u32);
    for (i, p) in image.pixels.iter().enumerate() {
        let (x, y) = (i as u32 % image.width, i as u32 / image.width);
        if inside(x, y) {
            sum += f64::from(p.element_sum());
            n += 1;
        }
    }
    sum / f64::from(n)
}

/// Mean and standard error of `values`.
fn mean_and_error(values: &[f64]) -> (f64, f64) {
    let n = values.len() as f64;
    let mean = values.iter().sum::<f64>() / n;
    let var = values.iter().map(|v| (v - mean).powi(2)).sum::<f64>() / (n - 1.0);
    (mean, (var / n).sqrt())
}

const ADAPTIVE: &str =
    "{type: independent, spp: 256, adaptive: {threshold: 0.1, batch: 16, min_spp: 16}}";

#[test]
fn flat_pixels_stop_early_and_noisy_ones_take_more() {
    let (image, counts) = render(ADAPTIVE, 1);
    let at = |x: u32, y: u32| counts[(y * 32 + x) as usize];
    let mut flat_counts = Vec::new();
    let mut noisy_counts = Vec::new();
    for y in 0..16 {
        for x in 0..32 {
            if flat(x, y) {
                flat_counts.push(at(x, y));
            } else if noisy(x, y) {
                noisy_counts.push(at(x, y));
            }
        }
    }
    // Every sample of a flat pixel is the same: it stops at the first check.
    assert!(flat_counts.iter().all(|&c| c == 16), "{flat_counts:?}");
    let mean = noisy_counts.iter().map(|&c| f64::from(c)).sum::<f64>() / noisy_counts.len() as f64;
    assert!(mean > 64.0, "noisy pixels took {mean} samples on average");
    assert!(noisy_counts.contains(&256), "some reach max_spp");
    // The flat panel is exactly its radiance.
    assert!((region_mean(&image, flat) - 3.0).abs() < 1e-5);
}

#[test]
fn the_adaptive_image_is_unbiased() {
    // Eight seeds each: the noisy region's mean under adaptive sampling
    // and at a fixed 512 spp, compared within their standard errors.
    let seeds = 1..=8u64;
    let adaptive: Vec<f64> = seeds
        .clone()
        .map(|s| region_mean(&render(ADAPTIVE, s).0, noisy))
        .collect();
    let fixed: Vec<f64> = seeds
        .map(|s| region_mean(&render("{type: independent, spp: 512}", 100 + s).0, noisy))
        .collect();
    let (a, ea) = mean_and_error(&adaptive);
    let (f, ef) = mean_and_error(&fixed);
    let z = (a - f) / (ea * ea + ef * ef).sqrt();
    assert!(
        z.abs() < 4.0,
        "adaptive {a:.5} ± {ea:.5} against fixed {f:.5} ± {ef:.5}: {z:.1} standard errors"
    );
    // The test can tell: the region's standard error is under 3 % of it.
    assert!(ea < 0.03 * f && ef < 0.03 * f, "{ea} {ef} of {f}");
}

#[test]
fn bad_adaptive_keys_are_located_errors() {
    for (sampler, needle) in [
        (
            "{type: independent, adaptive: {threshold: -1}}",
            "threshold",
        ),
        (
            "{type: independent, adaptive: {batch: 10}}",
            "multiple of 4",
        ),
        (
            "{type: independent, adaptive: {confidence: 2}}",
            "confidence",
        ),
        (
            "{type: independent, adaptive: {min_spp: 64, max_spp: 16}}",
            "min_spp",
        ),
        ("{type: independent, adaptive: {thresold: 0.1}}", "thresold"),
    ] {
        let text = scene(sampler);
        let err = radiant::scene::from_str(&text, Path::new("adaptive.yaml"), Path::new("."))
            .err()
            .expect("a bad key is an error")
            .to_string();
        assert!(
            err.contains("adaptive.yaml:3:") && err.contains(needle),
            "{sampler}: {err}"
        );
    }
}

#[test]
fn a_splatting_gaussian_film_keeps_converged_pixels_their_value() {
    // The Cornell box's Gaussian filter splats (radius 2 pixels). Without
    // weighting each pixel's samples by 1 / its count, a converged pixel's
    // few samples were outweighed in its neighbours' sums by their many:
    // the light (flat, so converged at once) came out dark and the image's
    // mean 10 % low (checked by mutation: leaving out the weight makes the
    // ratio 0.918 here). Filter importance sampling, where each pixel keeps
    // its own samples, must agree too.
    let overrides = Overrides {
        width: Some(48),
        height: Some(48),
        ..Overrides::default()
    };
    let box_scene = "scenes/cornell-box.yaml";
    let with = |spp: &'static str| {
        move |text: &str| {
            assert!(text.contains("  spp: 64\n"));
            text.replace("  spp: 64\n", spp)
        }
    };
    let fixed = radiant_tests::render_edited(box_scene, with("  spp: 256\n"), overrides);
    let adaptive =
        radiant_tests::render_edited(box_scene, with("  spp: 256\n  adaptive: true\n"), overrides);
    let ratio = adaptive.image.mean() / fixed.image.mean();
    assert!((ratio - 1.0).abs() < 0.02, "adaptive / fixed mean {ratio}");
    assert!(adaptive.samples < fixed.samples, "the light stopped early");
    // The light's pixels and their neighbours, block by block (8×8).
    let worst = radiant_tests::check_against(&adaptive.image, &fixed.image, 8).worst_block_error;
    assert!(worst < 0.08, "a block is off by {worst}");
    let importance = radiant_tests::render_edited(
        box_scene,
        with(
            "  spp: 256
  adaptive: true
",
        ),
        Overrides {
            filter_sampling: Some(radiant::scene::FilterSampling::Importance),
            ..overrides
        },
    );
    let ratio = importance.image.mean() / fixed.image.mean();
    assert!(
        (ratio - 1.0).abs() < 0.02,
        "importance: adaptive / fixed mean {ratio}"
    );
}

#[test]
fn adaptive_renders_in_passes_and_resumed_equal_one_render() {
    // A splatting Gaussian film: passes render the same share of every
    // pixel's count, weighted by 1 / the count, and the counts decided by
    // the first pass are kept in the film; a resumed render (a film of the
    // sums alone, as the resume file holds) decides again, the same.
    let text = scene(ADAPTIVE).replace(
        "filter: {type: box}",
        "filter: {type: gaussian, stddev: 0.5}",
    );
    assert!(text.contains("gaussian"));
    let loaded = radiant::scene::from_str(&text, Path::new("adaptive.yaml"), Path::new("."))
        .expect("the scene parses");
    let r =
        extract(&loaded, &radiant::builtin_registry(), &Overrides::default()).expect("extracts");
    assert!(radiant::backend::cpu::passes(&r).is_ok());
    let (one, counts) = try_render_counted(&r, &Progress::none()).expect("fits");
    let (one, counts) = (one.image, counts.expect("a tile integrator counts"));
    let mut film = Film::new(r.settings.width, r.settings.height);
    let mut samples = 0;
    for pass in [0..4, 4..40, 40..100] {
        samples += render_samples(&r, &mut film, pass, &Progress::none()).samples;
    }
    // "Interrupted" at 100 of 256 spp: the state file keeps the sums only.
    let mut resumed = film.clone();
    resumed.adaptive_counts = None;
    for pass in [100..180, 180..256] {
        samples += render_samples(&r, &mut resumed, pass, &Progress::none()).samples;
    }
    let image = resumed.try_develop().expect("fits");
    assert!(image == one, "passes and resume differ from one render");
    // The passes traced each pixel's count once, the same samples.
    assert_eq!(samples, counts.iter().map(|&c| u64::from(c)).sum::<u64>());
}

#[test]
fn the_gpu_refuses_adaptive_sampling_by_name() {
    let text = scene(ADAPTIVE);
    let loaded = radiant::scene::from_str(&text, Path::new("adaptive.yaml"), Path::new("."))
        .expect("the scene parses");
    let r =
        extract(&loaded, &radiant::builtin_registry(), &Overrides::default()).expect("extracts");
    let gpu = radiant::backend::gpu::Plan::check(&r)
        .expect_err("refused")
        .to_string();
    assert!(gpu.contains("adaptive"), "{gpu}");
}
