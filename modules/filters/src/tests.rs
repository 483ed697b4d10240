//! Properties every filter must have: its integral is the closed form of
//! its formula, it is symmetric, and bad parameters are rejected with
//! their location.

use super::*;

use radiant_core::{BuildContext, Filter, Params, TextureTable};
use std::collections::HashMap;
use std::f64::consts::PI;

/// Si(x) = ∫₀ˣ sin t / t dt by its power series (fine for |x| < 20).
fn si(x: f64) -> f64 {
    let (mut term, mut sum) = (x, 0.0);
    for n in 0..60 {
        let k = (2 * n + 1) as f64;
        sum += term / k;
        term *= -x * x / ((k + 1.0) * (k + 2.0));
    }
    sum
}

/// ∫ sinc(x) sinc(x/a) over [−a, a], in closed form through Si.
fn lanczos_integral(a: f64) -> f64 {
    let (alpha, beta) = (PI * (1.0 - 1.0 / a), PI * (1.0 + 1.0 / a));
    a / (PI * PI) * (beta * si(beta * a) - alpha * si(alpha * a))
}

/// ∫ of the truncated Gaussian over [−r, r].
fn gaussian_integral(stddev: f64, r: f64) -> f64 {
    let erf = statrs::function::erf::erf(r / (stddev * 2f64.sqrt()));
    stddev * (2.0 * PI).sqrt() * erf - 2.0 * r * (-r * r / (2.0 * stddev * stddev)).exp()
}

/// Every filter under test, with the closed form of its 1D integral.
fn filters() -> Vec<(&'static str, Box<dyn Filter>, f64)> {
    vec![
        (
            "box 0.5",
            Box::new(Separable(BoxKernel { radius: 0.5 })),
            1.0,
        ),
        (
            "box 1.5",
            Box::new(Separable(BoxKernel { radius: 1.5 })),
            3.0,
        ),
        (
            "tent 1",
            Box::new(Separable(TentKernel { radius: 1.0 })),
            1.0,
        ),
        (
            "tent 2.5",
            Box::new(Separable(TentKernel { radius: 2.5 })),
            2.5,
        ),
        (
            "gaussian 0.5",
            Box::new(Separable(GaussianKernel::new(0.5, 2.0))),
            gaussian_integral(0.5, 2.0),
        ),
        (
            "gaussian 0.7 r 1",
            Box::new(Separable(GaussianKernel::new(0.7, 1.0))),
            gaussian_integral(0.7, 1.0),
        ),
        (
            "mitchell 1/3",
            Box::new(Separable(MitchellKernel::new(1.0 / 3.0, 1.0 / 3.0, 2.0))),
            1.0,
        ),
        (
            "catmull-rom r 3",
            Box::new(Separable(MitchellKernel::new(0.0, 0.5, 3.0))),
            1.5,
        ),
        (
            "lanczos 1",
            Box::new(Separable(LanczosKernel::new(1))),
            lanczos_integral(1.0),
        ),
        (
            "lanczos 3",
            Box::new(Separable(LanczosKernel::new(3))),
            lanczos_integral(3.0),
        ),
        (
            "blackman-harris 2",
            Box::new(Separable(BlackmanHarrisKernel { radius: 2.0 })),
            4.0 * BLACKMAN_HARRIS[0] as f64,
        ),
    ]
}

#[test]
fn closed_forms_are_right() {
    // Si(π) = 1.851937051982466 (Abramowitz & Stegun 5.2); the Lanczos-1
    // kernel is sinc², whose integral over [−1, 1] is 2 Si(2π)/π.
    assert!((si(PI) - 1.851_937_051_982_466).abs() < 1e-12);
    assert!((lanczos_integral(1.0) - 2.0 * si(2.0 * PI) / PI).abs() < 1e-12);
    // Wider windows approach ∫ sinc = 1 from below.
    assert!(lanczos_integral(1.0) < lanczos_integral(3.0));
    assert!((lanczos_integral(3.0) - 1.0).abs() < 0.02);
    assert!((gaussian_integral(0.5, 100.0) - 0.5 * (2.0 * PI).sqrt()).abs() < 1e-12);
}

