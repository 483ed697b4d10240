//! Participating media: the sampling routines against their densities,
//! the free-flight estimator against closed forms, a medium furnace, a
//! smoke sphere against Mitsuba 3's `volpath`, and bad input.
//!
//! The reference `tests/data/media-smoke-mitsuba.exr` is Mitsuba 3.9.1
//! (`scalar_rgb`, `volpath`, 32768 spp) rendering
//! `scenes/media/cornell-smoke.yaml`'s scene; regenerate it with
//! `tests/reference/render_media.py` (its docstring has the command).

use glam::{Vec2, Vec3};
use radiant::extract::Overrides;
use radiant::film::Image;
use radiant::film::output::read_exr;
use radiant_core::Rgb;
use radiant_core::medium::{
    free_flight, henyey_greenstein, sample_henyey_greenstein, transmittance,
};
use radiant_tests::SplitMix;
use radiant_tests::chi2::{SIGNIFICANCE, invert_cdf, uniform_p_value};
use radiant_tests::{check_against, render_edited, root};

/// The CDF of μ = wo·wi under Henyey–Greenstein, in closed form (the
/// integral of its density from −1 to μ).
fn hg_cdf(mu: f64, g: f64) -> f64 {
    if g.abs() < 1e-3 {
        return 0.5 * (mu + 1.0);
    }
    (1.0 - g * g) / (2.0 * g) * (1.0 / (1.0 - g).abs() - 1.0 / (1.0 + g * g + 2.0 * g * mu).sqrt())
}

#[test]
fn henyey_greenstein_sampling_matches_its_density() {
    const MU_CELLS: usize = 50;
    const PHI_CELLS: usize = 8;
    const SAMPLES: usize = 200_000;
    for g in [-0.9f32, 0.0, 0.3, 0.99] {
        let g64 = f64::from(g);
        // The closed-form CDF is the integral of the density the renderer
        // evaluates: its derivative matches `henyey_greenstein`.
        for mu in [-0.9, -0.3, 0.0, 0.5, 0.95] {
            let h = 1e-6;
            let slope = (hg_cdf(mu + h, g64) - hg_cdf(mu - h, g64)) / (2.0 * h);
            let density = 2.0 * std::f64::consts::PI * f64::from(henyey_greenstein(mu as f32, g));
            assert!(
                (slope - density).abs() < 1e-3 * density.max(1.0),
                "g {g}, μ {mu}: {slope} vs {density}"
            );
        }
        // Cells of equal probability in μ (by the CDF) times equal cells
        // in φ about wo.
        let edges: Vec<f64> = (1..MU_CELLS)
            .map(|k| invert_cdf(|m| hg_cdf(m, g64), k as f64 / MU_CELLS as f64, -1.0, 1.0))
            .collect();
        let wo = Vec3::new(0.36, -0.48, 0.8);
        let frame = radiant_core::Frame::from_normal(wo);
        let mut rng = SplitMix(17 + (g * 100.0) as u64);
        let mut observed = vec![0.0f64; MU_CELLS * PHI_CELLS];
        for _ in 0..SAMPLES {
            let (wi, pdf) = sample_henyey_greenstein(wo, g, Vec2::new(rng.unit(), rng.unit()));
            assert!(
                (wi.length() - 1.0).abs() < 1e-4 && pdf > 0.0,
                "g {g}: {wi} {pdf}"
            );
            let local = frame.to_local(wi);
            let mu = f64::from(wo.dot(wi));
            let i = edges.partition_point(|&e| e < mu);
            let phi = f64::from(local.y.atan2(local.x)) + std::f64::consts::PI;
            let j = ((phi / std::f64::consts::TAU * PHI_CELLS as f64) as usize).min(PHI_CELLS - 1);
            observed[i * PHI_CELLS + j] += 1.0;
        }
        let p = uniform_p_value(&observed);
        assert!(p > SIGNIFICANCE, "HG g = {g}: p = {p}");
    }
}

