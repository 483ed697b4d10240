//! Renders in which one sampling routine dominates the image, compared
//! with values computed apart from the renderer, tightly enough to see
//! about 1 % in the mean:
//!
//! * a diffuse floor lit only by a sphere light, and one lit only by a
//!   rectangle light, against their closed-form irradiance (the projected
//!   solid angle of a sphere cap, π sin²α cos θ; Lambert's polygon
//!   formula);
//! * the blur of an out-of-focus edge through the thin lens, whose width
//!   is fitted and compared with the thin-lens formula, so that an
//!   aperture 2 % off fails;
//! * a diffuse sphere lit only by an environment map with light in every
//!   direction, seen from below so that the lower hemisphere counts,
//!   against the irradiance integrated by quadrature over the map's own
//!   `eval_escaped`.
//!
//! Each test also renders the scene with the light 2 % brighter (or the
//! aperture 2 % wider) and requires the comparison to reject it, so the
//! tolerances are shown to have the power the test claims.

use glam::{Vec2, Vec3};
use radiant::backend::cpu::{Progress, render};
use radiant::extract::{Overrides, RenderScene, extract};
use radiant::film::Image;
use std::f32::consts::PI;

/// Extracts the scene `text` (paths relative to `dir`).
fn extract_text(text: &str, dir: &std::path::Path) -> RenderScene {
    let scene = radiant::scene::from_str(text, &dir.join("test.yaml"), dir).expect("scene parses");
    extract(&scene, &radiant::builtin_registry(), &Overrides::default()).expect("scene extracts")
}

/// World-space rays through `n`×`n` sub-pixel positions of every pixel
/// (render space is world space less the camera position `eye`), row by
/// row, `n²` per pixel.
fn pixel_rays(scene: &RenderScene, eye: Vec3, n: u32) -> Vec<(Vec3, Vec3)> {
    let (w, h) = (scene.settings.width, scene.settings.height);
    let mut film = Vec::new();
    for y in 0..h {
        for x in 0..w {
            for j in 0..n {
                for i in 0..n {
                    film.push(Vec2::new(
                        x as f32 + (i as f32 + 0.5) / n as f32,
                        y as f32 + (j as f32 + 0.5) / n as f32,
                    ));
                }
            }
        }
    }
    radiant_tests::camera_rays(scene, &film)
        .into_iter()
        .map(|(o, d)| (o + eye, d))
        .collect()
}

/// The mean of the channel means of `image` over the pixels `mask` keeps.
fn masked_mean(image: &Image, mask: &[bool]) -> f64 {
    let (mut sum, mut count) = (0.0, 0);
    for (p, keep) in image.pixels.iter().zip(mask) {
        if *keep {
            sum += f64::from(p.x + p.y + p.z) / 3.0;
            count += 1;
        }
    }
    sum / f64::from(count)
}

/// Relative tolerance of an image mean against its closed-form value:
/// noise is below 0.15 % at these sample counts (measured), and the 2 %
/// brighter light must fail.
const MEAN_TOLERANCE: f64 = 0.006;

/// Renders the floor scene `text` (camera at `eye`, floor z = 0, albedo
/// `albedo`) and compares its mean with the mean of `radiance(x)` at the
/// floor points the pixels see; returns the relative error.
fn floor_error(text: &str, eye: Vec3, radiance: impl Fn(Vec3) -> f64) -> f64 {
    let dir = std::env::temp_dir();
    let scene = extract_text(text, &dir);
    let image = render(&scene, &Progress::none()).image;
    let n = 4;
    let rays = pixel_rays(&scene, eye, n);
    let per_pixel = (n * n) as usize;
    let expected: Vec<f64> = rays
        .chunks(per_pixel)
        .map(|c| {
            c.iter()
                .map(|(o, d)| {
                    let t = -o.z / d.z;
                    radiance(*o + *d * t)
                })
                .sum::<f64>()
                / per_pixel as f64
        })
        .collect();
    let mask = vec![true; expected.len()];
    let mean = masked_mean(&image, &mask);
    let want = expected.iter().sum::<f64>() / expected.len() as f64;
    (mean / want - 1.0).abs()
}

const ALBEDO: f64 = 0.5;

/// A floor of albedo [`ALBEDO`] seen from above, lit by `light` alone,
/// direct light only (`max_depth: 2`); the light is outside the view.
fn floor_scene(light: &str) -> String {
    format!(
        "integrator: {{type: path, max_depth: 2}}
film: {{width: 64, height: 64, filter: {{type: box}}}}
sampler: {{type: independent, spp: 64}}
camera: {{type: perspective, fov: 40, look_at: {{origin: [0, 0, 4], target: [0, 0, 0], up: [0, 1, 0]}}}}
shapes:
  - {{type: rectangle, transform: [{{scale: 10}}], material: {{type: diffuse, reflectance: {ALBEDO}}}}}
  - {light}
"
    )
}

