//! Chi-square tests of every sampling routine against its own density:
//! BSDF sampling of the shaders, area-light sampling (triangles and
//! spheres), and the warps they are built on.

// `unwrap` in this test code is the assertion: the inputs are the test's
// own, so a failure is a bug, and the panic reports it with the error.

use glam::{Vec2, Vec3};
use radiant::accel::{Accel, BuildQuality, Primitive};
use radiant_core::warp::{UNIFORM_SPHERE_PDF, square_to_uniform_sphere};
use radiant_core::{
    BsdfEval, BsdfSample, EmitterEval, EmitterHit, EmitterShape, Light, LightSample, Rgb,
    ShadeContext, Shader, SurfaceBatch, TextureTable,
};
use radiant_tests::chi2::{Chi2, Rng};

fn diffuse(textures: &mut TextureTable) -> Box<dyn Shader> {
    let white = textures.add_constant(Rgb::ONE);
    Box::new(radiant_shaders::Diffuse::new(
        white,
        radiant_core::Effects::empty(),
    ))
}

#[test]
fn diffuse_sampling_matches_its_pdf_at_every_incidence() {
    let mut textures = TextureTable::default();
    let shader = diffuse(&mut textures);
    let cfg = Chi2::default();
    for cos_o in [1.0f32, 0.5, 1e-4] {
        let wo = Vec3::new((1.0 - cos_o * cos_o).sqrt(), 0.0, cos_o);
        let n = cfg.samples;
        let mut rng = Rng::new(1);
        let u: Vec<Vec3> = (0..n)
            .map(|_| Vec3::new(rng.uniform(), rng.uniform(), rng.uniform()))
            .collect();
        let wos = vec![wo; n];
        let uvs = vec![Vec2::ZERO; n];
        let mut out = vec![BsdfSample::default(); n];
        let mut ctx = ShadeContext::new(&textures);
        shader.sample(&mut ctx, SurfaceBatch::new(&wos, &uvs), &u, &mut out);
        let pdf = |wi: Vec3| {
            let mut e = [BsdfEval::default()];
            let mut ctx = ShadeContext::new(&textures);
            shader.eval(
                &mut ctx,
                SurfaceBatch::new(&[wo], &[Vec2::ZERO]),
                &[wi],
                &mut e,
            );
            e[0].pdf as f64
        };
        let samples = out.iter().map(|s| (s.pdf > 0.0).then_some(s.wi));
        cfg.run(samples, pdf)
            .unwrap_or_else(|e| panic!("cos θo = {cos_o}: {e}"));
    }
}

/// The index of `prim` in the emitter shape's own order (`prims`), as the
/// engine reports it in [`EmitterHit::primitive`] (the BVH reorders).
fn emitter_index(prims: &[Primitive], prim: Primitive) -> u32 {
    prims
        .iter()
        .position(|p| *p == prim)
        .expect("a primitive of the shape") as u32
}

/// The solid-angle density of `light` towards direction `d` from `origin`,
/// found by intersecting the light's own shape.
fn light_pdf(
    light: &dyn Light,
    shape: &Accel,
    shape_prims: &[Primitive],
    origin: Vec3,
    d: Vec3,
) -> f64 {
    let Some(hit) = shape.intersect(origin, d, f32::INFINITY) else {
        return 0.0;
    };
    let p = origin + d * hit.t;
    let hit_prim = *shape.primitive(&hit, 0.0).0;
    let n = match hit_prim {
        Primitive::Triangle(v) => (v[1] - v[0]).cross(v[2] - v[0]).normalize(),
        Primitive::Sphere(c, _) => (p - c).normalize(),
    };
    let mut e = [EmitterEval::default()];
    light.eval_hits(
        &[EmitterHit {
            origin,
            p,
            n,
            primitive: emitter_index(shape_prims, hit_prim),
        }],
        &mut e,
    );
    e[0].pdf as f64
}

/// Stretches polar angles about `axis` by `k` (θ → kθ), so that a small
/// cone of directions covers many cells of the chi-square grid.
#[derive(Clone, Copy)]
struct Magnify {
    frame: radiant_core::Frame,
    k: f32,
}

impl Magnify {
    fn new(axis: Vec3, k: f32) -> Self {
        Self {
            frame: radiant_core::Frame::from_normal(axis),
            k,
        }
    }

    fn forward(&self, d: Vec3) -> Vec3 {
        let l = self.frame.to_local(d);
        // atan2 rather than acos: precise for the small angles magnified.
        let theta = l.truncate().length().atan2(l.z) * self.k;
        let phi = l.y.atan2(l.x);
        self.frame.to_world(Vec3::new(
            theta.sin() * phi.cos(),
            theta.sin() * phi.sin(),
            theta.cos(),
        ))
    }