#[test]
fn a_wrong_asymmetry_fails_the_hg_test() {
    // Power: samples of g = 0.3 binned by the cells of g = 0.32.
    let (g, wrong) = (0.3f32, 0.32f64);
    let edges: Vec<f64> = (1..50)
        .map(|k| invert_cdf(|m| hg_cdf(m, wrong), k as f64 / 50.0, -1.0, 1.0))
        .collect();
    let wo = Vec3::Z;
    let mut rng = SplitMix(5);
    let mut observed = vec![0.0f64; 50];
    for _ in 0..200_000 {
        let (wi, _) = sample_henyey_greenstein(wo, g, Vec2::new(rng.unit(), rng.unit()));
        observed[edges.partition_point(|&e| e < f64::from(wi.z))] += 1.0;
    }
    assert!(uniform_p_value(&observed) < SIGNIFICANCE);
}

/// σt of a strongly chromatic medium.
const SIGMA_T: Rgb = Rgb::new(0.5, 2.0, 8.0);

#[test]
fn free_flight_distances_follow_the_mixture_of_exponentials() {
    // Hero channel uniform, then its exponential: the density is the
    // average of the three channels' exponentials, CDF 1 − mean(e^{−σt}).
    let cdf = |t: f64| {
        1.0 - (0..3)
            .map(|c| (-f64::from(SIGMA_T[c]) * t).exp())
            .sum::<f64>()
            / 3.0
    };
    const CELLS: usize = 100;
    let edges: Vec<f64> = (1..CELLS)
        .map(|k| invert_cdf(cdf, k as f64 / CELLS as f64, 0.0, 200.0))
        .collect();
    for (sigma, name) in [(SIGMA_T, "chromatic"), (Rgb::splat(1.5), "grey")] {
        let cdf = |t: f64| {
            1.0 - (0..3)
                .map(|c| (-f64::from(sigma[c]) * t).exp())
                .sum::<f64>()
                / 3.0
        };
        let edges: Vec<f64> = if name == "grey" {
            (1..CELLS)
                .map(|k| invert_cdf(cdf, k as f64 / CELLS as f64, 0.0, 200.0))
                .collect()
        } else {
            edges.clone()
        };
        let mut rng = SplitMix(3);
        let mut observed = vec![0.0f64; CELLS];
        for _ in 0..200_000 {
            let f = free_flight(sigma, rng.unit(), rng.unit(), f32::INFINITY);
            assert!(f.scattered && f.t.is_finite() && f.t >= 0.0);
            observed[edges.partition_point(|&e| e < f64::from(f.t))] += 1.0;
        }
        let p = uniform_p_value(&observed);
        assert!(p > SIGNIFICANCE, "{name}: p = {p}");
    }
}

#[test]
fn free_flight_estimates_transmittance_and_extinction_without_bias() {
    // Over a segment of length d: E[weight · 1(pass)] = T(d) and
    // E[weight · σt · 1(scatter)] = 1 − T(d), per channel (the weights of
    // the one-sample MIS over channels are unbiased for every channel).
    for d in [0.05f32, 0.4, 2.0] {
        let n = 400_000u32;
        let mut rng = SplitMix(11);
        // Sums in f64: f32 sums of 10^5 terms round with a bias.
        let (mut pass, mut pass2) = ([0.0f64; 3], [0.0f64; 3]);
        let (mut ext, mut ext2) = ([0.0f64; 3], [0.0f64; 3]);
        for _ in 0..n {
            let f = free_flight(SIGMA_T, rng.unit(), rng.unit(), d);
            let (x, sum, sum2) = if f.scattered {
                (f.weight * SIGMA_T, &mut ext, &mut ext2)
            } else {
                (f.weight, &mut pass, &mut pass2)
            };
            for c in 0..3 {
                sum[c] += f64::from(x[c]);
                sum2[c] += f64::from(x[c]) * f64::from(x[c]);
            }
        }
        let tr = transmittance(SIGMA_T, d);
        for (sum, sum2, expected, what) in [
            (pass, pass2, tr, "transmittance"),
            (ext, ext2, Rgb::ONE - tr, "extinction"),
        ] {
            for c in 0..3 {
                let mean = sum[c] / f64::from(n);
                let var = sum2[c] / f64::from(n) - mean * mean;
                let sigma = (var / f64::from(n)).sqrt();
                let expected = f64::from(expected[c]);
                assert!(
                    (mean - expected).abs() <= 4.0 * sigma + 1e-6,
                    "d {d}, {what}, channel {c}: {mean} vs {expected} (σ {sigma})"
                );
            }
        }
    }
}