const EYE: Vec3 = Vec3::new(0.0, 0.0, 4.0);

#[test]
fn sphere_light_irradiance_matches_the_closed_form() {
    let (centre, r, l) = (Vec3::new(2.2, 0.3, 0.9), 0.4f32, 5.0f32);
    let sphere = |radiance: f32| {
        format!(
            "{{type: sphere, center: [{}, {}, {}], radius: {r}, material: {{type: diffuse, reflectance: 0}}, emitter: {{type: area, radiance: {radiance}}}}}",
            centre.x, centre.y, centre.z
        )
    };
    // The projected solid angle of a sphere wholly above the horizon is
    // π sin²α cos θ: outgoing radiance ρ L (r/d)² cos θ.
    let radiance = |x: Vec3| {
        let to = centre - x;
        let d2 = f64::from(to.length_squared());
        let cos = f64::from(to.z) / d2.sqrt();
        ALBEDO * f64::from(l) * f64::from(r * r) / d2 * cos
    };
    let error = floor_error(&floor_scene(&sphere(l)), EYE, radiance);
    eprintln!(
        "sphere light: mean {:.3} % off the closed form",
        100.0 * error
    );
    assert!(error < MEAN_TOLERANCE / 2.0, "sphere light: {error}");
    let brighter = floor_error(&floor_scene(&sphere(l * 1.02)), EYE, radiance);
    assert!(
        brighter > MEAN_TOLERANCE,
        "a 2 % brighter sphere went unnoticed: {brighter}"
    );
}

/// Irradiance at `x` (normal +z) from a polygon of radiance `l` with
/// corners `v`, wholly above the horizon and facing `x` (Lambert).
fn polygon_irradiance(x: Vec3, v: &[Vec3], l: f64) -> f64 {
    let mut sum = 0.0f64;
    for i in 0..v.len() {
        let a = (v[i] - x).normalize().as_dvec3();
        let b = (v[(i + 1) % v.len()] - x).normalize().as_dvec3();
        let angle = a.dot(b).clamp(-1.0, 1.0).acos();
        sum += angle * a.cross(b).normalize().z;
    }
    0.5 * l * sum.abs()
}

#[test]
fn rectangle_light_irradiance_matches_the_closed_form() {
    let l = 4.0f32;
    // A 0.8 × 0.8 rectangle facing down and towards −y, outside the view.
    let transform =
        "[{translate: [-2.2, 0.4, 1.0]}, {rotate: {axis: [1, 0, 0], angle: 150}}, {scale: 0.4}]";
    let rectangle = |radiance: f32| {
        format!(
            "{{type: rectangle, transform: {transform}, material: {{type: diffuse, reflectance: 0}}, emitter: {{type: area, radiance: {radiance}}}}}"
        )
    };
    let turn = glam::Mat3::from_rotation_x(150f32.to_radians());
    let corners: Vec<Vec3> = [(-1.0, -1.0), (1.0, -1.0), (1.0, 1.0), (-1.0, 1.0)]
        .iter()
        .map(|&(x, y)| Vec3::new(-2.2, 0.4, 1.0) + turn * Vec3::new(x, y, 0.0) * 0.4)
        .collect();
    let radiance =
        |x: Vec3| ALBEDO / std::f64::consts::PI * polygon_irradiance(x, &corners, f64::from(l));
    let error = floor_error(&floor_scene(&rectangle(l)), EYE, radiance);
    eprintln!(
        "rectangle light: mean {:.3} % off the closed form",
        100.0 * error
    );
    assert!(error < MEAN_TOLERANCE / 2.0, "rectangle light: {error}");
    let brighter = floor_error(&floor_scene(&rectangle(l * 1.02)), EYE, radiance);
    assert!(
        brighter > MEAN_TOLERANCE,
        "a 2 % brighter rectangle went unnoticed: {brighter}"
    );
}

/// The fraction of a disk of radius `r` whose centre lies `d` to the right
/// of a straight edge that is on the edge's left.
fn disk_left_of(d: f64, r: f64) -> f64 {
    let s = (d / r).clamp(-1.0, 1.0);
    (s.acos() - s * (1.0 - s * s).sqrt()) / std::f64::consts::PI
}

/// The profile a box-filtered render of a dark half-plane left of `edge`
/// (pixels) blurred into disks of radius `r` (pixels) has at column `i`.
fn edge_profile(i: usize, edge: f64, r: f64) -> f64 {
    let n = 16;
    (0..n)
        .map(|k| 1.0 - disk_left_of(i as f64 + (k as f64 + 0.5) / n as f64 - edge, r))
        .sum::<f64>()
        / n as f64
}

