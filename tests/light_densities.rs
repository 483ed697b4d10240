//! Every light's sample agrees with its evaluation path: the density (and
//! radiance) `sample` returns for a point equals what `eval_hits` (surface
//! lights) or `eval_escaped` (environments) returns for a ray that reaches
//! the same point, from many random reference points near and far, to
//! single-precision tolerance. A light whose sampling side reports a
//! density 1 % off its evaluation side brightens or darkens every image it
//! lights by about as much, and no render comparison sees that reliably;
//! this test does, cheaply. Delta lights (point, spot, directional), which
//! no ray can hit, must return density 1 and the radiance their formulas
//! give.

// `unwrap` in this test code is the assertion: the inputs are the test's
// own, so a failure is a bug, and the panic reports it with the error.

use glam::{Mat3, UVec2, Vec2, Vec3};
use radiant_core::{
    BoundingSphere, EmitterEval, EmitterHit, EmitterShape, Light, LightSample, Rgb,
};
use radiant_lights::{AreaLight, DirectionalLight, EnvironmentLight, PointLight, SpotLight};
use radiant_tests::chi2::Rng;

/// Relative tolerance: both sides compute the same density in single
/// precision (measured: below 1e-6 for every shape).
const TOLERANCE: f32 = 1e-4;

/// A random unit vector.
fn unit(rng: &mut Rng) -> Vec3 {
    let z = 2.0 * rng.uniform() - 1.0;
    let r = (1.0 - z * z).max(0.0).sqrt();
    let phi = std::f32::consts::TAU * rng.uniform();
    Vec3::new(r * phi.cos(), r * phi.sin(), z)
}

/// Reference points around `centre` at distances from `near` to `far`
/// times `size`, log-uniformly spread, in random directions.
fn reference_points(rng: &mut Rng, centre: Vec3, size: f32, n: usize) -> Vec<Vec3> {
    (0..n)
        .map(|_| {
            let distance = size * 10f32.powf(-1.5 + 4.5 * rng.uniform());
            centre + unit(rng) * distance
        })
        .collect()
}

/// The index of the triangle of `triangles` that holds `p`.
fn triangle_holding(triangles: &[[Vec3; 3]], p: Vec3) -> u32 {
    let mut best = (f32::INFINITY, 0);
    for (i, [a, b, c]) in triangles.iter().enumerate() {
        let n = (*b - *a).cross(*c - *a);
        let area2 = n.length();
        let off_plane = (p - *a).dot(n).abs() / area2;
        let bary = [
            (*c - *b).cross(p - *b).dot(n) / (area2 * area2),
            (*a - *c).cross(p - *c).dot(n) / (area2 * area2),
            (*b - *a).cross(p - *a).dot(n) / (area2 * area2),
        ];
        let outside = bary.iter().map(|&w| (-w).max(0.0)).sum::<f32>();
        let miss = off_plane / area2.sqrt() + outside;
        if miss < best.0 {
            best = (miss, i as u32);
        }
    }
    best.1
}

/// Relative difference of two densities or radiances.
fn relative(a: f32, b: f32) -> f32 {
    (a - b).abs() / a.abs().max(b.abs()).max(1e-30)
}

/// Samples `light` from `refs` and checks each sample against
/// `eval_hits` of a ray from the reference point to the sampled point;
/// returns how many samples succeeded and the worst relative difference.
fn check_area_light(name: &str, light: &AreaLight, shape: &EmitterShape, refs: &[Vec3]) -> usize {
    let mut rng = Rng::new(11);
    let u: Vec<Vec2> = refs
        .iter()
        .map(|_| Vec2::new(rng.uniform(), rng.uniform()))
        .collect();
    let mut samples = vec![LightSample::default(); refs.len()];
    light.sample(refs, &u, &mut samples);
    let triangles = shape.triangles.len() as u32;
    let mut hits = Vec::new();
    let mut used = Vec::new();
    for (r, s) in refs.iter().zip(&samples) {
        if s.pdf <= 0.0 {
            continue;
        }
        let primitive = if shape.spheres.is_empty() {
            triangle_holding(&shape.triangles, s.p)
        } else {
            triangles
        };
        hits.push(EmitterHit {
            origin: *r,
            p: s.p,
            n: s.n,
            primitive,
        });
        used.push(*s);
    }
    let mut evals = vec![EmitterEval::default(); hits.len()];
    light.eval_hits(&hits, &mut evals);
    let mut worst = 0.0f32;
    for ((h, s), e) in hits.iter().zip(&used).zip(&evals) {
        let d = relative(s.pdf, e.pdf);
        worst = worst.max(d);
        assert!(
            d < TOLERANCE,
            "{name}: sample density {} but eval_hits {} for the point {} seen from {}",
            s.pdf,
            e.pdf,
            h.p,
            h.origin
        );
        assert_eq!(s.radiance, e.radiance, "{name}: radiance");
    }
    eprintln!(
        "{name}: {} of {} samples succeeded, worst density difference {worst:.1e}",
        hits.len(),
        refs.len()
    );
    hits.len()
}

