//! Chi-square tests of the camera lens and of filter importance sampling
//! against their own densities (the shaders' and lights' are in
//! `sampling.rs`).

// `unwrap` in this test code is the assertion: the inputs are the test's
// own, so a failure is a bug, and the panic reports it with the error.

use glam::{Mat4, Vec2, Vec3};
use radiant_cameras::{FovAxis, ThinLens};
use radiant_core::{Camera, CameraRays, Filter, FilterSampler};
use radiant_filters::{
    BlackmanHarrisKernel, BoxKernel, GaussianKernel, LanczosKernel, MitchellKernel, Separable,
    TentKernel,
};
use radiant_tests::chi2::{Chi2, Rng, SIGNIFICANCE};

#[test]
fn thin_lens_aperture_samples_match_the_uniform_disk_density() {
    // Lifting a point (x, y) of the unit disk to (x, y, √(1 − x² − y²))
    // turns the uniform density 1/π on the disk into cos θ/π on the
    // hemisphere, which the direction test checks on equal-area cells.
    let cfg = Chi2::default();
    for radius in [0.05f32, 1.0, 3.0] {
        let cam = ThinLens::new(
            Mat4::IDENTITY,
            Vec2::new(32.0, 32.0),
            40.0,
            FovAxis::X,
            radius,
            5.0,
        )
        .unwrap();
        assert!((cam.lens_pdf() - 1.0 / (std::f32::consts::PI * radius * radius)).abs() < 1e-4);
        let n = cfg.samples;
        let mut rng = Rng::new(3);
        let lens: Vec<Vec2> = (0..n).map(|_| rng.next_2d()).collect();
        let film = vec![Vec2::new(16.0, 16.0); n];
        let (mut o, mut d, mut w) = (vec![Vec3::ZERO; n], vec![Vec3::ZERO; n], vec![0.0; n]);
        cam.generate(
            &film,
            &lens,
            CameraRays {
                origins: &mut o,
                directions: &mut d,
                weights: &mut w,
            },
        );
        let lifted = o.iter().map(|p| {
            let q = p.truncate() / radius;
            Some(Vec3::new(q.x, q.y, (1.0 - q.length_squared()).max(0.0).sqrt()).normalize())
        });
        let pdf = |v: Vec3| (v.z.max(0.0) / std::f32::consts::PI) as f64;
        cfg.run(lifted, pdf)
            .unwrap_or_else(|e| panic!("aperture radius {radius}: {e}"));
    }
}

fn filters() -> Vec<(&'static str, Box<dyn Filter>)> {
    vec![
        ("box", Box::new(Separable(BoxKernel { radius: 0.5 }))),
        ("tent", Box::new(Separable(TentKernel { radius: 1.5 }))),
        (
            "gaussian",
            Box::new(Separable(GaussianKernel::new(0.5, 2.0))),
        ),
        (
            "mitchell",
            Box::new(Separable(MitchellKernel::new(1.0 / 3.0, 1.0 / 3.0, 2.0))),
        ),
        (
            "catmull-rom",
            Box::new(Separable(MitchellKernel::new(0.0, 0.5, 2.0))),
        ),
        ("lanczos", Box::new(Separable(LanczosKernel::new(3)))),
        (
            "blackman-harris",
            Box::new(Separable(BlackmanHarrisKernel { radius: 2.0 })),
        ),
    ]
}

/// ∫ f and ∫ |f| over the filter's support by the midpoint rule.
fn integrals(f: &dyn Filter) -> (f64, f64) {
    let r = f.radius() as f64;
    let n = 600;
    let h = 2.0 * r / n as f64;
    let (mut s, mut a) = (0.0, 0.0);
    for j in 0..n {
        for i in 0..n {
            let v = f.eval(
                (-r + (i as f64 + 0.5) * h) as f32,
                (-r + (j as f64 + 0.5) * h) as f32,
            ) as f64;
            s += v;
            a += v.abs();
        }
    }
    (s * h * h, a * h * h)
}

#[test]
fn filter_importance_sampling_matches_the_normalised_absolute_filter() {
    let cfg = Chi2 {
        theta_cells: 16,
        phi_cells: 16,
        refine: 16,
        samples: 400_000,
        significance: SIGNIFICANCE,
    };
    for (name, f) in filters() {
        let sampler = FilterSampler::new(&*f, FilterSampler::DEFAULT_RESOLUTION);
        let (signed, abs) = integrals(&*f);
        assert!(
            (sampler.abs_integral() as f64 / abs - 1.0).abs() < 2e-3,
            "{name}: tabulated ∫|f| {} vs {abs}",
            sampler.abs_integral()
        );
        let mut rng = Rng::new(17);
        let drawn: Vec<(Vec2, f32)> = (0..cfg.samples)
            .map(|_| sampler.sample(rng.next_2d()))
            .collect();
        let r = f.radius();
        cfg.run_planar(
            Vec2::splat(-r),
            Vec2::splat(r),
            drawn.iter().map(|(p, _)| Some(*p)),
            |p| f.eval(p.x, p.y).abs() as f64 / abs,
        )
        .unwrap_or_else(|e| panic!("{name}: {e}"));
        // The weights f/pdf estimate ∫ f, and carry the sign of f.
        let mean = drawn.iter().map(|(_, w)| *w as f64).sum::<f64>() / drawn.len() as f64;
        let sd = abs / (drawn.len() as f64).sqrt();
        assert!(
            (mean - signed).abs() < 5.0 * sd + 1e-3 * abs,
            "{name}: E[w] = {mean}, ∫f = {signed}"
        );
        let wrong_sign = drawn
            .iter()
            .filter(|(p, w)| f.eval(p.x, p.y) * w < 0.0)
            .count();
        assert!(
            wrong_sign * 100 < drawn.len(),
            "{name}: {wrong_sign} weights of the wrong sign"
        );
        // pdf() is |f| at the centre of the cell holding the offset over the
        // tabulated ∫|f| (the piecewise-constant density `sample` draws from).
        let res = FilterSampler::DEFAULT_RESOLUTION;
        let cell = 2.0 * r / res as f32;
        for (p, _) in drawn.iter().take(2000) {
            let centre = ((*p + Vec2::splat(r)) / cell)
                .floor()
                .min(Vec2::splat(res as f32 - 1.0))
                * cell
                + Vec2::splat(0.5 * cell - r);
            let expected = f.eval(centre.x, centre.y).abs() as f64 / sampler.abs_integral() as f64;
            let pdf = sampler.pdf(*p) as f64;
            assert!(
                pdf > 0.0 && (pdf / expected - 1.0).abs() < 1e-3,
                "{name}: pdf {pdf} at {p}, expected {expected}"
            );
        }
        // … and it integrates to one over the support (midpoint rule on a
        // grid finer than the table's cells).
        let n = 4 * res;
        let h = 2.0 * r / n as f32;
        let total: f64 = (0..n * n)
            .map(|i| {
                let p = Vec2::new((i % n) as f32 + 0.5, (i / n) as f32 + 0.5) * h - Vec2::splat(r);
                sampler.pdf(p) as f64
            })
            .sum::<f64>()
            * (h * h) as f64;
        assert!((total - 1.0).abs() < 1e-3, "{name}: ∫ pdf = {total}");
        assert_eq!(sampler.pdf(Vec2::splat(r * 1.01)), 0.0);
    }
}
