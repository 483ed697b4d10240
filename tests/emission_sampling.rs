//! The module contract's sampling routines for light paths: chi-square
//! tests of every light type's emitted rays (origins per unit area,
//! directions per unit solid angle) against the densities the light
//! itself reports (`EmissionSample`, `Emission::emission_pdf`), and of the
//! perspective cameras' importance side (`Importance::sample_wi` against
//! its solid-angle density, `Camera::generate` against
//! `Importance::pdf_ray`), with the identities the integrator relies on
//! (We cos θ / (pdf_pos pdf_dir) = the camera ray's weight of 1, a lens
//! connection lands where `generate` would start the same ray). Each
//! family has a test that a wrong density is rejected.

// `unwrap` in this test code is the assertion: the inputs are the test's
// own, so a failure is a bug, and the panic reports it with the error.

use glam::{Mat3, Mat4, UVec2, Vec2, Vec3};
use radiant::film::output::read_exr;
use radiant_cameras::{FovAxis, Orthographic, Perspective, ThinLens};
use radiant_core::{
    BoundingSphere, Camera, CameraRayPdf, CameraRays, EmissionKind, EmissionPdf, EmissionSample,
    EmittedRay, EmitterShape, Frame, LensSample, Light, Rgb,
};
use radiant_lights::{AreaLight, DirectionalLight, EnvironmentLight, PointLight, SpotLight};
use radiant_tests::chi2::{Chi2, Rng};
use radiant_tests::root;

const SPHERE: BoundingSphere = BoundingSphere {
    centre: Vec3::new(0.3, -0.2, 0.1),
    radius: 1.5,
};

/// `n` emitted rays of `light` from seeded uniform samples.
fn emit(light: &dyn Light, n: usize, seed: u64) -> Vec<EmissionSample> {
    let mut rng = Rng::new(seed);
    let u_pos: Vec<Vec2> = (0..n).map(|_| rng.next_2d()).collect();
    let u_dir: Vec<Vec2> = (0..n).map(|_| rng.next_2d()).collect();
    let mut out = vec![EmissionSample::default(); n];
    light
        .emission()
        .expect("every built-in light emits rays")
        .sample_emission(&u_pos, &u_dir, &mut out);
    out
}

/// The densities `light` reports for the emitted ray (`p`, `n`, `dir`).
fn densities(light: &dyn Light, p: Vec3, n: Vec3, dir: Vec3) -> EmissionPdf {
    let mut out = [EmissionPdf::default()];
    let ray = EmittedRay {
        p,
        n,
        dir,
        primitive: 0,
    };
    light.emission().unwrap().emission_pdf(&[ray], &mut out);
    out[0]
}

/// A unit square at z = 0 facing +z, as `rectangle` shapes tessellate.
fn square() -> EmitterShape {
    EmitterShape {
        triangles: vec![
            [Vec3::ZERO, Vec3::X, Vec3::new(1.0, 1.0, 0.0)],
            [Vec3::ZERO, Vec3::new(1.0, 1.0, 0.0), Vec3::Y],
        ],
        spheres: vec![],
    }
}

#[test]
fn area_light_origins_are_uniform_over_the_surface() {
    // A square (two triangles) and a lone triangle: origins uniform by
    // area over both, density 1 / total area.
    let mut shape = square();
    shape.triangles.push([
        Vec3::new(2.0, 0.0, 0.0),
        Vec3::new(3.0, 0.0, 0.0),
        Vec3::new(2.0, 1.0, 0.0),
    ]);
    let light = AreaLight::new(Rgb::ONE, shape).unwrap();
    // A fine integration grid: the triangle's hypotenuse crosses cells.
    let cfg = Chi2 {
        refine: 32,
        ..Chi2::default()
    };
    let rays = emit(&light, cfg.samples, 1);
    let pdf_pos = densities(&light, Vec3::new(0.5, 0.5, 0.0), Vec3::Z, Vec3::Z).pdf_pos;
    let inside = |p: Vec2| {
        (0.0..1.0).contains(&p.x) && (0.0..1.0).contains(&p.y)
            || (p.x >= 2.0 && p.y >= 0.0 && (p.x - 2.0) + p.y <= 1.0)
    };
    let samples = rays
        .iter()
        .map(|s| (s.pdf_pos > 0.0).then_some(Vec2::new(s.p.x, s.p.y)));
    cfg.run_planar(Vec2::ZERO, Vec2::new(3.0, 1.0), samples, |p| {
        if inside(p) { pdf_pos as f64 } else { 0.0 }
    })
    .unwrap();
    for s in &rays {
        assert_eq!(s.kind, EmissionKind::Surface);
        assert_eq!(s.pdf_pos, pdf_pos);
        assert_eq!(s.n, Vec3::Z);
    }
}