/// An irregular tetrahedron (no two faces form a rectangle): sampled by
/// area, triangle by triangle.
fn tetrahedron() -> EmitterShape {
    let v = [
        Vec3::new(0.1, 0.0, 0.0),
        Vec3::new(1.3, 0.2, -0.1),
        Vec3::new(0.4, 1.1, 0.3),
        Vec3::new(0.5, 0.4, 1.2),
    ];
    EmitterShape {
        triangles: vec![
            [v[0], v[2], v[1]],
            [v[0], v[1], v[3]],
            [v[1], v[2], v[3]],
            [v[0], v[3], v[2]],
        ],
        spheres: vec![],
    }
}

/// A 2 × 0.5 rectangle, turned, as the two triangles a `rectangle` shape
/// makes: sampled by solid angle.
fn rectangle() -> EmitterShape {
    let turn = Mat3::from_rotation_x(0.4) * Mat3::from_rotation_z(0.9);
    let c = [
        Vec3::new(-1.0, -0.25, 0.0),
        Vec3::new(1.0, -0.25, 0.0),
        Vec3::new(1.0, 0.25, 0.0),
        Vec3::new(-1.0, 0.25, 0.0),
    ]
    .map(|p| turn * p + Vec3::new(0.3, -0.2, 0.5));
    EmitterShape {
        triangles: vec![[c[0], c[1], c[2]], [c[0], c[2], c[3]]],
        spheres: vec![],
    }
}

/// A box of six rectangles, as a `cube` shape makes it.
fn cube() -> EmitterShape {
    EmitterShape {
        triangles: radiant_tests::box_triangles(Vec3::new(0.5, 1.0, 0.25), Vec3::ZERO),
        spheres: vec![],
    }
}

#[test]
fn area_lights_sample_the_density_eval_hits_returns() {
    let mut rng = Rng::new(3);
    let shapes: [(&str, EmitterShape, Vec3); 3] = [
        ("triangles", tetrahedron(), Vec3::new(0.5, 0.4, 0.3)),
        ("rectangle", rectangle(), Vec3::new(0.3, -0.2, 0.5)),
        ("cube", cube(), Vec3::ZERO),
    ];
    for (name, shape, centre) in shapes {
        let light = AreaLight::new(Rgb::new(1.0, 2.0, 3.0), shape.clone()).unwrap();
        let refs = reference_points(&mut rng, centre, 1.0, 4000);
        let used = check_area_light(name, &light, &shape, &refs);
        assert!(used > 1000, "{name}: only {used} samples succeeded");
    }
}

#[test]
fn sphere_lights_sample_the_density_eval_hits_returns() {
    // Outside (by solid angle: cone sampling, with its small-angle
    // expansion far away); inside, the one-sided emission faces away, so
    // no sample may succeed.
    let mut rng = Rng::new(5);
    let (centre, radius) = (Vec3::new(0.2, -0.3, 0.1), 0.7);
    let shape = EmitterShape {
        triangles: vec![],
        spheres: vec![(centre, radius)],
    };
    let light = AreaLight::new(Rgb::ONE, shape.clone()).unwrap();
    let outside: Vec<Vec3> = reference_points(&mut rng, centre, radius, 8000)
        .into_iter()
        .filter(|p| (*p - centre).length() > radius * 1.0001)
        .collect();
    let used = check_area_light("sphere from outside", &light, &shape, &outside);
    assert!(
        used == outside.len() && used > 4000,
        "only {used} of {} samples from outside succeeded",
        outside.len()
    );
    let inside: Vec<Vec3> = (0..4000)
        .map(|_| centre + unit(&mut rng) * radius * rng.uniform().sqrt() * 0.999)
        .collect();
    let used = check_area_light("sphere from inside", &light, &shape, &inside);
    assert_eq!(used, 0, "the sphere emits outwards only");
}

