//! Modules that say they read no samples of a kind give the same output
//! whatever those samples hold: a camera without a lens
//! (`Camera::uses_lens_samples`), a light at a point or from a direction
//! (`Light::uses_point_samples`) and a shader with one lobe
//! (`Shader::uses_lobe_samples`). The path integrator draws no such samples
//! for them, so a module that said so and read them anyway would see
//! whatever the buffer last held. Every built-in module that declares
//! samples unused is checked, and the check is shown to fail on modules
//! that do read them (a thin lens, area and environment lights, the
//! lobe choices of plastic, dielectrics, principled and blend).

// `unwrap` in this test code is the assertion: the inputs are the test's
// own, so a failure is a bug, and the panic reports it with the error.

use glam::{Vec2, Vec3};
use radiant::extract::{Overrides, RenderScene, extract};
use radiant_core::{CameraRays, LightSample};
use radiant_tests::chi2::Rng;
use radiant_tests::shading::{direction, shader};

/// A scene with every built-in light type and the camera `camera`.
fn scene(camera: &str) -> RenderScene {
    let text = format!(
        "camera: {camera}
materials:
  grey: {{type: diffuse, reflectance: 0.5}}
  black: {{type: diffuse, reflectance: 0}}
shapes:
  - {{type: rectangle, material: grey}}
  - {{type: sphere, center: [0, 2, 0], radius: 0.3, material: black, emitter: {{type: area, radiance: 5}}}}
  - {{type: rectangle, material: black, transform: [{{translate: [1, 2, 1]}}], emitter: {{type: area, radiance: 5}}}}
lights:
  - {{type: point, position: [1, 3, 2], intensity: 10}}
  - {{type: spot, position: [-1, 3, 1], target: [0, 0, 0], intensity: 10, cutoff_angle: 30}}
  - {{type: directional, direction: [0.3, -1, 0.2], irradiance: 2}}
  - {{type: environment, radiance: 0.1}}
"
    );
    let scene = radiant::scene::from_str(
        &text,
        std::path::Path::new("sample-dimensions.yaml"),
        std::path::Path::new("."),
    )
    .unwrap();
    extract(&scene, &radiant::builtin_registry(), &Overrides::default()).unwrap()
}

/// `n` uniform 2D samples.
fn uniform_2d(rng: &mut Rng, n: usize) -> Vec<Vec2> {
    (0..n)
        .map(|_| Vec2::new(rng.uniform(), rng.uniform()))
        .collect()
}

/// Whether `a` and `b` are the same bit for bit (NaN equal to itself).
fn same_bits<T: std::fmt::Debug>(a: &T, b: &T) -> bool {
    format!("{a:?}") == format!("{b:?}")
}

/// Whether the camera's rays through the same film points change with the
/// lens samples.
fn camera_reads_lens(scene: &RenderScene) -> bool {
    let mut rng = Rng::new(3);
    let n = 256;
    let (w, h) = (scene.settings.width as f32, scene.settings.height as f32);
    let film: Vec<Vec2> = uniform_2d(&mut rng, n)
        .into_iter()
        .map(|p| p * Vec2::new(w, h))
        .collect();
    let rays = |lens: &[Vec2]| {
        let (mut o, mut d, mut wt) = (vec![Vec3::ZERO; n], vec![Vec3::ZERO; n], vec![0.0; n]);
        scene.camera.generate(
            &film,
            lens,
            CameraRays {
                origins: &mut o,
                directions: &mut d,
                weights: &mut wt,
            },
        );
        (o, d, wt)
    };
    let (a, b) = (uniform_2d(&mut rng, n), uniform_2d(&mut rng, n));
    !same_bits(&rays(&a), &rays(&b))
}

#[test]
fn cameras_without_a_lens_ignore_the_lens_samples() {
    let look = "look_at: {origin: [0, 1, 5], target: [0, 0.5, 0], up: [0, 1, 0]}";
    let cameras = [
        (format!("{{type: perspective, fov: 40, {look}}}"), false),
        (format!("{{type: orthographic, width: 4, {look}}}"), false),
        (format!("{{type: spherical, {look}}}"), false),
        (
            format!(
                "{{type: thin_lens, fov: 40, aperture_radius: 0.1, focus_distance: 5, {look}}}"
            ),
            true,
        ),
    ];
    for (camera, reads) in cameras {
        let scene = scene(&camera);
        assert_eq!(
            scene.camera.uses_lens_samples(),
            reads,
            "{camera}: what it declares"
        );
        assert_eq!(camera_reads_lens(&scene), reads, "{camera}: what it does");
    }
}

#[test]
fn lights_at_a_point_or_from_a_direction_ignore_their_samples() {
    let scene = scene("{type: perspective, fov: 40}");
    let mut rng = Rng::new(7);
    let n = 256;
    let refs: Vec<Vec3> = (0..n)
        .map(|_| Vec3::new(rng.uniform(), rng.uniform(), rng.uniform()) * 4.0 - 2.0)
        .collect();
    let (ua, ub) = (uniform_2d(&mut rng, n), uniform_2d(&mut rng, n));
    let lights = scene.lights.lights();
    let mut declared_free = 0;
    for (i, light) in lights.iter().enumerate() {
        let sample = |u: &[Vec2]| {
            let mut out = vec![LightSample::default(); n];
            light.sample(&refs, u, &mut out);
            out
        };
        let reads = !same_bits(&sample(&ua), &sample(&ub));
        if light.uses_point_samples() {
            // Every light here that may read them does.
            assert!(reads, "light {i} declares samples it does not read");
        } else {
            declared_free += 1;
            assert!(!reads, "light {i} reads samples it declares unused");
        }
    }
    // Point, spot and directional; the sphere, rectangle and environment
    // read theirs.
    assert_eq!((lights.len(), declared_free), (6, 3));
}

#[test]
fn shaders_with_one_lobe_ignore_the_lobe_choice() {
    let shaders = [
        ("{type: diffuse, reflectance: 0.8}", false),
        ("{type: rough_diffuse, alpha: 0.3}", false),
        ("{type: conductor}", false),
        ("{type: conductor, alpha: 0.2}", false),
        (
            "{type: normal_map, normals: tilt, material: {type: rough_diffuse, alpha: 0.5}}",
            false,
        ),
        ("{type: plastic, alpha: 0.1}", true),
        ("{type: dielectric, alpha: 0.3}", true),
        ("{type: dielectric}", true),
        ("{type: thin_dielectric}", true),
        ("{type: principled, metallic: 0.3, roughness: 0.5}", true),
        (
            "{type: blend, weight: 0.3, materials: [{type: diffuse}, {type: conductor, alpha: 0.1}]}",
            true,
        ),
        (
            "{type: normal_map, normals: tilt, material: {type: plastic, alpha: 0.2}}",
            true,
        ),
    ];
    let mut rng = Rng::new(11);
    let n = 512;
    let u: Vec<Vec3> = (0..n)
        .map(|_| Vec3::new(rng.uniform(), rng.uniform(), rng.uniform()))
        .collect();
    // The same 2D samples, another lobe choice.
    let moved: Vec<Vec3> = u.iter().map(|u| Vec3::new(1.0 - u.x, u.y, u.z)).collect();
    for (yaml, reads) in shaders {
        let s = shader(yaml);
        assert_eq!(
            s.shader.uses_lobe_samples(),
            reads,
            "{yaml}: what it declares"
        );
        let wo = direction(0.6, 0.7);
        let changed = !same_bits(&s.sample(wo, &u), &s.sample(wo, &moved));
        assert_eq!(changed, reads, "{yaml}: what it does");
    }
}