/// A sphere of medium behind a `null` boundary under a uniform white
/// environment of radiance 1, seen from outside.
fn furnace(medium: &str) -> String {
    format!(
        "integrator: {{type: path, max_depth: -1}}\n\
         film: {{width: 16, height: 16, filter: {{type: box}}}}\n\
         sampler: {{type: independent, spp: 256}}\n\
         camera: {{type: perspective, fov: 40, look_at: {{origin: [0, 0, 4], target: [0, 0, 0], up: [0, 1, 0]}}}}\n\
         media:\n  m: {medium}\n\
         shapes:\n  - {{type: sphere, radius: 1, material: {{type: null}}, interior: m}}\n\
         lights:\n  - {{type: environment, radiance: 1}}\n"
    )
}

fn render_text(text: &str, overrides: Overrides) -> radiant::backend::cpu::Rendered {
    let scene = radiant::scene::from_str(text, std::path::Path::new("furnace.yaml"), &root())
        .expect("the test's scene parses");
    let r = radiant::extract::extract(&scene, &radiant::builtin_registry(), &overrides)
        .expect("the test's scene extracts");
    radiant::backend::cpu::render(&r, &radiant::backend::cpu::Progress::none())
}

#[test]
fn medium_furnace_returns_the_environment() {
    // Albedo 1 (grey, anisotropic, optically thick): every pixel is the
    // environment's radiance 1 — the estimator neither creates nor loses
    // energy through distance sampling, phase sampling, next-event
    // estimation through the boundary and their MIS.
    let lossless = render_text(
        &furnace("{type: homogeneous, albedo: 1, density: 3, phase: {type: hg, g: 0.6}}"),
        Overrides::default(),
    );
    assert_eq!(lossless.invalid_samples, 0);
    let mean: f64 = lossless
        .image
        .pixels
        .iter()
        .map(|p| f64::from(p.element_sum()) / 3.0)
        .sum::<f64>()
        / lossless.image.pixels.len() as f64;
    let worst = lossless
        .image
        .pixels
        .iter()
        .map(|p| (*p - Rgb::ONE).abs().max_element())
        .fold(0.0f32, f32::max);
    eprintln!("albedo-1 furnace: mean {mean}, worst pixel off by {worst}");
    assert!((mean - 1.0).abs() < 0.005, "albedo-1 furnace mean {mean}");
    assert!(worst < 0.1, "a pixel is off by {worst}");
    // Albedo < 1 (chromatic): never brighter than the environment, and
    // darker where the rays cross the sphere.
    let lossy = render_text(
        &furnace("{type: homogeneous, sigma_s: [1, 2, 3], sigma_a: [0.5, 0.1, 1.5]}"),
        Overrides::default(),
    );
    assert_eq!(lossy.invalid_samples, 0);
    for p in &lossy.image.pixels {
        assert!(p.max_element() < 1.05, "pixel {p} exceeds the environment");
    }
    let centre = lossy.image.pixels[8 * 16 + 8];
    assert!(centre.max_element() < 0.9, "the sphere's centre {centre}");
}

/// The mean and the largest channel value of an image.
fn mean_and_max(image: &Image) -> (f64, f32) {
    let n = image.pixels.len() as f64;
    let mean = image
        .pixels
        .iter()
        .map(|p| f64::from(p.element_sum()) / 3.0)
        .sum::<f64>()
        / n;
    let max = image
        .pixels
        .iter()
        .map(|p| p.max_element())
        .fold(0.0f32, f32::max);
    (mean, max)
}

