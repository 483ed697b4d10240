//! Lights: chi-square tests of every non-delta light's sampling against its
//! own density (environment maps over directions, spheres over solid angle
//! from near, far and grazing points), the piecewise-constant 2D
//! distribution they build on, and the environment map's lookup against
//! Mitsuba 3's `envmap` texel by texel.

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
    let map = read_exr(root().join("scenes/environment-sky.exr")).expect("sky map");
    EnvironmentLight::from_pixels(
        map.pixels,
        UVec2::new(map.width, map.height),
        rotation,
        SPHERE,
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
