//! Energy and consistency of every shader:
//!
//! * white furnace: E[weight] = 1 within noise for the non-absorbing
//!   shaders (smooth conductor of reflectance 1, smooth dielectric counting
//!   refracted energy, thin dielectric) at many incidence angles, and never
//!   above 1 for the lossy ones;
//! * each non-delta sample's weight and density equal `eval`'s value/pdf;
//! * delta lobes are chosen with their Fresnel probability, in the exact
//!   mirror and Snell directions;
//! * reciprocity f(wo, wi) = f(wi, wo), and its generalised form across a
//!   refracting interface, f(wo, wi)·η(wi)² = f(wi, wo)·η(wo)²;
//! * no NaN or infinity for any input, including tangent and below-horizon
//!   directions and sample values 0 and 1;
//! * bad parameters are reported with their line and column.

use glam::Vec3;
use radiant_core::Rgb;
use radiant_tests::chi2::Rng;
use radiant_tests::shading::{ALL, TestShader, build, direction, shader};

const SAMPLES: usize = 200_000;

/// Mean and standard error of the sampled weights at `wo`; refracted
/// samples are multiplied by `refraction_gain` (η_t²/η_i² undoes radiance
/// scaling, for counting energy).
fn furnace(s: &TestShader, wo: Vec3, refraction_gain: f32, seed: u64) -> (Rgb, Rgb) {
    let mut rng = Rng::new(seed);
    let u: Vec<Vec3> = (0..SAMPLES)
        .map(|_| Vec3::new(rng.uniform(), rng.uniform(), rng.uniform()))
        .collect();
    let (mut sum, mut sq) = (Rgb::ZERO.as_dvec3(), Rgb::ZERO.as_dvec3());
    for b in s.sample(wo, &u) {
        if b.pdf <= 0.0 {
            continue;
        }
        let gain = if b.wi.z * wo.z < 0.0 {
            refraction_gain
        } else {
            1.0
        };
        let w = (b.weight * gain).as_dvec3();
        sum += w;
        sq += w * w;
    }
    let n = SAMPLES as f64;
    let mean = sum / n;
    let var = (sq / n - mean * mean).max(glam::DVec3::ZERO);
    (mean.as_vec3(), (var / n).as_vec3().map(f32::sqrt))
}

const ANGLES: &[f32] = &[1.0, 0.9, 0.7, 0.5, 0.3, 0.1, 0.02, 1e-3];

#[test]
fn energy_conserving_shaders_return_all_light() {
    let eta = 1.5f32;
    let cases: &[(&str, bool)] = &[
        ("{type: conductor}", false),
        ("{type: thin_dielectric, int_ior: 1.5, ext_ior: 1}", false),
        ("{type: dielectric, int_ior: 1.5, ext_ior: 1}", true),
    ];
    for &(yaml, refracts) in cases {
        let s = shader(yaml);
        for (k, &c) in ANGLES.iter().enumerate() {
            for side in [1.0f32, -1.0] {
                if !refracts && yaml.contains("conductor") && side < 0.0 {
                    continue;
                }
                let wo = direction(c * side, 0.3);
                let gain = match (refracts, side > 0.0) {
                    (false, _) => 1.0,
                    (true, true) => eta * eta,
                    (true, false) => 1.0 / (eta * eta),
                };
                let (mean, err) = furnace(&s, wo, gain, k as u64);
                let tol = 5.0 * err.max_element() + 1e-4;
                assert!(
                    (mean - Rgb::ONE).abs().max_element() < tol,
                    "{yaml} at cos θo = {}: furnace {mean} ± {err}",
                    wo.z
                );
            }
        }
    }
}

