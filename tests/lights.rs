//! Lights: chi-square tests of every non-delta light's sampling against its
//! own density (environment maps over directions, spheres over solid angle
//! from near, far and grazing points), the piecewise-constant 2D
//! distribution they build on, and the environment map's lookup against
//! Mitsuba 3's `envmap` texel by texel.

// `unwrap` in this test code is the assertion: the inputs are the test's
// own, so a failure is a bug, and the panic reports it with the error.

use glam::{Mat3, UVec2, Vec2, Vec3};
use radiant::film::output::read_exr;
use radiant_core::{BoundingSphere, EmitterEval, Light, LightSample, Rgb};
use radiant_lights::EnvironmentLight;
use radiant_tests::chi2::{Chi2, Rng};
use radiant_tests::root;

const SPHERE: BoundingSphere = BoundingSphere {
    centre: Vec3::ZERO,
    radius: 1.0,
};

fn sky(rotation: Mat3) -> EnvironmentLight {
    sky_around(rotation, SPHERE)
}

/// The sky map around a scene bounded by `sphere`.
fn sky_around(rotation: Mat3, sphere: BoundingSphere) -> EnvironmentLight {
    let map = read_exr(root().join("scenes/environment-sky.exr")).expect("sky map");
    EnvironmentLight::from_pixels(
        map.pixels,
        UVec2::new(map.width, map.height),
        rotation,
        sphere,
    )
    .expect("valid map")
}

fn eval(light: &dyn Light, d: Vec3) -> EmitterEval {
    let mut e = [EmitterEval::default()];
    light.eval_escaped(&[d], &mut e);
    e[0]
}

#[test]
fn environment_lookup_matches_mitsuba() {
    let text = std::fs::read_to_string(root().join("tests/data/environment-eval-mitsuba.txt"))
        .expect("reference values");
    let light = sky(Mat3::from_rotation_y(60f32.to_radians()));
    let mut worst = 0.0f32;
    for line in text.lines().filter(|l| !l.starts_with('#')) {
        let v: Vec<f32> = line
            .split_whitespace()
            .map(|x| x.parse().unwrap())
            .collect();
        let d = Vec3::new(v[0], v[1], v[2]);
        let expected = Rgb::new(v[3], v[4], v[5]);
        let got = eval(&light, d.normalize()).radiance;
        let err = ((got - expected).abs() / (expected.abs() + 1e-2)).max_element();
        if err > 1e-3 {
            eprintln!("{d}: {got} vs Mitsuba {expected}");
        }
        worst = worst.max(err);
    }
    assert!(worst < 1e-3, "worst relative difference {worst}");
}

/// Draws `n` light samples from `origin` and returns their directions
/// (`None` for failed samples) and the samples themselves.
fn sample_directions(light: &dyn Light, origin: Vec3, n: usize, seed: u64) -> Vec<LightSample> {
    let mut rng = Rng::new(seed);
    let u: Vec<Vec2> = (0..n).map(|_| rng.next_2d()).collect();
    let mut out = vec![LightSample::default(); n];
    light.sample(&vec![origin; n], &u, &mut out);
    out
}

fn check_environment(light: &dyn Light) -> Result<f64, String> {
    let cfg = Chi2 {
        refine: 32,
        ..Chi2::default()
    };
    let origin = Vec3::new(0.2, -0.3, 0.1);
    let out = sample_directions(light, origin, cfg.samples, 17);
    let samples = out
        .iter()
        .map(|s| (s.pdf > 0.0).then(|| (s.p - origin).normalize()));
    cfg.run(samples, |d| eval(light, d).pdf as f64)
}

#[test]
fn environment_map_sampling_matches_its_pdf() {
    let turned = Mat3::from_axis_angle(Vec3::new(1.0, 2.0, -0.5).normalize(), 1.1);
    for rotation in [Mat3::IDENTITY, turned] {
        let light = sky(rotation);
        check_environment(&light).unwrap();
    }
}

/// A 6 × 5 map with bright, uneven poles above black rows and a black
/// column: every cell at a pole has two black corners on its inner row,
/// and half the cells have a black side.
fn black_rings_under_the_poles() -> EnvironmentLight {
    let (w, h) = (6u32, 5u32);
    let pixels = (0..w * h)
        .map(|i| {
            let (x, y) = ((i % w) as f32, (i / w) as f32);
            if y == 1.0 || y == 3.0 || x == 2.0 {
                Rgb::ZERO
            } else {
                Rgb::new(1.0 + x, 0.5 + 0.3 * x * y, 2.0 - 0.2 * y)
            }
        })
        .collect();
    EnvironmentLight::from_pixels(pixels, UVec2::new(w, h), Mat3::IDENTITY, SPHERE).unwrap()
}

#[test]
fn a_map_is_sampled_wherever_its_radiance_is_not_zero() {
    let light = black_rings_under_the_poles();
    check_environment(&light).unwrap();
    // θ on a grid, finer near the poles, where the pole's radiance fades
    // out towards the black rows while the pole itself weighs nothing.
    let mut thetas: Vec<f32> = (0..200).map(|k| (k as f32 + 0.5) / 200.0).collect();
    thetas.extend([1e-4, 1e-3, 1e-2, 0.05].iter().flat_map(|&t| [t, 1.0 - t]));
    let mut lit = 0;
    for t in thetas {
        let (sin_t, cos_t) = (std::f32::consts::PI * t).sin_cos();
        for k in 0..400 {
            let phi = std::f32::consts::TAU * (k as f32 + 0.5) / 400.0;
            let d = Vec3::new(phi.sin() * sin_t, cos_t, -phi.cos() * sin_t);
            let e = eval(&light, d);
            if e.radiance.max_element() > 0.0 {
                lit += 1;
                assert!(
                    e.pdf > 0.0,
                    "{d} (θ = {t}π) has radiance {} but no density",
                    e.radiance
                );
            }
        }
    }
    assert!(lit > 40_000, "only {lit} directions are lit");
}