#[test]
fn torture_media_are_finite_terminate_and_keep_their_energy() {
    // Optically very thick (density 1e4, albedo 0.5): paths end by
    // absorption and roulette; finite, never above the environment, and
    // the sphere is dark (it absorbs half at every one of its many
    // scatterings).
    let thick = render_text(
        &furnace("{type: homogeneous, albedo: 0.5, density: 1e4}"),
        Overrides::default(),
    );
    assert_eq!(thick.invalid_samples, 0);
    let (_, max) = mean_and_max(&thick.image);
    assert!(max < 1.05, "thick medium: a pixel at {max}");
    assert!(thick.image.pixels[8 * 16 + 8].max_element() < 0.5);
    // Nearly vacuum (density 1e-6): the image is the empty scene's, the
    // environment's radiance 1 everywhere.
    let thin = render_text(
        &furnace("{type: homogeneous, albedo: 0.5, density: 1e-6}"),
        Overrides::default(),
    );
    for p in &thin.image.pixels {
        assert!(
            (*p - Rgb::ONE).abs().max_element() < 1e-3,
            "thin medium: pixel {p}"
        );
    }
    // g = ±0.999 (nearly a delta lobe either way), albedo 1: the furnace
    // still returns the environment.
    for g in ["0.999", "-0.999"] {
        let r = render_text(
            &furnace(&format!(
                "{{type: homogeneous, albedo: 1, density: 2, phase: {{type: hg, g: {g}}}}}"
            )),
            Overrides::default(),
        );
        assert_eq!(r.invalid_samples, 0);
        let (mean, _) = mean_and_max(&r.image);
        assert!((mean - 1.0).abs() < 0.01, "g = {g}: mean {mean}");
    }
    // The camera inside the medium (`camera: {medium: m}`), looking out
    // through the boundary: still the environment.
    let inside = furnace("{type: homogeneous, albedo: 1, density: 1.5}").replace(
        "camera: {type: perspective, fov: 40, look_at: {origin: [0, 0, 4],",
        "camera: {type: perspective, fov: 40, medium: m, look_at: {origin: [0, 0, 0.5],",
    );
    assert!(inside.contains("medium: m"));
    let r = render_text(&inside, Overrides::default());
    let (mean, _) = mean_and_max(&r.image);
    assert!((mean - 1.0).abs() < 0.01, "camera inside: mean {mean}");
}

// --- Against Mitsuba 3 `volpath` -------------------------------------------

const SPP: u32 = 256;
/// Allowed |mean ratio − 1| per colour channel (the 1 %).
const CHANNEL_MEAN_TOLERANCE: f64 = 0.01;

fn render_at(scene: &str, edit: impl FnOnce(&str) -> String, spp: u32, seed: u64) -> Image {
    let overrides = Overrides {
        spp: Some(spp),
        seed: Some(seed),
        ..Default::default()
    };
    let r = render_edited(scene, edit, overrides);
    assert_eq!(r.invalid_samples, 0);
    r.image
}

fn reference(name: &str) -> Image {
    read_exr(root().join("tests/data").join(name)).expect("reference EXR")
}

/// Side of the blocks whose means are compared, in pixels.
const BLOCK: u32 = 16;
/// Allowed relative error of a 16×16 block mean of the smoke in the
/// Cornell box at 256 spp (measured: see the test's output).
const BLOCK_TOLERANCE: f64 = 0.04;

#[test]
fn smoke_in_the_cornell_box_matches_mitsuba_volpath() {
    let image = render_at("scenes/media/cornell-smoke.yaml", str::to_string, SPP, 7);
    let check = check_against(&image, &reference("media-smoke-mitsuba.exr"), BLOCK);
    eprintln!("smoke in the Cornell box: {check:?}");
    assert!(
        check.worst_channel_mean_error < CHANNEL_MEAN_TOLERANCE
            && check.worst_block_error < BLOCK_TOLERANCE,
        "{check:?}"
    );
}

