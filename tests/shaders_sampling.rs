//! Chi-square goodness-of-fit of every shader's `sample` against its own
//! `pdf` (the density `eval` reports), over a grid of directions, for the
//! hard parameters: roughness 1e-3 and 1, indices of refraction 1.0001 and
//! 3, grazing incidence (cos θ = 1e-4), anisotropy 0.95 (α_v = 0.05 α_u),
//! outgoing directions on both sides of two-sided shaders.
//!
//! Glossy lobes are tested on a zoomed sphere
//! (`radiant_tests::shading::Zoom`) centred on the lobe, at a scale ε of
//! about α², so that the grid resolves them (down to α = 1e-3); refraction
//! and reflection lobes are then tested separately, each restricted to its
//! side (the other side's samples count as failures). Delta samples are
//! excluded the same way, so the non-delta density must integrate to the
//! fraction of non-delta samples.

use glam::Vec3;
use radiant_tests::chi2::{Chi2, Rng};
use radiant_tests::shading::{Zoom, direction, shader};

/// Where to zoom, if anywhere.
#[derive(Clone, Copy)]
enum Focus {
    /// The whole sphere.
    Sphere,
    /// The side of wo, zoomed on its mirror direction at scale ε (no zoom
    /// for ε = 0).
    Mirror(f64),
    /// The other side, zoomed on the refracted direction of wo for
    /// relative index η at scale ε (no zoom for ε = 0).
    Refracted(f32, f64),
}

fn refracted(wo: Vec3, eta: f32) -> Vec3 {
    let e = if wo.z > 0.0 { 1.0 / eta } else { eta };
    let cos2 = 1.0 - (1.0 - wo.z * wo.z) * e * e;
    let z = cos2.max(0.0).sqrt() * -wo.z.signum();
    Vec3::new(-e * wo.x, -e * wo.y, z).normalize()
}

fn check(yaml: &str, cosines: &[f32], focus: Focus) {
    let s = shader(yaml);
    let cfg = Chi2 {
        refine: 16,
        ..Chi2::default()
    };
    for (k, &cos) in cosines.iter().enumerate() {
        let wo = direction(cos, 0.7);
        let mut rng = Rng::new(17 + k as u64);
        let u: Vec<Vec3> = (0..cfg.samples)
            .map(|_| Vec3::new(rng.uniform(), rng.uniform(), rng.uniform()))
            .collect();
        let samples = s.sample(wo, &u);
        let side = match focus {
            Focus::Sphere => 0.0,
            Focus::Mirror(_) => 1.0,
            Focus::Refracted(..) => -1.0,
        };
        let on_side = |wi: Vec3| side == 0.0 || wi.z * wo.z * side > 0.0;
        let pdf = |wi: Vec3| {
            if on_side(wi) {
                s.eval(wo, wi).pdf as f64
            } else {
                0.0
            }
        };
        let ok = |b: &radiant_core::BsdfSample| b.pdf > 0.0 && !b.delta && on_side(b.wi);
        let result = match focus {
            Focus::Sphere | Focus::Mirror(0.0) | Focus::Refracted(_, 0.0) => {
                cfg.run(samples.iter().map(|b| ok(b).then_some(b.wi)), pdf)
            }
            Focus::Mirror(eps) | Focus::Refracted(_, eps) => {
                let centre = match focus {
                    Focus::Refracted(eta, _) => refracted(wo, eta),
                    _ => Vec3::new(-wo.x, -wo.y, wo.z),
                };
                let zoom = Zoom::new(centre, eps);
                cfg.run(
                    samples.iter().map(|b| ok(b).then(|| zoom.forward(b.wi))),
                    |z| zoom.pdf(z, pdf),
                )
            }
        };
        if let Err(e) = result {
            panic!("{yaml} at cos θo = {cos}: {e}");
        }
    }
}

/// Incidence for broad lobes: normal, oblique, grazing.
const FRONT: &[f32] = &[1.0, 0.5, 1e-4];
/// The same from both sides, with total internal reflection at −0.3.
const BOTH: &[f32] = &[1.0, 0.5, 1e-4, -0.3, -0.9];
/// Incidence for zoomed lobes: away from the horizon, whose image under
/// the zoom would cut grid cells and defeat the midpoint quadrature.
const ZOOMED: &[f32] = &[1.0, 0.5];
/// The same from both sides.
const ZOOMED_BOTH: &[f32] = &[1.0, 0.5, -0.9];