/// Lossy shaders, white where they have a colour: never above 1.
const LOSSY: &[&str] = &[
    "{type: diffuse, reflectance: 1}",
    "{type: rough_diffuse, reflectance: 1, alpha: 0.2}",
    "{type: rough_diffuse, reflectance: 1, alpha: 1}",
    "{type: conductor, alpha: 0.05}",
    "{type: conductor, alpha: 1}",
    "{type: conductor, alpha_u: 0.5, alpha_v: 0.025}",
    "{type: dielectric, int_ior: 1.5, ext_ior: 1, alpha: 0.3}",
    "{type: dielectric, int_ior: 3, ext_ior: 1, alpha: 1}",
    "{type: plastic, diffuse_reflectance: 1}",
    "{type: plastic, diffuse_reflectance: 1, nonlinear: true}",
    "{type: plastic, diffuse_reflectance: 1, alpha: 0.3}",
    "{type: plastic, diffuse_reflectance: 1, alpha: 1, int_ior: 2.5}",
    "{type: principled, base_color: 1, roughness: 0.5}",
    "{type: principled, base_color: 1, roughness: 0.1, specular: 1}",
    "{type: principled, base_color: 1, metallic: 1, roughness: 0.3}",
    "{type: principled, base_color: 1, transmission: 1, roughness: 0.5}",
    "{type: principled, base_color: 1, metallic: 0.4, transmission: 0.5, roughness: 1, specular: 1}",
    "{type: ashikhmin_shirley, diffuse_reflectance: 1, specular_reflectance: 0.05}",
    "{type: ashikhmin_shirley, diffuse_reflectance: 1, specular_reflectance: 1, exponent_u: 1, exponent_v: 1}",
    "{type: ashikhmin_shirley, diffuse_reflectance: 1, specular_reflectance: 0.3, exponent_u: 10, exponent_v: 1000}",
    "{type: ward, diffuse_reflectance: 0, specular_reflectance: 1, alpha_u: 1, alpha_v: 1}",
    "{type: ward, diffuse_reflectance: 0.5, specular_reflectance: 0.5, alpha_u: 0.4, alpha_v: 0.02}",
    "{type: blend, weight: 0.4, materials: [{type: diffuse, reflectance: 1}, {type: conductor, alpha: 0.3}]}",
    "{type: normal_map, normals: tilt, material: {type: diffuse, reflectance: 1}}",
    "{type: bump, height: ramp, material: {type: conductor, alpha: 0.2}}",
];

/// Oren–Nayar is not energy conserving: a white surface returns up to
/// 2.6 % more than it receives near grazing incidence (measured here;
/// a property of the model, shared by Mitsuba's and pbrt's versions).
const OREN_NAYAR_EXCESS: f32 = 0.03;

#[test]
fn lossy_shaders_never_exceed_one() {
    let mut worst_oren_nayar = 0.0f32;
    for yaml in LOSSY {
        let bound = if yaml.contains("rough_diffuse") {
            1.0 + OREN_NAYAR_EXCESS
        } else {
            1.0
        };
        let s = shader(yaml);
        let two_sided = yaml.contains("dielectric") || yaml.contains("transmission");
        for (k, &c) in ANGLES.iter().enumerate() {
            for side in [1.0f32, -1.0] {
                if side < 0.0 && !two_sided {
                    continue;
                }
                let wo = direction(c * side, 0.3);
                // Energy across a refracting interface is counted in flux.
                let eta: f32 = if yaml.contains("int_ior: 3") {
                    3.0
                } else if yaml.contains("principled") {
                    1.5
                } else {
                    1.5 / 1.000277
                };
                let gain = if side > 0.0 {
                    eta * eta
                } else {
                    1.0 / (eta * eta)
                };
                let (mean, err) = furnace(&s, wo, gain, 100 + k as u64);
                if yaml.contains("rough_diffuse") {
                    worst_oren_nayar = worst_oren_nayar.max(mean.max_element());
                }
                assert!(
                    mean.max_element() < bound + 5.0 * err.max_element() + 1e-3,
                    "{yaml} at cos θo = {}: furnace {mean} ± {err}",
                    wo.z
                );
            }
        }
    }
    eprintln!("Oren–Nayar furnace peaks at {worst_oren_nayar}");
}