#[test]
fn area_light_directions_match_their_density() {
    let light = AreaLight::new(Rgb::ONE, square()).unwrap();
    let cfg = Chi2::default();
    let rays = emit(&light, cfg.samples, 2);
    let samples = rays.iter().map(|s| (s.pdf_pos > 0.0).then_some(s.dir));
    cfg.run(samples, |d| {
        densities(&light, Vec3::splat(0.5), Vec3::Z, d).pdf_dir as f64
    })
    .unwrap();
    for s in rays.iter().take(1000) {
        let d = densities(&light, s.p, s.n, s.dir);
        assert!((d.pdf_dir - s.pdf_dir).abs() <= 1e-4 * s.pdf_dir.max(1.0));
    }
}

#[test]
fn sphere_light_origins_are_uniform_over_the_sphere() {
    // On a sphere of radius 2, uniform by area is uniform over the
    // normals: density per unit solid angle of n = pdf_pos · r².
    let shape = EmitterShape {
        triangles: vec![],
        spheres: vec![(Vec3::new(1.0, 2.0, 3.0), 2.0)],
    };
    let light = AreaLight::new(Rgb::ONE, shape).unwrap();
    let cfg = Chi2::default();
    let rays = emit(&light, cfg.samples, 3);
    let pdf_pos = densities(&light, Vec3::ZERO, Vec3::Z, Vec3::Z).pdf_pos;
    let samples = rays.iter().map(|s| (s.pdf_pos > 0.0).then_some(s.n));
    cfg.run(samples, |_| pdf_pos as f64 * 4.0).unwrap();
    for s in rays.iter().take(1000) {
        assert!(((s.p - Vec3::new(1.0, 2.0, 3.0)).length() - 2.0).abs() < 1e-4);
        assert!(s.dir.dot(s.n) > 0.0, "emitted from the outside");
    }
}

#[test]
fn point_light_directions_are_uniform() {
    let light = PointLight::new(Vec3::new(0.5, 1.0, -2.0), Rgb::new(3.0, 2.0, 1.0));
    let cfg = Chi2::default();
    let rays = emit(&light, cfg.samples, 4);
    let pdf_dir = rays[0].pdf_dir as f64;
    let samples = rays.iter().map(|s| (s.pdf_pos > 0.0).then_some(s.dir));
    cfg.run(samples, |_| pdf_dir).unwrap();
    for s in &rays {
        assert_eq!(s.kind, EmissionKind::Point);
        assert_eq!(s.p, Vec3::new(0.5, 1.0, -2.0));
        assert_eq!(s.radiance, Rgb::new(3.0, 2.0, 1.0));
    }
}

#[test]
fn spot_light_directions_fill_its_cone() {
    let axis = Vec3::new(1.0, -2.0, 0.5).normalize();
    let (cutoff, beam) = (35f32.to_radians(), 20f32.to_radians());
    let light = SpotLight::new(Vec3::ZERO, axis, Rgb::ONE, cutoff, beam);
    let cfg = Chi2 {
        refine: 32,
        ..Chi2::default()
    };
    let rays = emit(&light, cfg.samples, 5);
    let pdf_dir = rays[0].pdf_dir as f64;
    let samples = rays.iter().map(|s| (s.pdf_pos > 0.0).then_some(s.dir));
    cfg.run(samples, |d| {
        if d.dot(axis) > cutoff.cos() {
            pdf_dir
        } else {
            0.0
        }
    })
    .unwrap();
    for s in &rays {
        // The falloff rides on the ray: what next-event estimation sees.
        let expected = light.falloff(s.dir.dot(axis));
        assert!((s.radiance.x - expected).abs() < 1e-5);
    }
}

