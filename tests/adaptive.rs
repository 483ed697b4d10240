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

/// Adaptive sampling toward the least MSE: 64 samples a pixel on average.
const ADAPTIVE_MSE: &str = "{type: independent, spp: 64, adaptive: {error: mse}}";

#[test]
fn the_mse_goal_spends_the_budget_on_the_noisy_pixels() {
    let (image, counts) = render(ADAPTIVE_MSE, 1);
    let at = |x: u32, y: u32| counts[(y * 32 + x) as usize];
    let mean = counts.iter().map(|&c| f64::from(c)).sum::<f64>() / counts.len() as f64;
    // The budget, within the rounding of the counts to four per octave.
    assert!((mean - 64.0).abs() < 8.0, "mean count {mean}");
    let region = |inside: fn(u32, u32) -> bool| -> Vec<u32> {
        (0..16)
            .flat_map(|y| (0..32).map(move |x| (x, y)))
            .filter(|&(x, y)| inside(x, y))
            .map(|(x, y)| at(x, y))
            .collect()
    };
    // Flat pixels (σ = 0, among equal neighbours) take the floor, 64 / 4.
    assert!(region(flat).iter().all(|&c| c == 16), "{:?}", region(flat));
    let noisy = region(noisy);
    let noisy_mean = noisy.iter().map(|&c| f64::from(c)).sum::<f64>() / noisy.len() as f64;
    assert!(
        noisy_mean > 96.0,
        "noisy pixels took {noisy_mean} on average"
    );
    assert!((region_mean(&image, flat) - 3.0).abs() < 1e-5);
}

#[test]
fn the_mse_goal_is_unbiased_and_lowers_the_error_at_equal_budget() {
    // Against a fixed 4096-spp render: the noisy region's mean within its
    // standard errors, and the whole image's MSE (four seeds each) below
    // fixed spp's at the same average spp. (Spending the budget evenly
    // instead, the counts of fixed spp, gives the same MSE as fixed and
    // fails; the flat half's budget is what moves.)
    let reference = render("{type: independent, spp: 4096}", 999).0;
    let mse = |image: &Image| -> f64 {
        let sq: f64 = image
            .pixels
            .iter()
            .zip(&reference.pixels)
            .map(|(a, b)| f64::from((*a - *b).element_sum()).powi(2))
            .sum();
        sq / image.pixels.len() as f64
    };
    let seeds = 1..=6u64;
    let (mut adaptive, mut fixed) = (Vec::new(), Vec::new());
    let (mut adaptive_mse, mut fixed_mse) = (0.0, 0.0);
    for s in seeds {
        let a = render(ADAPTIVE_MSE, s).0;
        let f = render("{type: independent, spp: 64}", 100 + s).0;
        adaptive.push(region_mean(&a, noisy));
        fixed.push(region_mean(&f, noisy));
        adaptive_mse += mse(&a);
        fixed_mse += mse(&f);
    }
    let (a, ea) = mean_and_error(&adaptive);
    let r = region_mean(&reference, noisy);
    assert!(
        (a - r).abs() < 4.0 * ea + 0.005 * r,
        "adaptive {a:.5} ± {ea:.5} against the reference {r:.5}"
    );
    let (f, ef) = mean_and_error(&fixed);
    assert!(
        (f - r).abs() < 4.0 * ef + 0.005 * r,
        "fixed {f:.5} ± {ef:.5} against {r:.5}"
    );
    assert!(
        adaptive_mse < 0.7 * fixed_mse,
        "MSE: adaptive {adaptive_mse:.4e}, fixed {fixed_mse:.4e}"
    );
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
        (
            "{type: independent, adaptive: {error: mse, threshold: 0.1}}",
            "relative rule",
        ),
        ("{type: independent, adaptive: {error: rms}}", "mse"),
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
    for sampler in [ADAPTIVE, ADAPTIVE_MSE] {
        passes_and_resume_equal_one_render(sampler);
    }
}

/// Renders `sampler`'s Gaussian-filtered scene whole, then in passes cut at
/// 4/256, 40/256, 100/256 and 180/256 of its spp, with a resume after the
/// third, and checks the images are the same.
fn passes_and_resume_equal_one_render(sampler: &str) {
    let text = scene(sampler).replace(
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
    let spp = r.settings.spp;
    let cut = |k: u32| k * spp / 256;
    for pass in [0..cut(4), cut(4)..cut(40), cut(40)..cut(100)] {
        samples += render_samples(&r, &mut film, pass, &Progress::none()).samples;
    }
    // "Interrupted" at 100/256 of the spp: the state file keeps the sums only.
    let mut resumed = film.clone();
    resumed.adaptive_counts = None;
    for pass in [cut(100)..cut(180), cut(180)..spp] {
        samples += render_samples(&r, &mut resumed, pass, &Progress::none()).samples;
    }
    let image = resumed.try_develop().expect("fits");
    assert!(
        image == one,
        "{sampler}: passes and resume differ from one render"
    );
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