/// Relative tolerance of a sample's density and weight against `eval`'s
/// at density `pdf` for the directions `wo`, `wi`: single-precision
/// rounding, which near-delta lobes amplify in proportion to their density
/// (half vectors of nearly equal directions cancel) and grazing directions
/// amplify further. Measured: below 1e-4 for densities under 1e3, 6e-4 at
/// 1e6 (α = 0.001), 5e-3 at 1.4e7 (refraction at η = 1.0001), 7e-3 with
/// both directions within 1° of the horizon. Refraction at η = 1.0001
/// (`index_matched`) cancels in every half vector: up to 5e-3. A 0.2 %
/// error of an ordinary lobe (density below 1e5, away from the horizon)
/// fails.
fn density_tolerance(pdf: f32, wo: Vec3, wi: Vec3, index_matched: bool) -> f32 {
    if index_matched || wo.z.abs().min(wi.z.abs()) < 0.02 {
        3e-2
    } else {
        1e-3 + 1e-9 * pdf
    }
}

#[test]
fn sample_weights_and_densities_agree_with_eval() {
    for yaml in ALL.iter().chain(LOSSY) {
        let s = shader(yaml);
        let mut rng = Rng::new(7);
        let (mut worst_pdf, mut worst_weight) = (0.0f32, 0.0f32);
        // Four fixed incidences and four random ones (both sides).
        let random: Vec<(f32, f32)> = (0..4)
            .map(|_| {
                (
                    2.0 * rng.uniform() - 1.0,
                    std::f32::consts::TAU * rng.uniform(),
                )
            })
            .collect();
        for &(c, phi) in [(0.9f32, 1.1f32), (0.4, 1.1), (0.05, 1.1), (-0.6, 1.1)]
            .iter()
            .chain(&random)
        {
            let wo = direction(c, phi);
            let u: Vec<Vec3> = (0..2000)
                .map(|_| Vec3::new(rng.uniform(), rng.uniform(), rng.uniform()))
                .collect();
            for b in s.sample(wo, &u) {
                if b.pdf <= 0.0 || b.delta {
                    continue;
                }
                let e = s.eval(wo, b.wi);
                let rel = (e.pdf - b.pdf).abs() / b.pdf;
                worst_pdf = worst_pdf.max(rel);
                assert!(
                    rel < density_tolerance(b.pdf, wo, b.wi, yaml.contains("1.0001")),
                    "{yaml}: pdf {} vs eval {} at wo {wo} wi {}",
                    b.pdf,
                    e.pdf,
                    b.wi
                );
                let w = e.value / e.pdf;
                let err = (w - b.weight).abs().max_element() / b.weight.max_element().max(1e-3);
                worst_weight = worst_weight.max(err);
                assert!(
                    err < density_tolerance(b.pdf, wo, b.wi, yaml.contains("1.0001")),
                    "{yaml}: weight {} vs eval/pdf {w} at wo {wo} wi {}",
                    b.weight,
                    b.wi
                );
            }
        }
        eprintln!("{yaml}: worst density {worst_pdf:.1e}, weight {worst_weight:.1e}");
    }
}

