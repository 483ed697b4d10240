//! Spatial light selection (`light_selection: spatial`): the choice it
//! makes against the probabilities it claims, and the image it renders.
//!
//! * Chi-square: from shading points near, far, behind and inside the
//!   lights' boxes, the lights [`LightTable::select_at`] picks are counted
//!   against N × [`LightTable::pmf_at`]; every pick's returned probability
//!   must equal `pmf_at` for the same point bit for bit (the probability an
//!   emitter hit is weighted with under MIS), and the probabilities must
//!   sum to 1.
//! * Conservative bounds: where a light's importance is 0, its samples
//!   from that point carry no radiance (else selection would be biased).
//! * Renders: a floor lit by a spot, a point and a rectangle light gives
//!   the same image with spatial selection as with power selection, and a
//!   4 % brighter rectangle light is told apart by the same comparison.

// `unwrap` in this test code is the assertion: the inputs are the test's
// own, so a failure is a bug, and the panic reports it.

use glam::{Vec2, Vec3};
use radiant::backend::cpu::{Progress, render};
use radiant::extract::{FLAT_LIMIT, LightTable, Overrides, extract};
use radiant::film::Image;
use radiant::scene::LightSelection;
use radiant_core::{BoundingSphere, EmitterShape, Light, LightSample, Rgb};
use radiant_lights::{AreaLight, DirectionalLight, PointLight, SpotLight};
use radiant_tests::chi2::{Chi2, Rng};
use radiant_tests::{channel_means, root};

fn rectangle(centre: Vec3, half: f32, normal_down: bool) -> EmitterShape {
    let (a, b, c, d) = (
        centre + Vec3::new(-half, 0.0, -half),
        centre + Vec3::new(half, 0.0, -half),
        centre + Vec3::new(half, 0.0, half),
        centre + Vec3::new(-half, 0.0, half),
    );
    // (b − a) × (c − a) points down (−y) for this winding.
    let triangles = if normal_down {
        vec![[a, b, c], [a, c, d]]
    } else {
        vec![[a, c, b], [a, d, c]]
    };
    EmitterShape {
        triangles,
        spheres: Vec::new(),
    }
}

/// Bounded lights of every kind: a point, a spot, a rectangle facing down,
/// a sphere, and a triangle fan facing up.
fn bounded_lights() -> Vec<Box<dyn Light>> {
    let spot_axis = Vec3::new(0.2, -1.0, 0.1).normalize();
    vec![
        Box::new(PointLight::new(Vec3::new(-2.0, 2.0, 0.5), Rgb::splat(5.0))),
        Box::new(SpotLight::new(
            Vec3::new(1.0, 3.0, 0.0),
            spot_axis,
            Rgb::new(20.0, 18.0, 15.0),
            30f32.to_radians(),
            20f32.to_radians(),
        )),
        Box::new(
            AreaLight::new(
                Rgb::splat(8.0),
                rectangle(Vec3::new(0.0, 2.5, -1.0), 0.3, true),
            )
            .unwrap(),
        ),
        Box::new(
            AreaLight::new(
                Rgb::splat(3.0),
                EmitterShape {
                    triangles: Vec::new(),
                    spheres: vec![(Vec3::new(2.0, 0.5, 2.0), 0.25)],
                },
            )
            .unwrap(),
        ),
        Box::new(
            AreaLight::new(
                Rgb::splat(2.0),
                rectangle(Vec3::new(-1.0, -0.5, 1.0), 0.4, false),
            )
            .unwrap(),
        ),
    ]
}

/// Shading points near and far, behind the one-sided lights and inside the
/// rectangle light's box.
const POINTS: [Vec3; 7] = [
    Vec3::new(0.0, 0.0, 0.0),
    Vec3::new(1.2, 0.1, 0.0),
    Vec3::new(-1.9, 1.8, 0.4),
    Vec3::new(0.0, 2.5, -1.0),
    Vec3::new(0.0, 4.0, -1.0),
    Vec3::new(30.0, -5.0, 20.0),
    Vec3::new(2.0, 0.9, 2.0),
];