/// Checks both lobes of a two-sided shader, zoomed at scale ε.
fn check_interface(yaml: &str, cosines: &[f32], eta: f32, eps: f64) {
    check(yaml, cosines, Focus::Mirror(eps));
    check(yaml, cosines, Focus::Refracted(eta, eps));
}

#[test]
fn rough_diffuse() {
    check("{type: rough_diffuse, alpha: 0.3}", FRONT, Focus::Sphere);
    check(
        "{type: rough_diffuse, alpha: 1, reflectance: 0.9}",
        FRONT,
        Focus::Sphere,
    );
}

#[test]
fn rough_conductor() {
    check(
        "{type: conductor, material: Au, alpha: 0.1}",
        ZOOMED,
        Focus::Mirror(2e-3),
    );
    check(
        "{type: conductor, material: Au, alpha: 0.4}",
        FRONT,
        Focus::Sphere,
    );
    check(
        "{type: conductor, material: Au, alpha: 1}",
        FRONT,
        Focus::Sphere,
    );
    // Anisotropy 0.95: α_v = 0.05 α_u.
    check(
        "{type: conductor, material: Cu, alpha_u: 0.4, alpha_v: 0.02}",
        ZOOMED,
        Focus::Mirror(1e-3),
    );
    check(
        "{type: conductor, alpha_u: 0.02, alpha_v: 0.4}",
        ZOOMED,
        Focus::Mirror(1e-3),
    );
    check(
        "{type: conductor, material: Ag, alpha: 0.001}",
        ZOOMED,
        Focus::Mirror(1e-7),
    );
}

#[test]
fn rough_dielectric() {
    let bk7 = 1.5046 / 1.000277;
    check_interface("{type: dielectric, alpha: 0.1}", ZOOMED_BOTH, bk7, 2e-3);
    check_interface("{type: dielectric, alpha: 0.5}", BOTH, bk7, 0.0);
    check_interface("{type: dielectric, alpha: 1}", BOTH, bk7, 0.0);
    check_interface(
        "{type: dielectric, int_ior: 3, ext_ior: 1, alpha: 0.5}",
        BOTH,
        3.0,
        0.0,
    );
    check_interface(
        "{type: dielectric, int_ior: 3, ext_ior: 1, alpha: 0.1}",
        ZOOMED_BOTH,
        3.0,
        2e-3,
    );
    // Index 1.0001 is not chi-square tested: refraction hardly bends, so the
    // refracted lobe is α·(η − 1) ≈ 3e-5 rad wide, below what the
    // half-vector of `eval` resolves in f32, and the reflection lobe holds
    // F ≈ 1e-9 of the samples at every angle — too few for any grid cell
    // (the harness now fails rather than passing with no cell to judge, as
    // it used to). The furnace and finite-value tests cover it.
    check_interface(
        "{type: dielectric, int_ior: 1.5, ext_ior: 1, alpha_u: 0.5, alpha_v: 0.025}",
        ZOOMED_BOTH,
        1.5,
        1e-3,
    );
    check_interface(
        "{type: dielectric, int_ior: 1.5, ext_ior: 1, alpha: 0.001}",
        ZOOMED_BOTH,
        1.5,
        1e-7,
    );
}

#[test]
fn plastic() {
    // Smooth plastic's diffuse part is weighted by 1 − F: at cos θo = 1e-4
    // nearly every sample takes the delta lobe, too few are left for the
    // grid, so the most grazing angle tested is 0.05.
    check("{type: plastic}", &[1.0, 0.5, 0.05], Focus::Sphere);
    check(
        "{type: plastic, alpha: 0.1, diffuse_reflectance: 0.2}",
        FRONT,
        Focus::Mirror(2e-3),
    );
    check(
        "{type: plastic, alpha: 1, int_ior: 3}",
        FRONT,
        Focus::Sphere,
    );
    check(
        "{type: plastic, alpha: 0.001, diffuse_reflectance: 0.01}",
        ZOOMED,
        Focus::Mirror(1e-7),
    );
}