#[test]
fn constant_environment_sampling_matches_its_pdf() {
    let light = EnvironmentLight::constant(Rgb::new(1.0, 0.5, 0.25), SPHERE);
    check_environment(&light).unwrap();
}

#[test]
fn the_environment_test_rejects_a_wrong_pdf() {
    // The map's samples checked against the uniform density must fail.
    let light = sky(Mat3::IDENTITY);
    let cfg = Chi2::default();
    let out = sample_directions(&light, Vec3::ZERO, cfg.samples, 3);
    let samples = out.iter().map(|s| Some(s.p.normalize()));
    assert!(cfg.run(samples, |_| 0.25 / std::f64::consts::PI).is_err());
}

#[test]
fn environment_samples_agree_with_eval_and_lie_outside_the_scene() {
    let light = sky(Mat3::from_rotation_y(0.7));
    let origin = Vec3::new(0.5, 0.5, -0.5);
    let out = sample_directions(&light, origin, 20_000, 5);
    for s in &out {
        assert!(s.pdf > 0.0, "the map has no black pixels");
        assert_eq!(s.n, Vec3::ZERO);
        // pbrt's convention: p = reference + wi · 2r, outside the sphere.
        assert!(((s.p - origin).length() - 2.0 * SPHERE.radius).abs() < 1e-5);
        assert!(s.p.length() > SPHERE.radius);
        let e = eval(&light, (s.p - origin).normalize());
        let close = |a: f32, b: f32| (a - b).abs() <= 2e-3 * a.abs().max(b.abs()) + 1e-6;
        assert!(close(e.pdf, s.pdf), "pdf {} vs eval {}", s.pdf, e.pdf);
        for c in 0..3 {
            assert!(
                close(e.radiance[c], s.radiance[c]),
                "{} vs {}",
                s.radiance,
                e.radiance
            );
        }
    }
}

#[test]
fn environment_power_is_pi_r2_times_the_integral_of_luminance() {
    // A radius other than 1 and a centre off the origin, so that a missing
    // r² or a centre in the formula would show.
    let sphere = BoundingSphere {
        centre: Vec3::new(1.0, -2.0, 3.0),
        radius: 2.5,
    };
    let light = sky_around(Mat3::IDENTITY, sphere);
    let n = 400usize;
    let mut sum = 0.0f64;
    for i in 0..n {
        for j in 0..2 * n {
            // Midpoint rule over (cos θ, φ): equal solid angles.
            let z = 1.0 - 2.0 * (i as f64 + 0.5) / n as f64;
            let phi = std::f64::consts::PI * (j as f64 + 0.5) / n as f64;
            let r = (1.0 - z * z).sqrt();
            let d = Vec3::new((r * phi.cos()) as f32, z as f32, (r * phi.sin()) as f32);
            sum += radiant_core::luminance(eval(&light, d).radiance) as f64;
        }
    }
    let integral = sum * 4.0 * std::f64::consts::PI / (2 * n * n) as f64;
    let r = sphere.radius as f64;
    let expected = std::f64::consts::PI * r * r * integral;
    let power = light.power() as f64;
    assert!(
        (power / expected - 1.0).abs() < 0.02,
        "{power} vs {expected}"
    );
}

#[test]
fn distribution_2d_sampling_matches_its_pdf() {
    use radiant_core::distribution::Distribution2D;
    use std::f64::consts::{PI, TAU};
    // Uneven weights with empty cells and an empty row, on a 7 × 5 grid.
    let mut rng = Rng::new(11);
    let size = UVec2::new(7, 5);
    let weights: Vec<f32> = (0..35)
        .map(|i| {
            if i % 6 == 0 || (14..21).contains(&i) {
                0.0
            } else {
                rng.uniform() * 4.0
            }
        })
        .collect();
    let dist = Distribution2D::new(&weights, size);
    // Through the equal-area map (u, v) → (φ = 2πu, z = 1 − 2v), densities
    // on the square become densities on the sphere divided by 4π.
    let to_sphere = |p: Vec2| {
        let z = 1.0 - 2.0 * p.y;
        let r = (1.0 - z * z).max(0.0).sqrt();
        let (s, c) = (std::f32::consts::TAU * p.x).sin_cos();
        Vec3::new(r * c, r * s, z)
    };
    let pdf = |d: Vec3| {
        let mut phi = (d.y as f64).atan2(d.x as f64);
        if phi < 0.0 {
            phi += TAU;
        }
        let (u, v) = (phi / TAU, (1.0 - d.z as f64) / 2.0);
        let cell = UVec2::new(((u * 7.0) as u32).min(6), ((v * 5.0) as u32).min(4));
        dist.pdf(cell) as f64 / (4.0 * PI)
    };
    let cfg = Chi2 {
        refine: 16,
        ..Chi2::default()
    };
    let mut rng = Rng::new(12);
    let mut cells_ok = true;
    let samples: Vec<Option<Vec3>> = (0..cfg.samples)
        .map(|_| {
            let (p, cell) = dist.sample(rng.next_2d());
            cells_ok &= cell == UVec2::new((p.x * 7.0) as u32, (p.y * 5.0) as u32);
            Some(to_sphere(p))
        })
        .collect();
    assert!(cells_ok, "a sample's cell does not hold it");
    cfg.run(samples.iter().copied(), pdf).unwrap();
    // And the same samples fail against the uniform density.
    assert!(cfg.run(samples, |_| 0.25 / PI).is_err());
}