#[test]
fn delta_lobes_follow_fresnel() {
    // Smooth glass from outside at cos θ = 0.5, η = 1.5: Fresnel 0.0892.
    let s = shader("{type: dielectric, int_ior: 1.5, ext_ior: 1}");
    let wo = direction(0.5, 0.4);
    let mut rng = Rng::new(11);
    let u: Vec<Vec3> = (0..SAMPLES)
        .map(|_| Vec3::new(rng.uniform(), rng.uniform(), rng.uniform()))
        .collect();
    let f = 0.089_186_7f64;
    let mut reflected = 0usize;
    for b in s.sample(wo, &u) {
        assert!(b.delta);
        if b.wi.z > 0.0 {
            reflected += 1;
            assert!((b.wi - Vec3::new(-wo.x, -wo.y, wo.z)).length() < 1e-6);
            assert!((b.pdf as f64 - f).abs() < 1e-4);
        } else {
            // Snell: sin θt = sin θo / η, opposite azimuth.
            let sin_t = (1.0 - b.wi.z * b.wi.z).sqrt();
            assert!((sin_t * 1.5 - (1.0 - 0.25f32).sqrt()).abs() < 1e-5);
            assert!((b.wi.x * wo.x + b.wi.y * wo.y) < 0.0);
            assert!((b.weight.x - 1.0 / 2.25).abs() < 1e-5, "radiance scaling");
        }
    }
    let frac = reflected as f64 / SAMPLES as f64;
    let sigma = (f * (1.0 - f) / SAMPLES as f64).sqrt();
    assert!(
        (frac - f).abs() < 5.0 * sigma,
        "reflected {frac} vs Fresnel {f}"
    );
    // From inside beyond the critical angle: total internal reflection.
    let inside = direction(-0.5, 0.4);
    for b in s.sample(inside, &u[..1000]) {
        assert!(b.wi.z < 0.0 && b.pdf == 1.0);
    }
    // Smooth shaders have nothing for next-event estimation to evaluate.
    for yaml in [
        "{type: dielectric}",
        "{type: conductor}",
        "{type: thin_dielectric}",
    ] {
        let e = shader(yaml).eval(direction(0.5, 0.0), direction(0.5, std::f32::consts::PI));
        assert_eq!(e.value, Rgb::ZERO, "{yaml}");
    }
}

/// Unpolarised Fresnel reflectance of a dielectric interface at incidence
/// cosine `cos_i` > 0 with relative index `eta` (written out here, apart
/// from the shaders' own implementation).
fn fresnel_dielectric(cos_i: f64, eta: f64) -> f64 {
    let sin2_t = (1.0 - cos_i * cos_i) / (eta * eta);
    if sin2_t >= 1.0 {
        return 1.0;
    }
    let cos_t = (1.0 - sin2_t).sqrt();
    let rs = (cos_i - eta * cos_t) / (cos_i + eta * cos_t);
    let rp = (eta * cos_i - cos_t) / (eta * cos_i + cos_t);
    0.5 * (rs * rs + rp * rp)
}

/// Unpolarised Fresnel reflectance of a conductor with complex index
/// `eta + i k` at incidence cosine `cos_i` (complex arithmetic written out).
fn fresnel_conductor(cos_i: f64, eta: f64, k: f64) -> f64 {
    type C = (f64, f64);
    let mul = |a: C, b: C| (a.0 * b.0 - a.1 * b.1, a.0 * b.1 + a.1 * b.0);
    let div = |a: C, b: C| {
        let d = b.0 * b.0 + b.1 * b.1;
        ((a.0 * b.0 + a.1 * b.1) / d, (a.1 * b.0 - a.0 * b.1) / d)
    };
    let sqrt = |a: C| {
        let r = (a.0 * a.0 + a.1 * a.1).sqrt();
        let re = ((r + a.0) * 0.5).sqrt();
        let im = ((r - a.0) * 0.5).sqrt().copysign(a.1);
        (re, im)
    };
    let n: C = (eta, k);
    let sin2_t = div(((1.0 - cos_i * cos_i), 0.0), mul(n, n));
    let cos_t = sqrt((1.0 - sin2_t.0, -sin2_t.1));
    let n_cos_i = (n.0 * cos_i, n.1 * cos_i);
    let n_cos_t = mul(n, cos_t);
    let r_parallel = div(
        (n_cos_i.0 - cos_t.0, n_cos_i.1 - cos_t.1),
        (n_cos_i.0 + cos_t.0, n_cos_i.1 + cos_t.1),
    );
    let r_perpendicular = div(
        (cos_i - n_cos_t.0, -n_cos_t.1),
        (cos_i + n_cos_t.0, n_cos_t.1),
    );
    let norm2 = |a: C| a.0 * a.0 + a.1 * a.1;
    0.5 * (norm2(r_parallel) + norm2(r_perpendicular))
}