/// Counts `select_at` at `p` against `pmf_at`, checking each pick's
/// probability and the sum of the probabilities: 1 (or 0 where no light
/// reaches `p`) when every light's importance is evaluated; at most 1
/// through the light tree, whose walk can end at a light that cannot reach
/// `p` (the sample then fails, as in pbrt-v4), which the chi-square test's
/// count of successes checks.
fn check_table(table: &LightTable, p: Vec3, seed: u64) {
    let n = table.len();
    let sum: f32 = (0..n).map(|i| table.pmf_at(p, i)).sum();
    if n > FLAT_LIMIT {
        assert!(sum <= 1.0 + 1e-5, "at {p}: probabilities sum to {sum}");
    } else {
        assert!(
            (sum - 1.0).abs() < 1e-5 || sum == 0.0,
            "at {p}: probabilities sum to {sum}"
        );
    }
    if n <= FLAT_LIMIT && table.lights().iter().all(|l| l.bounds().is_some()) {
        // Exactly in proportion to the importance the lights claim.
        let importance: Vec<f64> = table
            .lights()
            .iter()
            .map(|l| f64::from(l.bounds().map_or(0.0, |b| b.importance(p))))
            .collect();
        let total: f64 = importance.iter().sum();
        for (i, w) in importance.iter().enumerate() {
            let expected = if total > 0.0 { w / total } else { 0.0 };
            let got = f64::from(table.pmf_at(p, i));
            assert!(
                (got - expected).abs() <= 1e-6 * expected.max(1e-3),
                "at {p}: light {i} has probability {got}, its importance share is {expected}"
            );
        }
    }
    let draws = 200_000;
    let mut rng = Rng::new(seed);
    let mut observed = vec![0.0f64; n];
    for _ in 0..draws {
        let (i, pmf) = table.select_at(p, rng.uniform());
        // Probability 0 marks a failed choice (no light reached).
        if pmf > 0.0 {
            assert_eq!(
                pmf.to_bits(),
                table.pmf_at(p, i).to_bits(),
                "at {p}: light {i} picked with {pmf}, pmf_at says {}",
                table.pmf_at(p, i)
            );
            observed[i] += 1.0;
        }
    }
    if sum == 0.0 {
        return;
    }
    let expected: Vec<f64> = (0..n)
        .map(|i| f64::from(table.pmf_at(p, i)) * draws as f64)
        .collect();
    Chi2::default()
        .run_discrete(&observed, &expected, draws)
        .unwrap_or_else(|e| panic!("at {p}: {e}"));
}

#[test]
fn spatial_selection_picks_lights_with_the_probability_it_reports() {
    let table = LightTable::new(bounded_lights(), LightSelection::Spatial);
    for (k, p) in POINTS.iter().enumerate() {
        check_table(&table, *p, 17 + k as u64);
    }
}

/// 60 lights of every bounded kind spread over a 6 × 4 × 6 block: more
/// than [`FLAT_LIMIT`], so selection goes through the light tree.
fn many_lights() -> Vec<Box<dyn Light>> {
    let mut lights: Vec<Box<dyn Light>> = Vec::new();
    for i in 0..60 {
        let f = i as f32;
        let p = Vec3::new(
            (f * 0.37).fract() * 6.0 - 3.0,
            (f * 0.61).fract() * 4.0 - 1.0,
            (f * 0.23).fract() * 6.0 - 3.0,
        );
        let power = 1.0 + (f * 0.77).fract() * 20.0;
        lights.push(match i % 4 {
            0 => Box::new(PointLight::new(p, Rgb::splat(power))),
            1 => Box::new(SpotLight::new(
                p,
                Vec3::new((f * 0.3).sin(), -1.0, (f * 0.7).cos()).normalize(),
                Rgb::splat(power),
                25f32.to_radians(),
                15f32.to_radians(),
            )),
            2 => Box::new(
                AreaLight::new(
                    Rgb::splat(power),
                    rectangle(p, 0.1 + 0.05 * (f * 0.5).fract(), i % 8 == 2),
                )
                .unwrap(),
            ),
            _ => Box::new(
                AreaLight::new(
                    Rgb::splat(power),
                    EmitterShape {
                        triangles: Vec::new(),
                        spheres: vec![(p, 0.05)],
                    },
                )
                .unwrap(),
            ),
        });
    }
    lights
}

#[test]
fn the_light_tree_picks_lights_with_the_probability_it_reports() {
    let lights = many_lights();
    assert!(lights.len() > FLAT_LIMIT);
    let table = LightTable::new(lights, LightSelection::Spatial);
    for (k, p) in POINTS.iter().enumerate() {
        check_table(&table, *p, 71 + k as u64);
    }
}

#[test]
fn lights_without_bounds_keep_a_fixed_share() {
    let sphere = BoundingSphere {
        centre: Vec3::ZERO,
        radius: 10.0,
    };
    let mut lights = bounded_lights();
    lights.push(Box::new(DirectionalLight::new(
        Vec3::new(0.3, -1.0, 0.2).normalize(),
        Rgb::splat(1.0),
        sphere,
    )));
    let table = LightTable::new(lights, LightSelection::Spatial);
    let sun = table.len() - 1;
    for (k, p) in POINTS.iter().enumerate() {
        // One unbounded light beside the bounded ones: pbrt-v4's 1/2.
        assert_eq!(table.pmf_at(*p, sun), 0.5);
        check_table(&table, *p, 41 + k as u64);
    }
}