const DARK: &str = "scenes/media/smoke-dark.yaml";
const LIT_SPP: u32 = 1024;
/// Allowed relative error of a 16×16 block mean of the lit smoke at
/// 1024 spp (blocks at the smoke's dim rim are the noisiest).
const LIT_BLOCK_TOLERANCE: f64 = 0.08;

#[test]
fn lit_smoke_matches_mitsuba_volpath_and_a_2_percent_sigma_s_error_fails() {
    // Nothing but in-scattered light reaches the camera, so the image
    // moves with σs. Measured at 4096 spp: mean within 0.08 %, worst block
    // 3.2 %; at 1024 spp σs ± 2 % moves the mean by about 2 %.
    let reference = reference("media-dark-mitsuba.exr");
    let image = render_at(DARK, str::to_string, LIT_SPP, 5);
    let check = check_against(&image, &reference, BLOCK);
    eprintln!("lit smoke: {check:?}");
    assert!(
        check.worst_channel_mean_error < CHANNEL_MEAN_TOLERANCE
            && check.worst_block_error < LIT_BLOCK_TOLERANCE,
        "{check:?}"
    );
    for sigma_s in ["1.1016", "1.0584"] {
        let wrong = render_at(
            DARK,
            |t| {
                assert!(t.contains("sigma_s: 1.08\n"));
                t.replace("sigma_s: 1.08\n", &format!("sigma_s: {sigma_s}\n"))
            },
            LIT_SPP,
            5,
        );
        let check = check_against(&wrong, &reference, BLOCK);
        eprintln!("sigma_s {sigma_s}: {check:?}");
        assert!(
            check.worst_channel_mean_error >= CHANNEL_MEAN_TOLERANCE,
            "a 2 % σs error went unnoticed: {check:?}"
        );
    }
}

// --- Bad input ---------------------------------------------------------------

fn load_error(text: &str) -> String {
    let scene = match radiant::scene::from_str(text, std::path::Path::new("bad.yaml"), &root()) {
        Err(e) => return e.to_string(),
        Ok(s) => s,
    };
    match radiant::extract::extract(&scene, &radiant::builtin_registry(), &Overrides::default()) {
        Err(e) => e.to_string(),
        Ok(_) => panic!("the scene was accepted:\n{text}"),
    }
}

#[test]
fn bad_media_are_located_errors() {
    let with = |media: &str, shape: &str| {
        format!(
            "camera: {{type: perspective}}\n\
             media:\n  fog: {media}\n\
             shapes:\n  - {shape}\n"
        )
    };
    let sphere = "{type: sphere, material: {type: null}, interior: fog}";
    for (text, line, words) in [
        (
            with("{type: homogeneous, sigma_s: -1}", sphere),
            3,
            "`sigma_s` must be 0 or more",
        ),
        (
            with("{type: homogeneous, sigma_a: .nan}", sphere),
            3,
            "sigma_a: expected a number",
        ),
        (
            with("{type: homogeneous, phase: {type: hg, g: 1}}", sphere),
            3,
            "strictly between",
        ),
        (
            with("{type: homogeneous, phase: {type: hg, g: -1.2}}", sphere),
            3,
            "strictly between",
        ),
        (
            with("{type: homogeneous}", "{type: rectangle, interior: fog}"),
            5,
            "closed shape",
        ),
        (
            with("{type: homogeneous}", "{type: sphere, interior: smoke}"),
            5,
            "undefined medium `smoke`",
        ),
        (
            with("{type: vapour}", sphere),
            3,
            "unknown medium type `vapour`",
        ),
        (
            with("{type: homogeneous, phase: {type: rayleigh}}", sphere),
            3,
            "unknown phase type",
        ),
    ] {
        let e = load_error(&text);
        assert!(e.contains(words), "{text}\n→ {e}");
        assert!(
            e.contains(&format!("bad.yaml:{line}:")),
            "{text}\n→ {e} (expected line {line})"
        );
    }
}

