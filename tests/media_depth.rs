//! What `max_depth` counts in scenes with `null` boundaries: real
//! scattering vertices only (surfaces other than `null`, medium events),
//! as Mitsuba 3's `volpath` counts them; crossing a `null` boundary uses
//! up no bounce. Single scattering in a slab behind a `null` boundary
//! against its closed form at `max_depth: 2`, the grid cloud at
//! `max_depth: 2` against Mitsuba's reference made the same way, and the
//! bound on crossings that keeps paths finite in degenerate scenes.
//!
//! Reference: `tests/data/media-cloud-depth2-mitsuba.exr`, Mitsuba 3.9.1
//! (`scalar_rgb`, `volpath`, `max_depth` 2, 8192 spp) rendering
//! `scenes/media/cloud.yaml`'s scene (`tests/reference/render_media.py
//! --scene cloud --max-depth 2`, its docstring has the command).

// `expect` in this test code is the assertion: the scenes are the test's
// own, so a failure is a bug, and the panic reports it.

use radiant::extract::Overrides;
use radiant::film::Image;
use radiant::film::output::read_exr;
use radiant_tests::{check_against, render_edited, root};

fn render_text(text: &str) -> radiant::backend::cpu::Rendered {
    let scene = radiant::scene::from_str(text, std::path::Path::new("depth.yaml"), &root())
        .expect("the test's scene parses");
    let r = radiant::extract::extract(&scene, &radiant::builtin_registry(), &Overrides::default())
        .expect("the test's scene extracts");
    radiant::backend::cpu::render(&r, &radiant::backend::cpu::Progress::none())
}

/// Per channel: the mean over the image's pixels and its standard error
/// (the pixels are independent estimates of one value).
fn pixel_mean(image: &Image) -> [(f64, f64); 3] {
    let n = image.pixels.len() as f64;
    std::array::from_fn(|c| {
        let mean = image.pixels.iter().map(|p| f64::from(p[c])).sum::<f64>() / n;
        let var = image
            .pixels
            .iter()
            .map(|p| (f64::from(p[c]) - mean).powi(2))
            .sum::<f64>()
            / (n - 1.0);
        (mean, (var / n).sqrt())
    })
}

const SIGMA_S: [f64; 3] = [0.4, 0.8, 1.6];
const SIGMA_A: f64 = 0.1;
const IRRADIANCE: f64 = 10.0;

/// An orthographic camera looking down −z into the middle of the front
/// face of a `null` cube [−1, 1]³ of homogeneous isotropic medium, a sun
/// shining along −z (from behind the camera), nothing else.
fn slab(max_depth: i32) -> String {
    format!(
        "integrator: {{type: path, max_depth: {max_depth}}}\n\
         film: {{width: 16, height: 16, filter: {{type: box}}}}\n\
         sampler: {{type: independent, spp: 256}}\n\
         camera: {{type: orthographic, width: 0.5, look_at: {{origin: [0, 0, 5], target: [0, 0, 0], up: [0, 1, 0]}}}}\n\
         media:\n  m: {{type: homogeneous, sigma_s: [{}, {}, {}], sigma_a: {SIGMA_A}, phase: {{type: isotropic}}}}\n\
         shapes:\n  - {{type: cube, material: {{type: null}}, interior: m}}\n\
         lights:\n  - {{type: directional, direction: [0, 0, -1], irradiance: {IRRADIANCE}}}\n",
        SIGMA_S[0], SIGMA_S[1], SIGMA_S[2]
    )
}

