//! Chi-square tests of every sampling routine against its own density:
//! BSDF sampling of the shaders, area-light sampling (triangles and
//! spheres), and the warps they are built on.

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
        shader.sample(&mut ctx, SurfaceBatch { wo: &wos, uv: &uvs }, &u, &mut out);
        let pdf = |wi: Vec3| {
            let mut e = [BsdfEval::default()];
            let mut ctx = ShadeContext::new(&textures);
            shader.eval(
                &mut ctx,
                SurfaceBatch {
                    wo: &[wo],
                    uv: &[Vec2::ZERO],
                },
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

/// The solid-angle density of `light` towards direction `d` from `origin`,
/// found by intersecting the light's own shape.
fn light_pdf(light: &dyn Light, shape: &Accel, origin: Vec3, d: Vec3) -> f64 {
    let Some(hit) = shape.intersect(origin, d, f32::INFINITY) else {
        return 0.0;
    };
    let p = origin + d * hit.t;
    let n = match shape.primitives()[hit.prim as usize] {
        Primitive::Triangle(v) => (v[1] - v[0]).cross(v[2] - v[0]).normalize(),
        Primitive::Sphere(c, _) => (p - c).normalize(),
    };
    let mut e = [EmitterEval::default()];
    light.eval_hits(
        &[EmitterHit {
            origin,
            p,
            n,
            primitive: 0,
        }],
        &mut e,
    );
    e[0].pdf as f64
}

fn check_light(shape: EmitterShape, origin: Vec3, refine: usize) {
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
                    .is_some_and(|h| (origin + *d * h.t - s.p).length() < 1e-3)
            })
    });
    cfg.run(samples, |d| light_pdf(&light, &accel, origin, d))
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
        SurfaceBatch {
            wo: &vec![Vec3::Z; n],
            uv: &vec![Vec2::ZERO; n],
        },
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
