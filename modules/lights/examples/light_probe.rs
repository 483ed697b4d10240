//! Times the lights' per-sample entry points on their own, as the suite's
//! scenes use them, so that a change to a sampling routine can be measured
//! (and counted with callgrind) without rendering:
//!
//! ```text
//! cargo run --release -p radiant-lights --example light_probe [ROUNDS [CASE]]
//! ```
//!
//! Cases: the Cornell box's ceiling rectangle seen from points in the box
//! (mostly sampled by area), a rectangle seen from close by (by solid
//! angle), Veach's four spheres (by solid angle), the sky map (`sample` and
//! `eval_escaped`). Each prints nanoseconds per sample over batches of
//! 4096, and a checksum of the outputs so that runs can be compared; with
//! CASE, only the cases whose names contain it run (for callgrind:
//! `--toggle-collect='*Light>::*'` counts the light's instructions alone).

use radiant_core::glam::{DMat4, Vec2, Vec3};
use radiant_core::{
    BoundingSphere, BuildContext, EmitterEval, EmitterHit, EmitterShape, Light, LightSample,
    Params, Registry, Rgb, TextureTable,
};
use radiant_lights::AreaLight;
use std::collections::HashMap;
use std::hint::black_box;
use std::path::Path;
use std::time::Instant;

const BATCH: usize = 4096;

/// A reproducible stream of numbers in [0, 1) (a 32-bit xorshift).
struct Uniform(u32);

impl Uniform {
    fn next(&mut self) -> f32 {
        self.0 ^= self.0 << 13;
        self.0 ^= self.0 >> 17;
        self.0 ^= self.0 << 5;
        (self.0 >> 8) as f32 / (1u32 << 24) as f32
    }

    fn in_box(&mut self, min: Vec3, max: Vec3) -> Vec3 {
        min + (max - min) * Vec3::new(self.next(), self.next(), self.next())
    }
}

/// The rectangle (a, b, c, d) as two triangles, as the `rectangle` shape
/// tessellates it.
fn rectangle(a: Vec3, b: Vec3, c: Vec3, d: Vec3) -> EmitterShape {
    EmitterShape {
        triangles: vec![[a, b, c], [a, c, d]],
        spheres: Vec::new(),
    }
}

/// Runs `f` over `rounds` batches and prints ns per sample, if `name`
/// contains `only`, and the checksum `f(true)` returns after them (`f`
/// hashes its outputs only when asked, outside the timing).
fn time(name: &str, (rounds, only): (usize, &str), mut f: impl FnMut(bool) -> u64) {
    if !name.contains(only) {
        return;
    }
    f(false);
    let start = Instant::now();
    for _ in 0..rounds {
        black_box(f(false));
    }
    let ns = start.elapsed().as_secs_f64() * 1e9 / (rounds * BATCH) as f64;
    let check = f(true);
    println!("{name:<28} {ns:7.2} ns/sample   checksum {check:016x}");
}

/// A hash of the bits of `values`, to tell whether two builds agree.
fn hash(values: impl Iterator<Item = f32>) -> u64 {
    values.fold(0xcbf2_9ce4_8422_2325, |h, v| {
        (h ^ v.to_bits() as u64).wrapping_mul(0x100_0000_01b3)
    })
}

fn hash_samples(out: &[LightSample]) -> u64 {
    hash(out.iter().flat_map(|s| {
        [s.p.to_array(), s.n.to_array(), s.radiance.to_array()]
            .into_iter()
            .flatten()
            .chain([s.pdf])
    }))
}

fn hash_evals(evals: &[EmitterEval]) -> u64 {
    hash(
        evals
            .iter()
            .flat_map(|e| e.radiance.to_array().into_iter().chain([e.pdf])),
    )
}

/// Samples `lights` from `refs`, each light a quarter of the batch.
fn sample_all(lights: &[Box<dyn Light>], refs: &[Vec3], u: &[Vec2], out: &mut [LightSample]) {
    let chunk = refs.len().div_ceil(lights.len());
    for (i, light) in lights.iter().enumerate() {
        let r = i * chunk..((i + 1) * chunk).min(refs.len());
        light.sample(&refs[r.clone()], &u[r.clone()], &mut out[r]);
    }
}