#[test]
fn a_light_of_zero_importance_sends_nothing_to_the_point() {
    let lights = bounded_lights();
    let mut rng = Rng::new(5);
    let mut zeros = 0;
    for _ in 0..4000 {
        let p = Vec3::new(
            rng.uniform() * 8.0 - 4.0,
            rng.uniform() * 8.0 - 4.0,
            rng.uniform() * 8.0 - 4.0,
        );
        for light in &lights {
            let bounds = light.bounds().expect("bounded light");
            if bounds.importance(p) > 0.0 {
                continue;
            }
            zeros += 1;
            let refs = [p; 16];
            let u: Vec<Vec2> = (0..16).map(|_| rng.next_2d()).collect();
            let mut out = [LightSample::default(); 16];
            light.sample(&refs, &u, &mut out);
            for s in out {
                // Emission reaches p only from the emitting side.
                let reaches = s.pdf > 0.0
                    && s.radiance != Rgb::ZERO
                    && (s.n == Vec3::ZERO || s.n.dot(p - s.p) > 0.0);
                assert!(
                    !reaches,
                    "importance 0 at {p}, but a sample reaches it: {s:?}"
                );
            }
        }
    }
    // The scene has points behind the one-sided lights and outside the spot.
    assert!(
        zeros > 1000,
        "only {zeros} zero-importance cases were tested"
    );
}

/// A floor and a ball lit directly by a spot light, a point light and a
/// small rectangle light. (The choice among three lights of very different
/// contributions is itself the main noise: two seeds of power selection
/// differ by 0.46 % in the mean at 256 spp, so the test takes 2048.)
fn three_lights(light_scale: f32) -> String {
    format!(
        "integrator: {{type: path, max_depth: 2}}
film: {{width: 40, height: 40, filter: {{type: box}}}}
sampler: {{type: independent, spp: 2048}}
camera: {{type: perspective, fov: 50, look_at: {{origin: [0, 3, 4], target: [0, 0, 0], up: [0, 1, 0]}}}}
materials:
  grey: {{type: diffuse, reflectance: 0.6}}
shapes:
  - {{type: rectangle, material: grey, transform: [{{rotate: {{axis: [1, 0, 0], angle: -90}}}}, {{scale: 3}}]}}
  - {{type: sphere, center: [0.3, 0.4, 0], radius: 0.4, material: grey}}
  - type: rectangle
    material: grey
    transform: [{{translate: [-1, 2, -0.5]}}, {{rotate: {{axis: [1, 0, 0], angle: 90}}}}, {{scale: 0.2}}]
    emitter: {{type: area, radiance: [{r}, {r}, {r}]}}
lights:
  - {{type: spot, position: [1, 3, 1], target: [0, 0, 0], intensity: [30, 28, 25], cutoff_angle: 30}}
  - {{type: point, position: [-3, 2, -3], intensity: [20, 20, 22]}}
",
        r = 40.0 * light_scale
    )
}

fn render_text(text: &str, selection: LightSelection, seed: u64) -> Image {
    let dir = root().join("scenes");
    let scene =
        radiant::scene::from_str(text, &dir.join("three-lights.yaml"), &dir).expect("scene parses");
    let overrides = Overrides {
        light_selection: Some(selection),
        seed: Some(seed),
        ..Overrides::default()
    };
    let r = extract(&scene, &radiant::builtin_registry(), &overrides).expect("scene extracts");
    render(&r, &Progress::none()).image
}

/// The largest relative difference of the channel means.
fn mean_difference(a: &Image, b: &Image) -> f64 {
    let (a, b) = (channel_means(a), channel_means(b));
    (0..3)
        .map(|c| (a[c] - b[c]).abs() / b[c])
        .fold(0.0, f64::max)
}

#[test]
fn spatial_selection_renders_what_power_selection_renders() {
    let power = render_text(&three_lights(1.0), LightSelection::Power, 1);
    let spatial = render_text(&three_lights(1.0), LightSelection::Spatial, 2);
    let brighter = render_text(&three_lights(1.02 * 1.02), LightSelection::Spatial, 3);
    let same = mean_difference(&spatial, &power);
    let off = mean_difference(&brighter, &power);
    eprintln!("spatial vs power: {same:.4}; light 4 % brighter: {off:.4}");
    assert!(
        same < 0.006,
        "spatial selection changes the image by {same}"
    );
    assert!(off > 0.006, "a 4 % brighter area light is not seen ({off})");
}