/// The coordinates of `p` on the disc perpendicular to `dir` through the
/// scene sphere's centre, and its distance upstream of that plane.
fn on_disc(p: Vec3, dir: Vec3) -> (Vec2, f32) {
    let local = Frame::from_normal(dir).to_local(p - SPHERE.centre);
    (Vec2::new(local.x, local.y), -local.z)
}

/// Chi-square of emitted origins over the disc that covers the scene.
fn check_disc(rays: &[EmissionSample], pdf_pos: f32) -> Result<f64, String> {
    // A fine integration grid: the disc's rim crosses cells.
    let cfg = Chi2 {
        refine: 32,
        ..Chi2::default()
    };
    let r = SPHERE.radius;
    let samples = rays.iter().map(|s| {
        let (q, upstream) = on_disc(s.p, s.dir);
        assert!(upstream >= r, "rays start outside the scene");
        (s.pdf_pos > 0.0).then_some(q)
    });
    cfg.run_planar(Vec2::splat(-r), Vec2::splat(r), samples, |q| {
        if q.length() < r { pdf_pos as f64 } else { 0.0 }
    })
}

#[test]
fn directional_light_origins_cover_the_scene_uniformly() {
    let dir = Vec3::new(0.3, -1.0, 0.2).normalize();
    let light = DirectionalLight::new(dir, Rgb::ONE, SPHERE);
    let rays = emit(&light, Chi2::default().samples, 6);
    for s in &rays {
        assert_eq!(
            (s.kind, s.dir, s.pdf_dir),
            (EmissionKind::Directional, dir, 1.0)
        );
    }
    check_disc(&rays, rays[0].pdf_pos).unwrap();
}

fn sky() -> EnvironmentLight {
    let map = read_exr(root().join("scenes/environment-sky.exr")).expect("sky map");
    let rotation = Mat3::from_axis_angle(Vec3::new(1.0, 2.0, -0.5).normalize(), 1.1);
    EnvironmentLight::from_pixels(
        map.pixels,
        UVec2::new(map.width, map.height),
        rotation,
        SPHERE,
    )
    .expect("valid map")
}

#[test]
fn environment_emission_matches_its_densities() {
    let light = sky();
    let cfg = Chi2 {
        refine: 64,
        ..Chi2::default()
    };
    let rays = emit(&light, cfg.samples, 7);
    let samples = rays.iter().map(|s| (s.pdf_pos > 0.0).then_some(s.dir));
    cfg.run(samples, |d| {
        densities(&light, Vec3::ZERO, Vec3::ZERO, d).pdf_dir as f64
    })
    .unwrap();
    let pdf_pos = densities(&light, Vec3::ZERO, Vec3::ZERO, Vec3::Z).pdf_pos;
    check_disc(&rays, pdf_pos).unwrap();
    for s in rays.iter().take(1000) {
        let d = densities(&light, s.p, s.n, s.dir);
        assert!((d.pdf_dir - s.pdf_dir).abs() <= 2e-3 * s.pdf_dir);
        assert_eq!(d.pdf_pos, s.pdf_pos);
    }
}

#[test]
fn the_emission_tests_reject_a_wrong_density() {
    // Cosine-weighted directions against a uniform hemisphere, and the
    // disc's origins against a density 2 % too high, must both fail.
    let light = AreaLight::new(Rgb::ONE, square()).unwrap();
    let cfg = Chi2::default();
    let rays = emit(&light, cfg.samples, 8);
    let samples = rays.iter().map(|s| Some(s.dir));
    let uniform = |d: Vec3| {
        if d.z > 0.0 {
            0.5 / std::f64::consts::PI
        } else {
            0.0
        }
    };
    assert!(cfg.run(samples, uniform).is_err());
    let dir = Vec3::new(0.3, -1.0, 0.2).normalize();
    let sun = DirectionalLight::new(dir, Rgb::ONE, SPHERE);
    let rays = emit(&sun, cfg.samples, 9);
    assert!(check_disc(&rays, rays[0].pdf_pos * 1.02).is_err());
}