#[test]
fn the_reference_fresnel_formulas_match_known_values() {
    // Glass at normal incidence: ((1.5 − 1)/(1.5 + 1))² = 0.04; at cos 0.5
    // the value `delta_lobes_follow_fresnel` uses.
    assert!((fresnel_dielectric(1.0, 1.5) - 0.04).abs() < 1e-12);
    assert!((fresnel_dielectric(0.5, 1.5) - 0.089_186_7).abs() < 1e-7);
    // A conductor at normal incidence: ((n − 1)² + k²)/((n + 1)² + k²).
    let (n, k) = (0.2, 3.0);
    let normal = ((n - 1.0f64).powi(2) + k * k) / ((n + 1.0f64).powi(2) + k * k);
    assert!((fresnel_conductor(1.0, n, k) - normal).abs() < 1e-12);
    // With k = 0 it is the dielectric formula.
    assert!((fresnel_conductor(0.3, 1.5, 0.0) - fresnel_dielectric(0.3, 1.5)).abs() < 1e-12);
}

/// The fraction of `samples` that reflect (wi.z > 0), as (fraction, 5σ
/// bound) for an expected probability `p`.
fn reflected_fraction(samples: &[radiant_core::BsdfSample], p: f64) -> (f64, f64) {
    let reflected = samples.iter().filter(|b| b.wi.z > 0.0).count();
    let n = samples.len() as f64;
    (
        reflected as f64 / n,
        5.0 * (p * (1.0 - p) / n).sqrt() + 1e-12,
    )
}

#[test]
fn delta_lobes_split_as_fresnel_says_at_every_angle() {
    let mut rng = Rng::new(17);
    let u: Vec<Vec3> = (0..SAMPLES)
        .map(|_| Vec3::new(rng.uniform(), rng.uniform(), rng.uniform()))
        .collect();
    let glass = shader("{type: dielectric, int_ior: 1.5, ext_ior: 1}");
    let thin = shader("{type: thin_dielectric, int_ior: 1.5, ext_ior: 1}");
    for cos in [0.05f32, 0.2, 0.5, 0.8, 0.99] {
        let wo = direction(cos, 1.1);
        let f = fresnel_dielectric(cos as f64, 1.5);
        let samples = glass.sample(wo, &u);
        let (frac, bound) = reflected_fraction(&samples, f);
        assert!(
            (frac - f).abs() < bound,
            "glass at cos {cos}: {frac} vs {f}"
        );
        for b in samples.iter().filter(|b| b.wi.z > 0.0) {
            assert!(
                (b.pdf as f64 - f).abs() < 1e-5,
                "glass at cos {cos}: {} vs {f}",
                b.pdf
            );
        }

        // A thin slab sums its internal reflections: R = F + (1−F)²F/(1−F²).
        let slab = f + (1.0 - f) * (1.0 - f) * f / (1.0 - f * f);
        let samples = thin.sample(wo, &u);
        let (frac, bound) = reflected_fraction(&samples, slab);
        assert!(
            (frac - slab).abs() < bound,
            "thin at cos {cos}: {frac} vs {slab}"
        );
        for b in &samples {
            assert!(b.delta);
            if b.wi.z > 0.0 {
                assert!((b.wi - Vec3::new(-wo.x, -wo.y, wo.z)).length() < 1e-5);
                assert!((b.pdf as f64 - slab).abs() < 1e-5, "{}", b.pdf);
            } else {
                assert!(
                    (b.wi + wo).length() < 1e-6,
                    "a thin slab passes light straight"
                );
                assert!((b.pdf as f64 - (1.0 - slab)).abs() < 1e-5, "{}", b.pdf);
            }
            assert!(
                (b.weight - Rgb::ONE).abs().max_element() < 1e-5,
                "{}",
                b.weight
            );
        }
    }
}