/// Fits (edge, radius) to the column means `profile` by least squares
/// (coarse-to-fine search).
fn fit_edge(profile: &[f64]) -> (f64, f64) {
    let cost = |e: f64, r: f64| {
        profile
            .iter()
            .enumerate()
            .map(|(i, v)| (v - edge_profile(i, e, r)).powi(2))
            .sum::<f64>()
    };
    let (mut e, mut r, mut step) = (profile.len() as f64 / 2.0, 10.0, 4.0);
    while step > 1e-4 {
        let mut best = (cost(e, r), e, r);
        for de in [-1.0, 0.0, 1.0] {
            for dr in [-1.0, 0.0, 1.0] {
                let (e2, r2) = (e + de * step, (r + dr * step).max(0.5));
                let c = cost(e2, r2);
                if c < best.0 {
                    best = (c, e2, r2);
                }
            }
        }
        if (best.1, best.2) == (e, r) {
            step /= 2.0;
        }
        (e, r) = (best.1, best.2);
    }
    (e, r)
}

/// The fitted blur radius of the edge scene with `aperture`, relative to
/// the thin-lens prediction, minus 1.
fn blur_error(aperture: f64) -> f64 {
    let (width, height, fov, focus, depth) = (128u32, 48u32, 40.0f64, 2.0f64, 4.0f64);
    let text = format!(
        "integrator: {{type: path, max_depth: 2}}
film: {{width: {width}, height: {height}, filter: {{type: box}}}}
sampler: {{type: stratified, spp: 256}}
camera: {{type: thin_lens, fov: {fov}, fov_axis: x, aperture_radius: {aperture}, focus_distance: {focus}, look_at: {{origin: [0, 0, {depth}], target: [0, 0, 0], up: [0, 1, 0]}}}}
shapes:
  - {{type: rectangle, transform: [{{translate: [-10, 0, 0]}}, {{scale: 10}}], material: {{type: diffuse, reflectance: 0}}}}
lights:
  - {{type: environment, radiance: 1}}
"
    );
    let image = render(
        &extract_text(&text, &std::env::temp_dir()),
        &Progress::none(),
    )
    .image;
    let w = width as usize;
    let profile: Vec<f64> = (0..w)
        .map(|x| {
            (0..height as usize)
                .map(|y| f64::from(image.pixels[y * w + x].x))
                .sum::<f64>()
                / f64::from(height)
        })
        .collect();
    let (edge, radius) = fit_edge(&profile);
    // The bundle of a pixel focused at `focus` has radius
    // a·|depth − focus|/focus at `depth`, where a pixel spans
    // 2·depth·tan(fov/2)/width.
    let predicted = aperture * (depth - focus).abs()
        / focus
        / (2.0 * depth * (fov.to_radians() / 2.0).tan() / f64::from(width));
    eprintln!(
        "aperture {aperture}: edge at {edge:.2} px, blur radius {radius:.3} px, thin lens {predicted:.3} px"
    );
    radius / predicted - 1.0
}

#[test]
fn depth_of_field_blur_matches_the_thin_lens() {
    let error = blur_error(0.3);
    // Measured: 0.02 %; an aperture 1 % off would fail.
    assert!(
        error.abs() < 0.005,
        "blur radius {:.2} % off the thin lens",
        100.0 * error
    );
    for aperture in [0.3 * 0.98, 0.3 * 1.02] {
        let off = blur_error(aperture);
        // The scene still has the radius of aperture 0.3 in mind.
        let against_nominal = (1.0 + off) * aperture / 0.3 - 1.0;
        assert!(
            against_nominal.abs() > 0.012,
            "an aperture 2 % off went unnoticed ({against_nominal})"
        );
    }
}

/// An environment map with light in every direction: a smooth gradient,
/// a broad warm lobe above and a bright cool one below the horizon.
fn environment_map() -> Image {
    let (w, h) = (64u32, 32u32);
    let pixels = (0..w * h)
        .map(|i| {
            let (u, v) = (
                ((i % w) as f32 + 0.5) / w as f32,
                ((i / w) as f32 + 0.5) / h as f32,
            );
            let lobe = |cu: f32, cv: f32, s: f32| {
                let du = (u - cu).abs().min(1.0 - (u - cu).abs());
                (-(du * du + (v - cv).powi(2)) / s).exp()
            };
            let warm = 3.0 * lobe(0.3, 0.25, 0.02);
            let cool = 6.0 * lobe(0.7, 0.8, 0.01);
            radiant::core::Rgb::new(
                0.2 + 0.3 * u + warm + 0.3 * cool,
                0.2 + 0.2 * v + 0.6 * warm + 0.6 * cool,
                0.3 + 0.1 * warm + cool,
            )
        })
        .collect();
    Image {
        width: w,
        height: h,
        pixels,
    }
}