#[test]
fn principled() {
    check("{type: principled}", FRONT, Focus::Mirror(0.05));
    check(
        "{type: principled, metallic: 1, roughness: 1}",
        FRONT,
        Focus::Sphere,
    );
    check(
        "{type: principled, metallic: 0.5, roughness: 0.2, specular: 1}",
        FRONT,
        Focus::Mirror(1e-3),
    );
    check_interface(
        "{type: principled, transmission: 1, roughness: 0.4}",
        BOTH,
        1.5,
        0.01,
    );
    check_interface(
        "{type: principled, transmission: 0.5, metallic: 0.2, roughness: 0.7, base_color: [0.9, 0.2, 0.4]}",
        BOTH,
        1.5,
        0.05,
    );
    // Roughness 0.0316: α = 1e-3.
    check(
        "{type: principled, metallic: 1, roughness: 0.0316}",
        ZOOMED,
        Focus::Mirror(1e-7),
    );
}

#[test]
fn ashikhmin_shirley_and_ward() {
    check("{type: ashikhmin_shirley}", ZOOMED, Focus::Mirror(5e-3));
    check(
        "{type: ashikhmin_shirley, exponent_u: 10, exponent_v: 1000, specular_reflectance: 0.5}",
        &[1.0],
        Focus::Mirror(5e-4),
    );
    check(
        "{type: ashikhmin_shirley, exponent_u: 1, exponent_v: 1}",
        FRONT,
        Focus::Sphere,
    );
    check("{type: ward}", ZOOMED, Focus::Mirror(2e-3));
    check(
        "{type: ward, alpha_u: 0.4, alpha_v: 0.02, specular_reflectance: 0.5}",
        ZOOMED,
        Focus::Mirror(1e-3),
    );
    check(
        "{type: ward, alpha_u: 1, alpha_v: 1, diffuse_reflectance: 0.1}",
        FRONT,
        Focus::Sphere,
    );
}

#[test]
fn wrappers() {
    check(
        "{type: blend, weight: 0.3, materials: [{type: diffuse}, {type: conductor, alpha: 0.1}]}",
        ZOOMED,
        Focus::Mirror(2e-3),
    );
    check(
        "{type: blend, weight: 0.3, materials: [{type: diffuse}, {type: conductor, alpha: 0.5}]}",
        FRONT,
        Focus::Sphere,
    );
    // A delta part: its samples are excluded, the rest must still match.
    check_interface(
        "{type: blend, weight: 0.6, materials: [{type: conductor}, {type: dielectric, alpha: 0.3}]}",
        ZOOMED_BOTH,
        1.5046 / 1.000277,
        2e-3,
    );
    // The perturbed horizon is a tilted great circle that cuts grid cells;
    // a nested density that vanishes there (Oren–Nayar) keeps the midpoint
    // quadrature exact enough at every angle, a glossy one at normal
    // incidence.
    check(
        "{type: normal_map, normals: tilt, material: {type: rough_diffuse, alpha: 0.5}}",
        FRONT,
        Focus::Sphere,
    );
    check(
        "{type: normal_map, normals: tilt, material: {type: conductor, alpha: 0.2}}",
        &[1.0],
        Focus::Sphere,
    );
    check(
        "{type: bump, height: ramp, scale: 0.5, material: {type: plastic, alpha: 0.1}}",
        FRONT,
        Focus::Sphere,
    );
}

#[test]
fn the_zoomed_test_rejects_a_slightly_wrong_roughness() {
    // Samples of α = 0.001 checked against the density of α = 0.0012
    // must fail: the zoom gives the test power at this scale.
    let sampled = shader("{type: conductor, alpha: 0.001}");
    let claimed = shader("{type: conductor, alpha: 0.0012}");
    let cfg = Chi2::default();
    let wo = direction(0.5, 0.7);
    let mut rng = Rng::new(3);
    let u: Vec<Vec3> = (0..cfg.samples)
        .map(|_| Vec3::new(rng.uniform(), rng.uniform(), rng.uniform()))
        .collect();
    let zoom = Zoom::new(Vec3::new(-wo.x, -wo.y, wo.z), 1e-7);
    let samples = sampled.sample(wo, &u);
    let result = cfg.run(
        samples
            .iter()
            .map(|b| (b.pdf > 0.0).then(|| zoom.forward(b.wi))),
        |z| zoom.pdf(z, |wi| claimed.eval(wo, wi).pdf as f64),
    );
    assert!(result.is_err(), "a 20 % roughness error went unnoticed");
}