#[test]
fn each_filter_integrates_to_its_closed_form() {
    for (name, f, integral_1d) in filters() {
        let r = f.radius() as f64;
        let n = 800;
        let h = 2.0 * r / n as f64;
        let mut sum = 0.0f64;
        for j in 0..n {
            let y = -r + (j as f64 + 0.5) * h;
            for i in 0..n {
                let x = -r + (i as f64 + 0.5) * h;
                sum += f.eval(x as f32, y as f32) as f64;
            }
        }
        let numeric = sum * h * h;
        let expected = integral_1d * integral_1d;
        assert!(
            (numeric / expected - 1.0).abs() < 2e-4,
            "{name}: ∫f = {numeric}, closed form {expected}"
        );
    }
}

#[test]
fn each_filter_is_symmetric_and_zero_outside_its_radius() {
    for (name, f, _) in filters() {
        let r = f.radius();
        for i in 0..200 {
            let x = r * ((i * 37 % 200) as f32 / 100.0 - 1.0);
            let y = r * ((i * 91 % 200) as f32 / 100.0 - 1.0);
            let v = f.eval(x, y);
            assert!(v.is_finite(), "{name} at ({x}, {y})");
            for w in [f.eval(-x, y), f.eval(x, -y), f.eval(-x, -y), f.eval(y, x)] {
                assert!(
                    (v - w).abs() <= 1e-6 * v.abs().max(1.0),
                    "{name}: {v} vs {w}"
                );
            }
        }
        for p in [(r * 1.01, 0.0), (0.0, -r * 1.5), (r * 2.0, r * 2.0)] {
            assert_eq!(f.eval(p.0, p.1), 0.0, "{name} outside at {p:?}");
        }
    }
}

/// Builds filter `ty` through the registry from the YAML parameters `yaml`.
fn build(ty: &str, yaml: &str) -> Result<Box<dyn Filter>, radiant_core::registry::BuildError> {
    let mut registry = radiant_core::Registry::new();
    register(&mut registry);
    let mut textures = TextureTable::default();
    let named = HashMap::new();
    let mut ctx = BuildContext::standalone(std::path::Path::new("."), &mut textures, &named);
    let params = Params::from_yaml(yaml).expect("test YAML parses");
    registry.build::<dyn Filter>(ty, &params, &mut ctx)
}

#[test]
fn registered_filters_build_with_defaults() {
    for (ty, radius) in [
        ("box", 0.5),
        ("gaussian", 2.0),
        ("tent", 1.0),
        ("mitchell", 2.0),
        ("lanczos", 3.0),
        ("blackman_harris", 2.0),
    ] {
        let f = build(ty, "{}").unwrap_or_else(|e| panic!("{ty}: {e}"));
        assert_eq!(f.radius(), radius, "{ty}");
    }
}

#[test]
fn bad_parameters_are_rejected_at_their_key() {
    for (ty, yaml, line, needle) in [
        ("tent", "radius: 0", 1, "from 0.5 to 32 pixels"),
        (
            "blackman_harris",
            "\nradius: -2",
            2,
            "from 0.5 to 32 pixels",
        ),
        ("box", "radius: 1e12", 1, "from 0.5 to 32 pixels"),
        (
            "box",
            "radius: 1e-30",
            1,
            "samples between pixel centres are lost",
        ),
        ("gaussian", "stddev: 1e-30", 1, "from 0.5 to 32 pixels"),
        (
            "gaussian",
            "stddev: 0.01\nradius: 10",
            2,
            "at most 16 × `stddev`",
        ),
        ("gaussian", "stddev: 0", 1, "positive"),
        ("mitchell", "B: 1e40", 1, "from 0 to 1"),
        ("mitchell", "\nC: -6", 2, "from 0 to 1"),
        ("mitchell", "radius: 1e39", 1, "from 0.5 to 32 pixels"),
        ("mitchell", "radius: wide", 1, "number"),
        ("lanczos", "lobes: 0", 1, "1 to 16"),
        ("lanczos", "lobes: 2.5", 1, "whole number"),
        ("tent", "width: 2", 1, "width"),
    ] {
        let Err(radiant_core::registry::BuildError::Params(e)) = build(ty, yaml) else {
            panic!("{yaml:?} should be rejected");
        };
        assert!(e.message.contains(needle), "{yaml:?}: {}", e.message);
        assert_eq!(e.location.map(|l| l.line), Some(line), "{yaml:?}: {e:?}");
    }
}