#[test]
fn a_medium_in_an_open_mesh_is_a_located_error() {
    let dir = tempfile::tempdir().expect("a temporary folder");
    let obj = dir.path().join("open.obj");
    // Two triangles of a square: every outer edge has one side only.
    std::fs::write(
        &obj,
        "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nf 1 2 3\nf 1 3 4\n",
    )
    .expect("the temporary folder is writable");
    let text = format!(
        "camera: {{type: perspective}}\n\
         media:\n  fog: {{type: homogeneous}}\n\
         shapes:\n  - {{type: mesh, filename: {}, interior: fog}}\n",
        obj.display()
    );
    let e = load_error(&text);
    assert!(e.contains("closed shape") && e.contains("4 edges"), "{e}");
    assert!(e.contains("bad.yaml:5:"), "{e}");
}

#[test]
fn an_emitting_absorber_glows_as_the_closed_form() {
    // A purely absorbing sphere (σa = 1.5, radius 1) of emitted radiance
    // Le, no lights, seen from afar through a 2° field: each ray's chord l
    // is between 1.97 and 2, so its radiance Le·(1 − e^(−σa·l)) lies
    // between 0.94796 and 0.95021 times Le.
    let text = "integrator: {type: path, max_depth: -1}\n\
         film: {width: 16, height: 16, filter: {type: box}}\n\
         sampler: {type: independent, spp: 256}\n\
         camera: {type: perspective, fov: 2, look_at: {origin: [0, 0, 10], target: [0, 0, 0], up: [0, 1, 0]}}\n\
         media:\n  glow: {type: homogeneous, sigma_a: 1.5, emission: [2, 1, 0.5]}\n\
         shapes:\n  - {type: sphere, radius: 1, material: {type: null}, interior: glow}\n";
    let r = render_text(text, Overrides::default());
    assert_eq!(r.invalid_samples, 0);
    let n = r.image.pixels.len() as f64;
    for (c, le) in [2.0f64, 1.0, 0.5].into_iter().enumerate() {
        let mean = r.image.pixels.iter().map(|p| f64::from(p[c])).sum::<f64>() / n;
        // Per sample Le or 0 (σa·Le·T/pdf = Le): σ ≈ 0.22·Le/√(256·256).
        let (lo, hi) = (0.94796 * le - 0.004 * le, 0.95021 * le + 0.004 * le);
        assert!(
            mean > lo && mean < hi,
            "channel {c}: {mean} outside [{lo}, {hi}]"
        );
    }
}

#[test]
fn juice_in_a_glass_is_tinted_by_its_absorption() {
    // An absorbing chromatic liquid (σa = 0.05, 0.6, 2 per unit length)
    // inside a dielectric sphere (η = 1.33) under a uniform environment:
    // rays refract in, are absorbed along their way through the liquid and
    // refract out. Finite, darker than the environment, and the centre is
    // tinted in the order of the absorption: nearly the environment in
    // red (e^(−0.1) ≈ 0.9 before Fresnel), e^(−4) ≈ 0.02 in blue.
    let text = furnace("{type: homogeneous, sigma_a: [0.05, 0.6, 2], sigma_s: 0}").replace(
        "material: {type: null}",
        "material: {type: dielectric, int_ior: 1.33}",
    );
    assert!(text.contains("dielectric"));
    let r = render_text(&text, Overrides::default());
    assert_eq!(r.invalid_samples, 0);
    // Roulette inside the glass divides survivors by their survival
    // probability, so a pixel may exceed 1 by noise; the image as a whole
    // may not.
    let (mean, max) = mean_and_max(&r.image);
    assert!(mean < 1.0 && max < 1.5, "mean {mean}, a pixel at {max}");
    let c = r.image.pixels[8 * 16 + 8];
    assert!(
        c.x > 0.75 && c.x < 1.0 && c.y < c.x && c.z < c.y && c.z < 0.1,
        "centre {c}"
    );
}