    /// The original direction of `d` and the factor dω / dω' on densities.
    fn inverse(&self, d: Vec3) -> Option<(Vec3, f64)> {
        let l = self.frame.to_local(d);
        let theta_m = l.truncate().length().atan2(l.z);
        let theta = theta_m / self.k;
        if !(1e-7..std::f32::consts::PI * 0.999).contains(&theta_m) {
            return None;
        }
        let phi = l.y.atan2(l.x);
        let orig = self.frame.to_world(Vec3::new(
            theta.sin() * phi.cos(),
            theta.sin() * phi.sin(),
            theta.cos(),
        ));
        let jac = theta.sin() as f64 / (self.k as f64 * theta_m.sin() as f64);
        Some((orig, jac))
    }
}

fn check_light(shape: EmitterShape, origin: Vec3, refine: usize) {
    check_light_magnified(shape, origin, refine, None);
}

fn check_light_magnified(
    shape: EmitterShape,
    origin: Vec3,
    refine: usize,
    magnify: Option<Magnify>,
) {
    let light = radiant_lights::AreaLight::new(Rgb::ONE, shape.clone()).unwrap();
    let mut prims: Vec<Primitive> = shape
        .triangles
        .iter()
        .map(|t| Primitive::Triangle(*t))
        .collect();
    prims.extend(shape.spheres.iter().map(|&(c, r)| Primitive::Sphere(c, r)));
    let (accel, _) = Accel::build(&prims, BuildQuality::Medium);
    let cfg = Chi2 {
        samples: 100_000,
        refine,
        ..Chi2::default()
    };
    let mut rng = Rng::new(9);
    let u: Vec<Vec2> = (0..cfg.samples).map(|_| rng.next_2d()).collect();
    let mut out = vec![LightSample::default(); cfg.samples];
    light.sample(&vec![origin; cfg.samples], &u, &mut out);
    // A sample is a direction; its density must be the light's own pdf. A
    // point hidden behind another part of the same shape (or seen from the
    // back) is a failed sample, since it emits nothing towards `origin`.
    let samples = out.iter().map(|s| {
        (s.pdf > 0.0)
            .then(|| (s.p - origin).normalize())
            .filter(|d| {
                accel
                    .intersect(origin, *d, f32::INFINITY)
                    .is_some_and(|h| (origin + *d * h.t - s.p).length() < 1e-3 * h.t.max(1.0))
            })
            .and_then(|d| match magnify {
                None => Some(d),
                // Keep the sample only if the magnified direction maps back
                // onto the shape (directions at the silhouette may not).
                Some(m) => {
                    let f = m.forward(d);
                    m.inverse(f)
                        .is_some_and(|(o, _)| accel.intersect(origin, o, f32::INFINITY).is_some())
                        .then_some(f)
                }
            })
    });
    cfg.run(samples, |d| match magnify {
        None => light_pdf(&light, &accel, &prims, origin, d),
        Some(m) => m.inverse(d).map_or(0.0, |(orig, jac)| {
            light_pdf(&light, &accel, &prims, origin, orig) * jac
        }),
    })
    .unwrap();
}

#[test]
fn area_light_sampling_matches_its_pdf_on_triangles() {
    // A tilted quad of two unequal triangles, seen from below at an angle.
    let shape = EmitterShape {
        triangles: vec![
            [
                Vec3::new(-1.0, -0.5, 1.0),
                Vec3::new(1.5, -0.5, 1.4),
                Vec3::new(1.5, 0.7, 1.4),
            ],
            [
                Vec3::new(-1.0, -0.5, 1.0),
                Vec3::new(1.5, 0.7, 1.4),
                Vec3::new(-1.0, 0.3, 1.0),
            ],
        ]
        .into_iter()
        .map(|[a, b, c]| [a, c, b]) // face the origin (normal towards -z)
        .collect(),
        spheres: vec![],
    };
    check_light(shape, Vec3::new(0.2, -0.3, -0.4), 32);
}

#[test]
fn area_light_sampling_matches_its_pdf_on_spheres() {
    // Close to the sphere, so it covers many cells. The density diverges at
    // the silhouette (cos → 0), so the expected counts need a fine grid.
    let shape = EmitterShape {
        triangles: vec![],
        spheres: vec![(Vec3::new(0.1, 0.2, 1.3), 1.0)],
    };
    check_light(shape, Vec3::ZERO, 64);
}

#[test]
fn sphere_light_solid_angle_sampling_from_just_outside() {
    let (centre, r) = (Vec3::new(0.1, 0.2, 1.3), 1.0);
    let sphere = || EmitterShape {
        triangles: vec![],
        spheres: vec![(centre, r)],
    };
    // Just outside the surface: the cone is almost a hemisphere.
    let near = centre + Vec3::new(0.3, -0.5, -0.8).normalize() * (r * 1.01);
    check_light(sphere(), near, 64);
}