/// A thin lens at the origin looking along +z (camera space is render
/// space), 32 × 24 pixels.
fn thin_lens() -> ThinLens {
    ThinLens::new(
        Mat4::IDENTITY,
        Vec2::new(32.0, 24.0),
        50.0,
        FovAxis::X,
        0.3,
        2.0,
    )
    .unwrap()
}

fn connect(camera: &dyn Camera, refs: &[Vec3], seed: u64) -> Vec<LensSample> {
    let mut rng = Rng::new(seed);
    let u: Vec<Vec2> = refs.iter().map(|_| rng.next_2d()).collect();
    let mut out = vec![LensSample::default(); refs.len()];
    camera.importance().unwrap().sample_wi(refs, &u, &mut out);
    out
}

/// Solid-angle density, seen from `r`, of a uniform point on the disc of
/// radius `radius` at z = 0 (normal +z).
fn lens_density(r: Vec3, d: Vec3, radius: f32) -> f64 {
    if d.z >= 0.0 {
        return 0.0;
    }
    let t = -r.z / d.z;
    let p = r + d * t;
    if p.truncate().length() >= radius {
        return 0.0;
    }
    let area = std::f64::consts::PI * (radius as f64).powi(2);
    (t as f64).powi(2) / ((-d.z) as f64 * area)
}

#[test]
fn lens_connections_match_their_density() {
    let camera = thin_lens();
    // Near the plane in focus, so that every lens point sees it on the film.
    let r = Vec3::new(0.02, -0.01, 1.2);
    let cfg = Chi2 {
        refine: 64,
        ..Chi2::default()
    };
    let out = connect(&camera, &vec![r; cfg.samples], 10);
    let samples = out.iter().map(|s| (s.pdf > 0.0).then_some(s.wi));
    cfg.run(samples, |d| lens_density(r, d, 0.3)).unwrap();
    for s in out.iter().take(1000) {
        let expected = lens_density(r, s.wi, 0.3) as f32;
        assert!((s.pdf - expected).abs() < 1e-3 * expected);
    }
    // A lens density 2 % off is rejected.
    let samples = out.iter().map(|s| (s.pdf > 0.0).then_some(s.wi));
    assert!(
        cfg.run(samples, |d| 1.02 * lens_density(r, d, 0.3))
            .is_err()
    );
}

/// Camera rays through uniform film positions and lens samples.
fn generate(camera: &dyn Camera, n: usize, seed: u64) -> Vec<(Vec3, Vec3)> {
    let mut rng = Rng::new(seed);
    let film: Vec<Vec2> = (0..n)
        .map(|_| rng.next_2d() * Vec2::new(32.0, 24.0))
        .collect();
    let lens: Vec<Vec2> = (0..n).map(|_| rng.next_2d()).collect();
    let (mut o, mut d, mut w) = (vec![Vec3::ZERO; n], vec![Vec3::ZERO; n], vec![0.0; n]);
    camera.generate(
        &film,
        &lens,
        CameraRays {
            origins: &mut o,
            directions: &mut d,
            weights: &mut w,
        },
    );
    o.into_iter().zip(d).collect()
}

fn ray_pdfs(camera: &dyn Camera, rays: &[(Vec3, Vec3)]) -> Vec<CameraRayPdf> {
    let mut out = vec![CameraRayPdf::default(); rays.len()];
    camera.importance().unwrap().pdf_ray(rays, &mut out);
    out
}

#[test]
fn camera_ray_directions_match_pdf_ray() {
    // A pinhole's directions over the whole film against pdf_dir.
    let camera = Perspective::new(Mat4::IDENTITY, Vec2::new(32.0, 24.0), 70.0, FovAxis::X).unwrap();
    let cfg = Chi2 {
        refine: 16,
        ..Chi2::default()
    };
    let rays = generate(&camera, cfg.samples, 11);
    let density = |d: Vec3| ray_pdfs(&camera, &[(Vec3::ZERO, d)])[0].pdf_dir as f64;
    cfg.run(rays.iter().map(|r| Some(r.1)), density).unwrap();
    assert!(
        cfg.run(rays.iter().map(|r| Some(r.1)), |d| 1.02 * density(d))
            .is_err()
    );
}