#[test]
fn smooth_conductors_reflect_the_fresnel_fraction() {
    let u = [Vec3::splat(0.5)];
    for (eta, k) in [(0.2f32, 3.0f32), (1.5, 0.5), (0.05, 4.0)] {
        let s = shader(&format!("{{type: conductor, eta: {eta}, k: {k}}}"));
        for cos in [0.05f32, 0.3, 0.7, 1.0] {
            let wo = direction(cos, 0.3);
            let b = s.sample(wo, &u)[0];
            let f = fresnel_conductor(cos as f64, eta as f64, k as f64);
            assert!(b.delta);
            assert!((b.wi - Vec3::new(-wo.x, -wo.y, wo.z)).length() < 1e-5);
            assert!(
                (b.weight - Rgb::splat(f as f32)).abs().max_element() < 1e-4,
                "eta {eta}, k {k}, cos {cos}: weight {} vs Fresnel {f}",
                b.weight
            );
        }
    }
    // Named metals give per-channel weights below 1 and not all equal.
    let b = shader("{type: conductor, material: Au}").sample(direction(0.7, 0.0), &u)[0];
    assert!(
        b.weight.max_element() < 1.0 && b.weight.x > b.weight.z,
        "{}",
        b.weight
    );
}

#[test]
fn reciprocity() {
    let reflective = [
        "{type: diffuse}",
        "{type: rough_diffuse, alpha: 0.7}",
        "{type: conductor, material: Au, alpha: 0.3}",
        "{type: conductor, alpha_u: 0.5, alpha_v: 0.05}",
        "{type: dielectric, alpha: 0.4}",
        "{type: plastic, alpha: 0.3}",
        "{type: plastic}",
        "{type: principled, metallic: 0.3, roughness: 0.4}",
        "{type: principled, transmission: 0.6, roughness: 0.4}",
        "{type: ashikhmin_shirley, exponent_u: 20, exponent_v: 400}",
        "{type: ward, alpha_u: 0.3, alpha_v: 0.1}",
        "{type: blend, materials: [{type: diffuse}, {type: conductor, alpha: 0.2}]}",
    ];
    let mut rng = Rng::new(13);
    for yaml in reflective {
        let s = shader(yaml);
        for _ in 0..500 {
            let a = direction(rng.uniform().max(1e-3), rng.uniform() * 6.3);
            let b = direction(rng.uniform().max(1e-3), rng.uniform() * 6.3);
            let f_ab = s.eval(a, b).value / b.z;
            let f_ba = s.eval(b, a).value / a.z;
            let scale = f_ab.max_element().max(f_ba.max_element()).max(1e-6);
            assert!(
                (f_ab - f_ba).abs().max_element() / scale < 2e-3,
                "{yaml}: f({a}, {b}) = {f_ab}, f({b}, {a}) = {f_ba}"
            );
        }
    }
    // Across a refracting interface, radiance transport is reciprocal up
    // to the squared indices of the two sides.
    for (yaml, eta) in [
        (
            "{type: dielectric, int_ior: 1.5, ext_ior: 1, alpha: 0.3}",
            1.5f32,
        ),
        (
            "{type: dielectric, int_ior: 3, ext_ior: 1, alpha: 0.8}",
            3.0,
        ),
    ] {
        let s = shader(yaml);
        let n2 = |d: Vec3| if d.z > 0.0 { 1.0 } else { eta * eta };
        for _ in 0..500 {
            let a = direction(rng.uniform().max(1e-2), rng.uniform() * 6.3);
            let b = direction(-rng.uniform().max(1e-2), rng.uniform() * 6.3);
            let f_ab = s.eval(a, b).value.x / b.z.abs() * n2(b);
            let f_ba = s.eval(b, a).value.x / a.z.abs() * n2(a);
            // Refraction near grazing cancels in f32: an absolute floor.
            let scale = f_ab.max(f_ba);
            assert!(
                (f_ab - f_ba).abs() < 2e-3 * scale + 2e-5,
                "{yaml}: {a} ↔ {b}: {f_ab} vs {f_ba}"
            );
        }
    }
}