fn main() -> Result<(), String> {
    let args: Vec<String> = std::env::args().collect();
    let count: usize = match args.get(1) {
        Some(a) => a.parse().map_err(|e| format!("ROUNDS: {e}"))?,
        None => 500,
    };
    let rounds = (count, args.get(2).map_or("", String::as_str));
    let mut rng = Uniform(0x9e37_79b9);
    let u: Vec<Vec2> = (0..BATCH)
        .map(|_| Vec2::new(rng.next(), rng.next()))
        .collect();
    let mut out = vec![LightSample::default(); BATCH];

    // The Cornell box's light, seen from anywhere in the box.
    let y = 0.99;
    let cornell = AreaLight::new(
        Rgb::new(18.4, 14.0, 6.75),
        rectangle(
            Vec3::new(-0.23, y, -0.18),
            Vec3::new(0.23, y, -0.18),
            Vec3::new(0.23, y, 0.2),
            Vec3::new(-0.23, y, 0.2),
        ),
    )?;
    // Points of the box farther from the light than it samples by solid
    // angle, as nearly all of the box's surfaces are.
    let centre = Vec3::new(0.0, y, 0.01);
    let in_box: Vec<Vec3> =
        std::iter::repeat_with(|| rng.in_box(Vec3::splat(-1.0), Vec3::new(1.0, 0.98, 1.0)))
            .filter(|p| p.distance(centre) > 0.9)
            .take(BATCH)
            .collect();
    time("area rectangle, far", rounds, |hash| {
        cornell.sample(&in_box, &u, &mut out);
        if hash { hash_samples(&out) } else { 0 }
    });
    let near: Vec<Vec3> = std::iter::repeat_with(|| {
        rng.in_box(Vec3::new(-0.5, 0.5, -0.5), Vec3::new(0.5, 0.98, 0.5))
    })
    .filter(|p| p.distance(centre) < 0.8)
    .take(BATCH)
    .collect();
    time("area rectangle, near", rounds, |hash| {
        cornell.sample(&near, &u, &mut out);
        if hash { hash_samples(&out) } else { 0 }
    });

    // Veach's plates: four spheres of very different radii.
    let spheres: Vec<Box<dyn Light>> = [(-2.6, 0.03), (-1.1, 0.1), (0.5, 0.25), (2.2, 0.6)]
        .iter()
        .map(|&(x, r)| {
            let shape = EmitterShape {
                triangles: Vec::new(),
                spheres: vec![(Vec3::new(x, 2.6, -2.0), r)],
            };
            AreaLight::new(Rgb::splat(10.0), shape).map(|l| Box::new(l) as Box<dyn Light>)
        })
        .collect::<Result<_, _>>()?;
    let scene: Vec<Vec3> = (0..BATCH)
        .map(|_| rng.in_box(Vec3::new(-4.0, -0.2, -3.0), Vec3::new(4.0, 2.0, 4.0)))
        .collect();
    time("area spheres", rounds, |hash| {
        sample_all(&spheres, &scene, &u, &mut out);
        if hash { hash_samples(&out) } else { 0 }
    });

    // Hits on the Cornell light from points in the box.
    let hits: Vec<EmitterHit> = in_box
        .iter()
        .zip(&u)
        .map(|(&origin, u)| EmitterHit {
            origin,
            p: Vec3::new(-0.23 + 0.46 * u.x, y, -0.18 + 0.38 * u.y),
            n: Vec3::NEG_Y,
            primitive: (u.x * 2.0) as u32,
        })
        .collect();
    let mut evals = vec![EmitterEval::default(); BATCH];
    time("area rectangle, eval_hits", rounds, |hash| {
        cornell.eval_hits(&hits, &mut evals);
        if hash { hash_evals(&evals) } else { 0 }
    });

    // The sky map of scenes/environment.yaml, turned as textured-env turns it.
    let mut registry = Registry::new();
    radiant_lights::register(&mut registry);
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../scenes");
    let mut textures = TextureTable::default();
    let named = HashMap::new();
    let mut ctx = BuildContext::standalone(&dir, &mut textures, &named);
    ctx.scene_sphere = BoundingSphere {
        centre: Vec3::ZERO,
        radius: 5.0,
    };
    ctx.to_world = DMat4::from_rotation_y(60f64.to_radians());
    let params = Params::from_yaml("{filename: environment-sky.exr}").map_err(|e| e.to_string())?;
    let sky = registry
        .build::<dyn Light>("environment", &params, &mut ctx)
        .map_err(|e| e.to_string())?;
    time("environment sample", rounds, |hash| {
        sky.sample(&in_box, &u, &mut out);
        if hash { hash_samples(&out) } else { 0 }
    });
    let dirs: Vec<Vec3> = u
        .iter()
        .map(|u| radiant_core::warp::square_to_uniform_sphere(*u))
        .collect();
    time("environment eval_escaped", rounds, |hash| {
        sky.eval_escaped(&dirs, &mut evals);
        if hash { hash_evals(&evals) } else { 0 }
    });
    Ok(())
}