#[test]
fn importance_and_densities_give_the_camera_ray_weight() {
    // For every camera ray: We cos θ / (pdf_pos pdf_dir) = 1 (the weight
    // `generate` gives), and connecting a point on the ray to the lens
    // with the same lens sample lands on the film position that made it.
    let pinhole =
        Perspective::new(Mat4::IDENTITY, Vec2::new(32.0, 24.0), 70.0, FovAxis::X).unwrap();
    let lens = thin_lens();
    for camera in [&pinhole as &dyn Camera, &lens] {
        let mut rng = Rng::new(12);
        for _ in 0..2000 {
            let film = rng.next_2d() * Vec2::new(32.0, 24.0);
            let u = rng.next_2d();
            let (mut o, mut d, mut w) = ([Vec3::ZERO], [Vec3::ZERO], [0.0]);
            camera.generate(
                &[film],
                &[u],
                CameraRays {
                    origins: &mut o,
                    directions: &mut d,
                    weights: &mut w,
                },
            );
            let pdf = ray_pdfs(camera, &[(o[0], d[0])])[0];
            let point = o[0] + d[0] * 3.0;
            let mut s = [LensSample::default()];
            camera
                .importance()
                .unwrap()
                .sample_wi(&[point], &[u], &mut s);
            let s = s[0];
            assert!((s.p - o[0]).length() < 1e-5, "the same lens point");
            assert!((s.raster - film).length() < 2e-3, "{} vs {film}", s.raster);
            // We cos / (pdf_pos pdf_dir) = 1, with cos θ = d.z here.
            let weight = s.importance * d[0].z / (pdf.pdf_pos * pdf.pdf_dir);
            assert!((weight - 1.0).abs() < 1e-3, "weight {weight}");
            // The lens density from the point: distance² / (cos · area).
            let dist2 = (point - o[0]).length_squared();
            assert!((s.pdf * d[0].z * pdf.pdf_pos.recip() - dist2).abs() < 1e-3 * dist2);
        }
        // Behind the camera and outside the film: no connection.
        let out = connect(
            camera,
            &[Vec3::new(0.0, 0.0, -1.0), Vec3::new(50.0, 0.0, 1.0)],
            13,
        );
        assert!(out.iter().all(|s| s.pdf == 0.0));
    }
}

#[test]
fn orthographic_connections_land_where_its_rays_start() {
    // One direction for all rays: a point connects to the window point
    // below it, at the film position that made the ray, with density 1
    // and importance 1 / window area = pdf_pos (We / (pdf_pos pdf_dir) = 1).
    let camera = Orthographic::new(Mat4::IDENTITY, Vec2::new(32.0, 24.0), 3.0).unwrap();
    let importance = camera.importance().unwrap();
    assert!(importance.directional());
    let mut rng = Rng::new(14);
    for _ in 0..1000 {
        let film = rng.next_2d() * Vec2::new(32.0, 24.0);
        let (mut o, mut d, mut w) = ([Vec3::ZERO], [Vec3::ZERO], [0.0]);
        camera.generate(
            &[film],
            &[Vec2::ZERO],
            CameraRays {
                origins: &mut o,
                directions: &mut d,
                weights: &mut w,
            },
        );
        let mut s = [LensSample::default()];
        importance.sample_wi(&[o[0] + d[0] * 2.5], &[Vec2::ZERO], &mut s);
        let pdf = ray_pdfs(&camera, &[(o[0], d[0])])[0];
        assert!((s[0].p - o[0]).length() < 1e-5 && (s[0].raster - film).length() < 1e-3);
        assert_eq!((s[0].pdf, pdf.pdf_dir), (1.0, 1.0));
        assert!((s[0].importance / pdf.pdf_pos - 1.0).abs() < 1e-6);
        assert!(
            (pdf.pdf_pos * 3.0 * 2.25 - 1.0).abs() < 1e-5,
            "1 / window area"
        );
    }
    // Behind the window and beside it: no connection.
    let out = connect(
        &camera,
        &[Vec3::new(0.0, 0.0, -1.0), Vec3::new(5.0, 0.0, 1.0)],
        15,
    );
    assert!(out.iter().all(|s| s.pdf == 0.0));
}