#[test]
fn single_scattering_behind_a_null_boundary_is_the_closed_form_at_max_depth_2() {
    // The camera ray crosses the `null` front face (no bounce), scatters at
    // depth s (its first vertex: next-event estimation to the sun is
    // allowed at max_depth 2) and sees the sun attenuated along the same
    // depth s: L = ∫₀² σs·e^(−2σt·s)·E/(4π) ds = σs·E·(1 − e^(−4σt))/(8π·σt).
    // Its continuation is the second vertex, which max_depth 2 forbids, so
    // the image is single scattering alone. Counting the crossing as a
    // bounce (the old rule) made this image black.
    let r = render_text(&slab(2));
    assert_eq!(r.invalid_samples, 0);
    let measured = pixel_mean(&r.image);
    for (c, &(mean, se)) in measured.iter().enumerate() {
        let sigma_t = SIGMA_S[c] + SIGMA_A;
        let exact = SIGMA_S[c] * IRRADIANCE * (1.0 - (-4.0 * sigma_t).exp())
            / (8.0 * std::f64::consts::PI * sigma_t);
        eprintln!("channel {c}: {mean} ± {se}, closed form {exact}");
        assert!(
            (mean - exact).abs() < 4.0 * se + 1e-3 * exact,
            "channel {c}: {mean} ± {se} against {exact}"
        );
    }
    // One more bounce adds multiple scattering: brighter in every channel.
    let deeper = pixel_mean(&render_text(&slab(3)).image);
    for c in 0..3 {
        assert!(
            deeper[c].0 > measured[c].0 + 4.0 * (deeper[c].1 + measured[c].1),
            "channel {c}: max_depth 3 {:?} against 2 {:?}",
            deeper[c],
            measured[c]
        );
    }
}

#[test]
fn the_cloud_at_max_depth_2_matches_mitsuba_volpath() {
    // The grid cloud inside its `null` cube: at max_depth 2, single
    // scattering of the sun and the sky plus the sky seen through the
    // cloud. Counting the crossing as a bounce lost the single scattering
    // (the mean fell to the transmitted sky alone).
    let overrides = Overrides {
        spp: Some(256),
        seed: Some(3),
        max_depth: Some(2),
        ..Default::default()
    };
    let r = render_edited("scenes/media/cloud.yaml", str::to_string, overrides);
    assert_eq!(r.invalid_samples, 0);
    let reference =
        read_exr(root().join("tests/data/media-cloud-depth2-mitsuba.exr")).expect("reference EXR");
    let check = check_against(&r.image, &reference, 16);
    eprintln!("cloud at max_depth 2: {check:?}");
    assert!(
        check.worst_channel_mean_error < 0.01 && check.worst_block_error < 0.05,
        "{check:?}"
    );
}

/// `nested` `null` cubes (no media) around an emitting sphere of radiance
/// 1, seen through all of them by an orthographic camera.
fn nested(boundaries: u32, max_depth: i32) -> String {
    let mut text = format!(
        "integrator: {{type: path, max_depth: {max_depth}}}\n\
         film: {{width: 4, height: 4, filter: {{type: box}}}}\n\
         sampler: {{type: independent, spp: 4}}\n\
         camera: {{type: orthographic, width: 0.1, look_at: {{origin: [0, 0, 50], target: [0, 0, 0], up: [0, 1, 0]}}}}\n\
         shapes:\n  - {{type: sphere, radius: 0.2, material: {{type: diffuse, reflectance: 0}}, emitter: {{type: area, radiance: 1}}}}\n"
    );
    for k in 0..boundaries {
        let half = 0.5 + 0.05 * k as f32;
        text.push_str(&format!(
            "  - {{type: cube, material: {{type: null}}, transform: {{scale: {half}}}}}\n"
        ));
    }
    text
}

#[test]
fn null_crossings_are_bounded_so_paths_end_in_degenerate_scenes() {
    // max_depth 1 (emitters seen directly): the emitter is seen through 256
    // `null` boundaries (crossings use up no bounce), and not through 257:
    // a path crosses at most MAX_CROSSINGS = 256 boundaries, then ends, so
    // even unlimited depth terminates among endless `null` shells.
    for (boundaries, max_depth, expected) in [(256, 1, 1.0), (257, 1, 0.0), (300, -1, 0.0)] {
        let r = render_text(&nested(boundaries, max_depth));
        assert_eq!(r.invalid_samples, 0);
        for p in &r.image.pixels {
            assert!(
                (p.x - expected).abs() < 1e-4 && (p.z - expected).abs() < 1e-4,
                "{boundaries} boundaries, max_depth {max_depth}: pixel {p}, expected {expected}"
            );
        }
    }
}