#[test]
fn no_nan_or_infinity_for_any_input() {
    let dirs = [
        Vec3::Z,
        -Vec3::Z,
        Vec3::X,
        Vec3::new(0.6, 0.8, 0.0),
        direction(1e-4, 0.3),
        direction(-1e-4, 2.0),
        direction(0.5, 1.0),
        direction(-0.7, 4.0),
        direction(1.0 - 1e-7, 0.1),
    ];
    let us = [
        Vec3::ZERO,
        Vec3::splat(1.0 - f32::EPSILON),
        Vec3::new(0.5, 0.0, 1.0 - f32::EPSILON),
        Vec3::new(1.0 - f32::EPSILON, 0.5, 0.0),
        Vec3::splat(0.5),
    ];
    for yaml in ALL {
        let s = shader(yaml);
        for &wo in &dirs {
            for b in s.sample(wo, &us) {
                assert!(
                    b.wi.is_finite() && b.weight.is_finite() && b.pdf.is_finite(),
                    "{yaml}: sample at wo {wo}: {b:?}"
                );
                assert!(
                    b.pdf >= 0.0 && b.weight.min_element() >= 0.0,
                    "{yaml}: {b:?}"
                );
                if b.pdf > 0.0 {
                    assert!((b.wi.length() - 1.0).abs() < 1e-3, "{yaml}: {b:?}");
                }
            }
            for &wi in &dirs {
                let e = s.eval(wo, wi);
                assert!(
                    e.value.is_finite() && e.pdf.is_finite() && e.pdf >= 0.0,
                    "{yaml}: eval({wo}, {wi}) = {e:?}"
                );
                assert!(
                    e.value.min_element() >= 0.0,
                    "{yaml}: eval({wo}, {wi}) = {e:?}"
                );
            }
        }
    }
}

#[test]
fn bad_parameters_are_located_errors() {
    let cases = [
        ("{type: conductor, material: Unobtainium}", "unknown metal"),
        (
            "{type: conductor, material: Au, eta: 1}",
            "either `material`",
        ),
        ("{type: conductor, eta: 1}", "both `eta` and `k`"),
        (
            "{type: conductor, alpha: 0.1, alpha_u: 0.2, alpha_v: 0.1}",
            "either `alpha`",
        ),
        (
            "{type: conductor, alpha_u: 0.2}",
            "both `alpha_u` and `alpha_v`",
        ),
        ("{type: conductor, alpha: 2}", "[0, 1]"),
        ("{type: dielectric, int_ior: 0.5}", "≥ 1"),
        (
            "{type: dielectric, int_ior: glas}",
            "unknown material `glas`",
        ),
        ("{type: plastic, alpha: -1}", "[0, 1]"),
        ("{type: plastic, alpha: rough}", "number"),
        ("{type: principled, metallic: 1.5}", "[0, 1]"),
        ("{type: principled, roughnes: 0.5}", "roughnes"),
        (
            "{type: ward, diffuse_reflectance: 0.8, specular_reflectance: 0.5}",
            "exceed 1",
        ),
        ("{type: blend, materials: [{type: diffuse}]}", "exactly two"),
        ("{type: blend, weight: 0.5}", "materials"),
        (
            "{type: blend, materials: [{type: diffuse}, {type: difuse}]}",
            "unknown shader type",
        ),
        ("{type: normal_map, material: {type: diffuse}}", "normals"),
        ("{type: bump, height: ramp}", "material"),
        (
            "{type: bump, height: nowhere, material: {type: diffuse}}",
            "undefined texture",
        ),
    ];
    for (yaml, expect) in cases {
        match build(yaml) {
            Ok(_) => panic!("{yaml} was accepted"),
            Err(e) => {
                assert!(e.message.contains(expect), "{yaml}: {}", e.message);
                // Errors point into the YAML (line 1), except for nested
                // materials, whose location is that of the inner mapping.
                assert!(
                    e.location.is_some() || yaml.contains("difuse"),
                    "{yaml}: no location in {e:?}"
                );
            }
        }
    }
}