#[test]
fn environments_sample_the_density_eval_escaped_returns() {
    let mut rng = Rng::new(9);
    let sphere = BoundingSphere {
        centre: Vec3::new(0.5, 0.0, -1.0),
        radius: 3.0,
    };
    // A map with a bright spot, a dark band and texels of every size.
    let (w, h) = (48u32, 24u32);
    let pixels: Vec<Rgb> = (0..w * h)
        .map(|i| {
            let (x, y) = ((i % w) as f32 / w as f32, (i / w) as f32 / h as f32);
            let spot = 50.0 * (-((x - 0.3).powi(2) + (y - 0.7).powi(2)) * 200.0).exp();
            Rgb::new(0.2 + spot, 0.1 + x, 0.05 + 0.5 * (y * 9.0).sin().abs())
        })
        .collect();
    let lights = [
        (
            "map",
            EnvironmentLight::from_pixels(
                pixels,
                UVec2::new(w, h),
                Mat3::from_rotation_y(0.3),
                sphere,
            )
            .unwrap(),
        ),
        (
            "constant",
            EnvironmentLight::constant(Rgb::splat(0.7), sphere),
        ),
    ];
    for (name, light) in lights {
        let refs = reference_points(&mut rng, sphere.centre, sphere.radius, 4000)
            .into_iter()
            .filter(|p| (*p - sphere.centre).length() < sphere.radius)
            .collect::<Vec<_>>();
        let u: Vec<Vec2> = refs
            .iter()
            .map(|_| Vec2::new(rng.uniform(), rng.uniform()))
            .collect();
        let mut samples = vec![LightSample::default(); refs.len()];
        light.sample(&refs, &u, &mut samples);
        let dirs: Vec<Vec3> = refs
            .iter()
            .zip(&samples)
            .map(|(r, s)| (s.p - *r).normalize())
            .collect();
        let mut evals = vec![EmitterEval::default(); dirs.len()];
        light.eval_escaped(&dirs, &mut evals);
        let mut worst = 0.0f32;
        for (s, e) in samples.iter().zip(&evals) {
            assert!(s.pdf > 0.0, "{name}: the map has no black texel");
            let d = relative(s.pdf, e.pdf);
            worst = worst.max(d);
            // The direction is recomputed from the point, which rounds.
            assert!(
                d < 2e-3,
                "{name}: sample density {} but eval {}",
                s.pdf,
                e.pdf
            );
            for c in 0..3 {
                assert!(
                    relative(s.radiance[c], e.radiance[c]) < 2e-3,
                    "{name}: radiance"
                );
            }
        }
        eprintln!("{name}: worst density difference {worst:.1e}");
    }
}

#[test]
fn delta_lights_return_their_formulas() {
    let mut rng = Rng::new(13);
    let refs = reference_points(&mut rng, Vec3::ZERO, 1.0, 2000);
    let u = vec![Vec2::splat(0.5); refs.len()];
    let mut out = vec![LightSample::default(); refs.len()];
    let position = Vec3::new(0.3, 0.2, -0.1);
    let intensity = Rgb::new(2.0, 3.0, 4.0);
    let close = |a: Rgb, b: Rgb| (0..3).all(|c| relative(a[c], b[c]) < TOLERANCE);

    let point = PointLight::new(position, intensity);
    assert!(point.is_delta());
    point.sample(&refs, &u, &mut out);
    for (r, s) in refs.iter().zip(&out) {
        assert_eq!((s.p, s.pdf), (position, 1.0), "point light");
        let expected = intensity / (position - *r).length_squared();
        assert!(
            close(s.radiance, expected),
            "point: {} vs {expected}",
            s.radiance
        );
    }

    // Mitsuba 3's spot: full intensity within the beam, falling linearly
    // in angle to zero at the cutoff.
    let axis = Vec3::new(0.2, -1.0, 0.3).normalize();
    let (cutoff, beam) = (40f32.to_radians(), 25f32.to_radians());
    let spot = SpotLight::new(position, axis, intensity, cutoff, beam);
    spot.sample(&refs, &u, &mut out);
    let mut lit = 0;
    for (r, s) in refs.iter().zip(&out) {
        assert_eq!((s.p, s.pdf), (position, 1.0), "spot light");
        let d = *r - position;
        let angle = axis.dot(d.normalize()).clamp(-1.0, 1.0).acos();
        let falloff = ((cutoff - angle) / (cutoff - beam)).clamp(0.0, 1.0);
        let expected = intensity * falloff / d.length_squared();
        if falloff > 0.0 {
            lit += 1;
            assert!(
                close(s.radiance, expected),
                "spot: {} vs {expected}",
                s.radiance
            );
        } else {
            assert_eq!(s.radiance, Rgb::ZERO, "spot outside its cutoff");
        }
    }
    assert!(lit > 100, "only {lit} points inside the spot's cone");

    let sphere = BoundingSphere {
        centre: Vec3::ZERO,
        radius: 50.0,
    };
    let direction = Vec3::new(0.3, -0.9, 0.1).normalize();
    let sun = DirectionalLight::new(direction, intensity, sphere);
    sun.sample(&refs, &u, &mut out);
    for (r, s) in refs.iter().zip(&out) {
        assert_eq!(s.pdf, 1.0, "directional light");
        assert_eq!(s.radiance, intensity, "directional light");
        let towards = (s.p - *r).normalize();
        assert!(
            towards.dot(-direction) > 1.0 - 1e-6,
            "the sun is behind the light's direction"
        );
    }
}