/// The mean, over the pixels wholly on a diffuse sphere, of the render of
/// that sphere lit by the map of [`environment_map`] scaled by `scale`,
/// relative to the quadrature of the unscaled map's `eval_escaped`, minus
/// 1.
fn environment_error(scale: f32) -> f64 {
    let dir = tempfile::tempdir().expect("a temporary directory");
    let map = dir.path().join("map.exr");
    radiant::film::output::write(&map, &environment_map()).expect("the map is written");
    let (albedo, eye) = (0.8f64, Vec3::new(0.0, -2.6, 1.8));
    let text = format!(
        "integrator: {{type: path, max_depth: 2}}
film: {{width: 64, height: 64, filter: {{type: box}}}}
sampler: {{type: independent, spp: 128}}
camera: {{type: perspective, fov: 40, look_at: {{origin: [{}, {}, {}], target: [0, 0, 0], up: [0, 0, 1]}}}}
shapes:
  - {{type: sphere, center: [0, 0, 0], radius: 1, material: {{type: diffuse, reflectance: {albedo}}}}}
lights:
  - {{type: environment, filename: map.exr, scale: {scale}, transform: [{{rotate: {{axis: [0, 1, 0], angle: 30}}}}]}}
",
        eye.x, eye.y, eye.z
    );
    let scene = extract_text(&text, dir.path());
    let image = render(&scene, &Progress::none()).image;
    // The unscaled light's radiance over a (θ, φ) grid of directions.
    let (nt, np) = (192usize, 384usize);
    let mut dirs = Vec::with_capacity(nt * np);
    let mut weights = Vec::with_capacity(nt * np);
    for i in 0..nt {
        let theta = (i as f32 + 0.5) / nt as f32 * PI;
        for j in 0..np {
            let phi = (j as f32 + 0.5) / np as f32 * 2.0 * PI;
            dirs.push(Vec3::new(
                theta.sin() * phi.cos(),
                theta.sin() * phi.sin(),
                theta.cos(),
            ));
            weights.push(f64::from(
                theta.sin() * PI / nt as f32 * 2.0 * PI / np as f32,
            ));
        }
    }
    let mut evals = vec![radiant::core::EmitterEval::default(); dirs.len()];
    scene.lights.lights()[0].eval_escaped(&dirs, &mut evals);
    let radiance: Vec<f64> = evals
        .iter()
        .zip(&weights)
        .map(|(e, w)| {
            f64::from(e.radiance.x + e.radiance.y + e.radiance.z) / 3.0 * w / f64::from(scale)
        })
        .collect();
    // Pixels whose 2×2 sub-pixel rays all hit the sphere, and the outgoing
    // radiance ρ/π·E(n) averaged over those rays.
    let rays = pixel_rays(&scene, eye, 2);
    let mut mask = Vec::new();
    let mut expected = 0.0;
    for c in rays.chunks(4) {
        let normals: Vec<Option<Vec3>> = c
            .iter()
            .map(|(o, d)| {
                let b = o.dot(*d);
                let disc = b * b - (o.length_squared() - 1.0);
                (disc > 0.0).then(|| (*o + *d * (-b - disc.sqrt())).normalize())
            })
            .collect();
        let inside = normals.iter().all(Option::is_some);
        mask.push(inside);
        if inside {
            for n in normals.into_iter().flatten() {
                let e: f64 = dirs
                    .iter()
                    .zip(&radiance)
                    .map(|(d, l)| l * f64::from(n.dot(*d).max(0.0)))
                    .sum();
                expected += albedo / std::f64::consts::PI * e / 4.0;
            }
        }
    }
    let pixels = mask.iter().filter(|m| **m).count();
    assert!(pixels > 1000, "only {pixels} pixels lie on the sphere");
    masked_mean(&image, &mask) / (expected / pixels as f64) - 1.0
}

#[test]
fn environment_lighting_matches_quadrature_over_the_whole_sphere() {
    let error = environment_error(1.0);
    eprintln!(
        "environment: mean {:.3} % off the quadrature",
        100.0 * error
    );
    assert!(error.abs() < MEAN_TOLERANCE / 2.0, "environment: {error}");
    let brighter = environment_error(1.02);
    assert!(
        brighter > MEAN_TOLERANCE,
        "a 2 % brighter map went unnoticed: {brighter}"
    );
}