#[test]
fn sphere_light_solid_angle_sampling_from_far_away() {
    let (centre, r) = (Vec3::new(0.1, 0.2, 1.3), 1.0);
    let sphere = || EmitterShape {
        triangles: vec![],
        spheres: vec![(centre, r)],
    };
    // 20 radii away (sin²θmax = 1/400) and 300 radii away (the Taylor
    // branch below 1.5°): the cones are magnified to cover the grid.
    for dist in [20.0f32, 300.0] {
        let axis = Vec3::new(-0.2, 0.3, 1.0).normalize();
        let origin = centre - axis * dist;
        let theta_max = (r / dist).asin();
        let k = 0.8 * std::f32::consts::PI / theta_max;
        check_light_magnified(sphere(), origin, 32, Some(Magnify::new(axis, k)));
    }
}

#[test]
fn triangle_light_sampling_at_grazing_angles() {
    // The reference point is 0.1 above the plane of a large triangle, so
    // most of the light is seen at grazing angles (cos θ at the light down
    // to 0.02); the density is steep near the horizon, hence the fine
    // integration grid.
    let shape = EmitterShape {
        triangles: vec![[
            Vec3::new(-2.0, 0.0, -2.0),
            Vec3::new(3.0, 0.0, -2.0),
            Vec3::new(-2.0, 0.0, 3.0),
        ]],
        spheres: vec![],
    };
    // Normal (b − a) × (c − a) points to −y; look from below.
    check_light(shape, Vec3::new(0.0, -0.1, 0.0), 128);
}

/// The rectangle x ∈ [−0.5, 0.7], y ∈ [−0.4, 0.3] at z = 1, facing −z, as
/// the `rectangle` shape tessellates it (two triangles sharing a diagonal).
fn rectangle_light() -> EmitterShape {
    let (a, b, c, d) = (
        Vec3::new(-0.5, -0.4, 1.0),
        Vec3::new(0.7, -0.4, 1.0),
        Vec3::new(0.7, 0.3, 1.0),
        Vec3::new(-0.5, 0.3, 1.0),
    );
    // Winding (a, c, b) faces −z, towards the reference points below.
    EmitterShape {
        triangles: vec![[a, c, b], [a, d, c]],
        spheres: vec![],
    }
}

#[test]
fn rectangle_light_solid_angle_sampling_matches_its_pdf() {
    // Close below (large solid angle), off to the side (a skewed spherical
    // rectangle), and at grazing angles (down to 6° below the plane); all
    // within the distance where the light samples by solid angle.
    for origin in [
        Vec3::new(0.1, 0.0, 0.7),
        Vec3::new(1.0, -0.8, 0.4),
        Vec3::new(-1.0, 0.2, 0.85),
    ] {
        eprintln!("rectangle light from {origin}");
        check_light(rectangle_light(), origin, 64);
    }
}

#[test]
fn rectangle_light_sampling_from_far_away() {
    // 8 and 100 units away (area sampling; the rectangle subtends 0.013
    // and 8e-5 sr), magnified to cover the grid.
    for dist in [8.0f32, 100.0] {
        let centre = Vec3::new(0.1, -0.05, 1.0);
        let axis = Vec3::new(0.3, -0.2, 1.0).normalize();
        let origin = centre - axis * dist;
        let theta_max = (0.75 / dist).atan();
        let k = 0.8 * std::f32::consts::PI / theta_max;
        check_light_magnified(rectangle_light(), origin, 32, Some(Magnify::new(axis, k)));
    }
}

#[test]
fn uniform_sphere_warp_matches_its_pdf() {
    let cfg = Chi2::default();
    let mut rng = Rng::new(3);
    let samples = (0..cfg.samples).map(|_| Some(square_to_uniform_sphere(rng.next_2d())));
    cfg.run(samples, |_| UNIFORM_SPHERE_PDF as f64).unwrap();
}

#[test]
fn the_test_rejects_a_wrong_pdf() {
    // A cosine-weighted sampler checked against a uniform hemisphere pdf
    // must fail: the test has power.
    let mut textures = TextureTable::default();
    let shader = diffuse(&mut textures);
    let cfg = Chi2::default();
    let n = cfg.samples;
    let mut rng = Rng::new(5);
    let u: Vec<Vec3> = (0..n)
        .map(|_| Vec3::new(rng.uniform(), rng.uniform(), rng.uniform()))
        .collect();
    let mut out = vec![BsdfSample::default(); n];
    let mut ctx = ShadeContext::new(&textures);
    shader.sample(
        &mut ctx,
        SurfaceBatch::new(&vec![Vec3::Z; n], &vec![Vec2::ZERO; n]),
        &u,
        &mut out,
    );
    let uniform = |d: Vec3| {
        if d.z > 0.0 {
            1.0 / std::f64::consts::TAU
        } else {
            0.0
        }
    };
    assert!(cfg.run(out.iter().map(|s| Some(s.wi)), uniform).is_err());
}
