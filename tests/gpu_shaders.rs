//! Every shader's WGSL holds to its Rust implementation: the same random
//! inputs (outgoing directions on the whole sphere, below the horizon
//! too, texture coordinates, sample numbers, incident directions on the
//! whole sphere and in the sampled lobes) through `Shader::sample` and
//! `Shader::eval` on the CPU and through the shader's WGSL in a probe
//! kernel, compared field by field at float precision.
//!
//! Sampling makes branch decisions (which lobe, total internal reflection,
//! a direction just below the horizon) that a rounding difference can flip
//! where the decision sits at its threshold, so a few records (at most
//! 0.5 %) may disagree; every other record must agree to a relative 1e-3
//! (plus 1e-5 absolute). Each case also checks that the comparison would
//! notice a 2 % error in the weights and values, and one test that a probe
//! body scaling the sample weight by 1.02 fails it.
//!
//! Two configurations are ill-conditioned in single precision whichever
//! side computes them, and are held to looser tolerances
//! ([`ill_conditioned`]).

use glam::{Vec2, Vec3};
use radiant::backend::gpu::probe::{Probe, ProbeKind};
use radiant::extract::{Overrides, RenderScene, extract};
use radiant_core::{BsdfEval, BsdfSample, GpuModule, ShadeContext, SurfaceBatch};
use radiant_tests::SplitMix as Rng;
use radiant_tests::gpu::backend;
use std::fmt::Write;
use std::path::Path;

/// Random records per shader configuration (a few special ones are added).
const RECORDS: usize = 4096;

/// Floats per input record: wo, uv, u, wi, ∂p/∂u, ∂p/∂v.
const INPUTS: usize = 17;

/// Floats per output record: the sample's wi, weight, pdf, delta and eta,
/// then the evaluation's value and pdf.
const OUTPUTS: usize = 13;

/// Names of the output fields, for failure messages.
const FIELDS: [&str; OUTPUTS] = [
    "sample.wi.x",
    "sample.wi.y",
    "sample.wi.z",
    "sample.weight.r",
    "sample.weight.g",
    "sample.weight.b",
    "sample.pdf",
    "sample.delta",
    "sample.eta",
    "eval.value.r",
    "eval.value.g",
    "eval.value.b",
    "eval.pdf",
];

/// Relative tolerance of a field.
const RELATIVE: f32 = 1e-3;

/// The 2 % error that every comparison at [`RELATIVE`] must notice.
const POWER: f32 = 0.02;

/// Absolute tolerance of a field.
const ABSOLUTE: f32 = 1e-5;

/// Share of records allowed to disagree (branch decisions at a threshold).
const ALLOWED: f64 = 0.005;

/// One input record.
#[derive(Debug, Clone, Copy)]
struct Record {
    wo: Vec3,
    uv: Vec2,
    u: Vec3,
    wi: Vec3,
    dp_du: Vec3,
    dp_dv: Vec3,
}

/// The scene holding `materials` as `m0`, `m1`, …, extracted, with the
/// image textures `ridges` (a height field) and `bumps` (a normal map) of
/// `data/tangents` for them to read.
fn scene(materials: &[&str]) -> RenderScene {
    let mut text = String::from(
        "camera: {type: perspective, fov: 45, look_at: {origin: [0, 0, 3], target: [0, 0, 0], up: [0, 1, 0]}}
textures:
  ridges: {type: image, filename: ridges-height.png, raw: true}
  bumps: {type: image, filename: ridges-normals.png, raw: true}
materials:\n",
    );
    for (i, m) in materials.iter().enumerate() {
        let _ = writeln!(text, "  m{i}: {m}");
    }
    text += "shapes:\n  - {type: sphere, center: [0, 0, 0], radius: 1, material: m0}\n";
    let data = Path::new(env!("CARGO_MANIFEST_DIR")).join("data/tangents");
    let loaded = radiant::scene::from_str(&text, Path::new("gpu_shaders.yaml"), &data)
        .unwrap_or_else(|e| panic!("the test scene parses: {e}\n{text}"));
    extract(&loaded, &radiant::builtin_registry(), &Overrides::default())
        .unwrap_or_else(|e| panic!("the test scene extracts: {e}\n{text}"))
}

/// The CPU's outputs for `records` (sampling with `u`, evaluating at `wi`).
fn cpu(scene: &RenderScene, m: usize, records: &[Record]) -> Vec<[f32; OUTPUTS]> {
    let shader = &scene.shaders[m];
    let wo: Vec<Vec3> = records.iter().map(|r| r.wo).collect();
    let uv: Vec<Vec2> = records.iter().map(|r| r.uv).collect();
    let u: Vec<Vec3> = records.iter().map(|r| r.u).collect();
    let wi: Vec<Vec3> = records.iter().map(|r| r.wi).collect();
    let dp_du: Vec<Vec3> = records.iter().map(|r| r.dp_du).collect();
    let dp_dv: Vec<Vec3> = records.iter().map(|r| r.dp_dv).collect();
    let mut ctx = ShadeContext::new(&scene.textures);
    let surface = SurfaceBatch {
        wo: &wo,
        uv: &uv,
        dp_du: &dp_du,
        dp_dv: &dp_dv,
    };
    let mut samples = vec![BsdfSample::default(); records.len()];
    shader.sample(&mut ctx, surface, &u, &mut samples);
    let mut evals = vec![BsdfEval::default(); records.len()];
    shader.eval(&mut ctx, surface, &wi, &mut evals);
    samples
        .iter()
        .zip(&evals)
        .map(|(s, e)| {
            [
                s.wi.x,
                s.wi.y,
                s.wi.z,
                s.weight.x,
                s.weight.y,
                s.weight.z,
                s.pdf,
                if s.delta { 1.0 } else { 0.0 },
                s.eta,
                e.value.x,
                e.value.y,
                e.value.z,
                e.pdf,
            ]
        })
        .collect()
}

/// The probe body: sample and evaluate the shader `ident`, with `tamper`
/// (WGSL that may change the sample `r`) in between.
fn body(ident: &str, tamper: &str) -> String {
    format!(
        "let s = ShadingPoint(vec3f(input(i, 0u), input(i, 1u), input(i, 2u)), vec2f(input(i, 3u), input(i, 4u)), vec3f(input(i, 11u), input(i, 12u), input(i, 13u)), vec3f(input(i, 14u), input(i, 15u), input(i, 16u)));
let u = vec3f(input(i, 5u), input(i, 6u), input(i, 7u));
let wi = vec3f(input(i, 8u), input(i, 9u), input(i, 10u));
var r = bsdf_sample_{ident}(P, s, u);
{tamper}
let e = bsdf_eval_{ident}(P, s, wi);
output(i, 0u, r.wi.x);
output(i, 1u, r.wi.y);
output(i, 2u, r.wi.z);
output(i, 3u, r.weight.x);
output(i, 4u, r.weight.y);
output(i, 5u, r.weight.z);
output(i, 6u, r.pdf);
output(i, 7u, select(0.0, 1.0, r.delta));
output(i, 8u, r.eta);
output(i, 9u, e.value.x);
output(i, 10u, e.value.y);
output(i, 11u, e.value.z);
output(i, 12u, e.pdf);"
    )
}

/// The GPU's outputs for `records` through the probe, with `tamper` in
/// the body.
fn gpu(
    scene: &RenderScene,
    module: &GpuModule,
    records: &[Record],
    tamper: &str,
) -> Vec<[f32; OUTPUTS]> {
    let inputs: Vec<f32> = records
        .iter()
        .flat_map(|r| {
            [
                r.wo.x, r.wo.y, r.wo.z, r.uv.x, r.uv.y, r.u.x, r.u.y, r.u.z, r.wi.x, r.wi.y,
                r.wi.z, r.dp_du.x, r.dp_du.y, r.dp_du.z, r.dp_dv.x, r.dp_dv.y, r.dp_dv.z,
            ]
        })
        .collect();
    let plain = body(&module.ident, tamper);
    let run = |body: &str| {
        let probe = Probe {
            module: module.clone(),
            kind: ProbeKind::Shader,
            textures: &scene.textures,
            body,
            inputs_per_record: INPUTS,
            outputs_per_record: OUTPUTS,
        };
        backend().probe(&probe, &inputs)
    };
    let out = run(&plain).unwrap_or_else(|e| panic!("the probe of `{}` runs: {e}", module.ident));
    assert_eq!(out.len(), records.len() * OUTPUTS, "probe output size");
    out.chunks(OUTPUTS)
        .map(|c| {
            let mut o = [0.0; OUTPUTS];
            o.copy_from_slice(c);
            o
        })
        .collect()
}

/// The records of a case: random ones, and a few special ones (normal
/// incidence from both sides, grazing, u at 0). Surface derivatives are
/// random vectors of lengths 0.1 to 2. Incident directions for
/// evaluation are uniform on the sphere for even records and the CPU's
/// sampled direction (in the lobe) for odd ones, so that narrow lobes are
/// evaluated where they are not zero.
fn records(scene: &RenderScene, m: usize, seed: u64) -> Vec<Record> {
    let mut rng = Rng(seed);
    let mut recs: Vec<Record> = (0..RECORDS)
        .map(|_| Record {
            wo: rng.sphere(),
            uv: Vec2::new(rng.unit(), rng.unit()),
            u: Vec3::new(rng.unit(), rng.unit(), rng.unit()),
            wi: rng.sphere(),
            dp_du: rng.sphere() * (0.1 + 1.9 * rng.unit()),
            dp_dv: rng.sphere() * (0.1 + 1.9 * rng.unit()),
        })
        .collect();
    let specials = [
        (Vec3::Z, Vec3::splat(0.5), Vec3::Z),
        (-Vec3::Z, Vec3::splat(0.5), -Vec3::Z),
        (Vec3::X, Vec3::splat(0.5), Vec3::Z),
        (
            Vec3::new(0.6, 0.0, 0.8),
            Vec3::ZERO,
            Vec3::new(-0.6, 0.0, 0.8),
        ),
        (
            Vec3::new(0.0, 0.6, -0.8),
            Vec3::ZERO,
            Vec3::new(0.0, -0.6, 0.8),
        ),
        (
            Vec3::new(0.6, 0.0, 0.8),
            Vec3::splat(0.999),
            Vec3::new(0.6, 0.0, -0.8),
        ),
    ];
    for (wo, u, wi) in specials {
        recs.push(Record {
            wo,
            uv: Vec2::splat(0.5),
            u,
            wi,
            dp_du: Vec3::X,
            dp_dv: Vec3::Y,
        });
    }
    let sampled = cpu(scene, m, &recs);
    for (i, (r, s)) in recs.iter_mut().zip(&sampled).enumerate() {
        let wi = Vec3::new(s[0], s[1], s[2]);
        if i % 2 == 1 && i < RECORDS && wi != Vec3::ZERO {
            r.wi = wi;
        }
    }
    recs
}

/// How far apart two values are, in units of the tolerance with relative
/// part `relative` (above 1: they disagree; NaN anywhere: infinitely far).
fn distance(a: f32, b: f32, relative: f32) -> f32 {
    if a.is_nan() || b.is_nan() {
        return f32::INFINITY;
    }
    if a == b {
        return 0.0;
    }
    (a - b).abs() / (relative * a.abs().max(b.abs()) + ABSOLUTE)
}

/// The outcome of comparing the CPU's outputs with the GPU's.
struct Comparison {
    /// Records that disagree.
    disagree: usize,
    /// Records compared.
    total: usize,
    /// A report of the worst records.
    report: String,
}

impl Comparison {
    fn passes(&self) -> bool {
        (self.disagree as f64) <= ALLOWED * self.total as f64
    }
}

/// Compares the outputs at relative tolerance `relative`.
fn compare(
    records: &[Record],
    cpu: &[[f32; OUTPUTS]],
    gpu: &[[f32; OUTPUTS]],
    relative: f32,
) -> Comparison {
    let mut worst: Vec<(f32, usize, usize)> = Vec::new();
    for (i, (c, g)) in cpu.iter().zip(gpu).enumerate() {
        let (d, field) = (0..OUTPUTS)
            .map(|k| {
                // `delta` is a flag: any difference disagrees.
                let d = if k == 7 && c[k] != g[k] {
                    f32::INFINITY
                } else {
                    distance(c[k], g[k], relative)
                };
                (d, k)
            })
            .fold((0.0f32, 0usize), |a, b| if b.0 > a.0 { b } else { a });
        if d > 1.0 {
            worst.push((d, i, field));
        }
    }
    worst.sort_by(|a, b| b.0.total_cmp(&a.0));
    let mut report = String::new();
    for &(d, i, k) in worst.iter().take(8) {
        let r = &records[i];
        let _ = writeln!(
            report,
            "  record {i}: {} differs by {d:.3e} tolerances (wo {:?}, uv {:?}, u {:?}, wi {:?})\n    cpu {:?}\n    gpu {:?}",
            FIELDS[k], r.wo, r.uv, r.u, r.wi, cpu[i], gpu[i]
        );
    }
    Comparison {
        disagree: worst.len(),
        total: cpu.len(),
        report,
    }
}

/// The GPU outputs with every weight and value scaled by `s`.
fn scaled(out: &[[f32; OUTPUTS]], s: f32) -> Vec<[f32; OUTPUTS]> {
    out.iter()
        .map(|o| {
            let mut o = *o;
            for k in [3, 4, 5, 9, 10, 11] {
                o[k] *= s;
            }
            o
        })
        .collect()
}

/// Checks every material of `materials` (YAML of one shader each): the
/// GPU agrees with the CPU, and would not with a 2 % error.
fn agree(materials: &[&str]) {
    agree_within(materials, RELATIVE, POWER);
}

/// Checks every material of `materials` at relative tolerance `relative`,
/// and that an error of `power` in the weights and values would be
/// noticed (where enough records carry a weight or a value: not for a
/// black material).
fn agree_within(materials: &[&str], relative: f32, power: f32) {
    let scene = scene(materials);
    let mut failures = String::new();
    for (j, yaml) in materials.iter().enumerate() {
        let name = format!("m{j}");
        let m = scene
            .material_names
            .iter()
            .position(|n| *n == name)
            .unwrap_or_else(|| panic!("material {name} is in the scene"));
        let module = scene.shaders[m]
            .gpu()
            .unwrap_or_else(|| panic!("{yaml} has a GPU side"));
        let recs = records(&scene, m, 0x5eed + j as u64);
        let c = cpu(&scene, m, &recs);
        let g = gpu(&scene, &module, &recs, "");
        let result = compare(&recs, &c, &g, relative);
        let zero = c.iter().filter(|o| o[3..6] == [0.0; 3]).count();
        let carrying = c
            .iter()
            .filter(|o| [3, 4, 5, 9, 10, 11].iter().any(|&k| o[k].abs() > 1e-3))
            .count();
        eprintln!(
            "{yaml}: {} of {} records disagree ({} samples of zero weight on the CPU)\n{}",
            result.disagree, result.total, zero, result.report
        );
        if !result.passes() {
            let _ = writeln!(
                failures,
                "{yaml}: {} of {} records disagree; the worst:\n{}",
                result.disagree, result.total, result.report
            );
        }
        if carrying as f64 > 2.0 * ALLOWED * c.len() as f64 {
            for s in [1.0 - power, 1.0 + power] {
                assert!(
                    !compare(&recs, &c, &scaled(&g, s), relative).passes(),
                    "{yaml}: the comparison would not notice a {s}× error"
                );
            }
        }
    }
    assert!(
        failures.is_empty(),
        "the GPU disagrees with the CPU:\n{failures}"
    );
}

#[test]
fn diffuse() {
    agree(&[
        "{type: diffuse, reflectance: 0.8}",
        "{type: diffuse, reflectance: [0.9, 0.5, 0.1]}",
        "{type: diffuse, reflectance: 0}",
    ]);
}

#[test]
fn conductor() {
    agree(&[
        "{type: conductor}",
        "{type: conductor, material: Au}",
        "{type: conductor, material: none, specular_reflectance: [0.9, 0.6, 0.3], alpha: 0.5}",
        "{type: conductor, material: Au, alpha: 0.2}",
        "{type: conductor, material: Cu, alpha_u: 0.4, alpha_v: 0.02}",
        "{type: conductor, eta: [0.2, 0.9, 1.1], k: [3.9, 2.4, 2.1], alpha: 0.001}",
        "{type: conductor, material: Al, alpha: 1}",
    ]);
}

#[test]
fn dielectric() {
    agree(&[
        "{type: dielectric}",
        "{type: dielectric, int_ior: 1.33, specular_reflectance: [0.9, 0.8, 0.7], specular_transmittance: [0.5, 0.6, 0.7]}",
        "{type: dielectric, int_ior: 1, ext_ior: 1, alpha: 0.3}",
        "{type: dielectric, alpha: 0.3}",
        "{type: dielectric, int_ior: 3, alpha: 0.001}",
        "{type: dielectric, int_ior: 1.01, ext_ior: 1, alpha: 0.5}",
        "{type: dielectric, alpha_u: 0.5, alpha_v: 0.05, specular_transmittance: [0.9, 0.8, 0.7]}",
        "{type: dielectric, int_ior: 1.2, ext_ior: 1.5, alpha: 1}",
    ]);
}

#[test]
fn thin_dielectric() {
    agree(&[
        "{type: thin_dielectric}",
        "{type: thin_dielectric, int_ior: 1.33, specular_reflectance: [0.9, 0.8, 0.7], specular_transmittance: [0.5, 0.6, 0.7]}",
        "{type: thin_dielectric, int_ior: 1, ext_ior: 1}",
    ]);
}

#[test]
fn plastic() {
    agree(&[
        "{type: plastic}",
        "{type: plastic, nonlinear: true, diffuse_reflectance: [0.9, 0.3, 0.1]}",
        "{type: plastic, alpha: 0.2, nonlinear: true}",
        "{type: plastic, alpha: 0.05, int_ior: 1.8, diffuse_reflectance: [0.9, 0.3, 0.1], specular_reflectance: 0.7}",
        "{type: plastic, alpha: 0.6, diffuse_reflectance: 0, specular_reflectance: 0}",
    ]);
}

#[test]
fn rough_diffuse() {
    agree(&[
        "{type: rough_diffuse}",
        "{type: rough_diffuse, reflectance: 0.8, alpha: 0.6}",
        "{type: rough_diffuse, reflectance: [0.9, 0.5, 0.1], alpha: 0}",
        "{type: rough_diffuse, reflectance: [0.2, 0.5, 0.9], alpha: 1}",
    ]);
}

#[test]
fn principled() {
    agree(&[
        "{type: principled}",
        "{type: principled, metallic: 1, roughness: 0.03, base_color: [0.9, 0.6, 0.3]}",
        "{type: principled, transmission: 1, roughness: 0.2}",
        "{type: principled, metallic: 0.3, transmission: 0.5, roughness: 0.7, specular: 0.8, base_color: [0.2, 0.7, 0.4]}",
        "{type: principled, roughness: 0, specular: 0, base_color: 0}",
        "{type: principled, transmission: 1, roughness: 1, specular: 0}",
    ]);
}

#[test]
fn ward() {
    agree(&[
        "{type: ward}",
        "{type: ward, alpha_u: 0.3, alpha_v: 0.05, diffuse_reflectance: [0.5, 0.3, 0.1], specular_reflectance: [0.3, 0.4, 0.5]}",
        "{type: ward, diffuse_reflectance: 0, specular_reflectance: 0}",
        "{type: ward, alpha_u: 0.001, alpha_v: 0.001, diffuse_reflectance: 0.2, specular_reflectance: 0.8}",
        "{type: ward, alpha_u: 1, alpha_v: 1}",
    ]);
}

#[test]
fn ashikhmin_shirley() {
    agree(&[
        "{type: ashikhmin_shirley}",
        "{type: ashikhmin_shirley, exponent_u: 10, exponent_v: 1000, diffuse_reflectance: [0.5, 0.3, 0.1], specular_reflectance: [0.3, 0.4, 0.5]}",
        "{type: ashikhmin_shirley, exponent_u: 0, exponent_v: 0}",
        "{type: ashikhmin_shirley, exponent_u: 10000, exponent_v: 3000, diffuse_reflectance: 0}",
    ]);
}

#[test]
fn blend() {
    agree(&[
        "{type: blend, weight: 0.3, materials: [{type: diffuse, reflectance: 0.8}, {type: conductor, material: Au, alpha: 0.2}]}",
        "{type: blend, weight: 0.7, materials: [{type: dielectric}, {type: plastic, alpha: 0.1}]}",
        "{type: blend, weight: [0.2, 0.5, 0.5], materials: [{type: blend, weight: 0.6, materials: [{type: diffuse}, {type: ward}]}, {type: principled, transmission: 0.5}]}",
        "{type: blend, weight: 0, materials: [{type: rough_diffuse}, {type: thin_dielectric}]}",
        "{type: blend, weight: 1, materials: [{type: rough_diffuse}, {type: dielectric, alpha: 0.4}]}",
        "{type: blend, materials: [{type: blend, materials: [{type: diffuse}, {type: ashikhmin_shirley}]}, {type: blend, materials: [{type: diffuse}, {type: ashikhmin_shirley}]}]}",
    ]);
}

/// Configurations whose sampling is ill-conditioned in single precision,
/// whichever side computes it, held to looser tolerances:
///
/// * an index of 1.0001: the refraction Jacobian divides by
///   (wo·m + η wi·m)² ≈ ((η² − 1)/2 cos)², a difference of two numbers
///   near cos θ that keeps only about three significant digits in f32, so
///   a sampled density differs by up to 0.5 % with the normal's last bits;
/// * Phong exponents of 1e5: the sampled half vector's sin θ comes from
///   1 − cos θ ≈ 1e-5, which f32 resolves to 0.6 % next to 1, and the
///   density cos^1e5 θ turns a one-ulp change of cos θ into 0.6 % (a
///   sampled density differs by up to 2 %).
#[test]
fn ill_conditioned() {
    agree_within(
        &["{type: dielectric, int_ior: 1.0001, ext_ior: 1, alpha: 0.5}"],
        1e-2,
        0.05,
    );
    agree_within(
        &[
            "{type: ashikhmin_shirley, exponent_u: 100000, exponent_v: 100000, diffuse_reflectance: 0}",
        ],
        5e-2,
        0.2,
    );
}

/// A scene whose kernel holds blends, nested blends (also by name) and
/// their parts as materials of their own compiles and renders: each
/// type's code is in the kernel once, and a nested blend's code is renamed
/// inside the blend that holds it.
#[test]
fn blends_and_their_parts_share_one_kernel() {
    let mut text = String::from(
        "camera: {type: perspective, fov: 45, look_at: {origin: [0, 0, 4], target: [0, 0, 0], up: [0, 1, 0]}}
lights:
  - {type: point, position: [0, 2, 3], intensity: 20}
materials:
  a: {type: diffuse}
  b: {type: blend, materials: [a, {type: ward}]}
  c: {type: blend, weight: 0.3, materials: [b, {type: principled, transmission: 0.5}]}
  d: {type: blend, materials: [b, b]}
  e: {type: ward, alpha_u: 0.2, alpha_v: 0.2}
shapes:
",
    );
    for (i, m) in ["a", "b", "c", "d", "e"].iter().enumerate() {
        let _ = writeln!(
            text,
            "  - {{type: sphere, center: [{}, 0, 0], radius: 0.4, material: {m}}}",
            i as f32 - 2.0
        );
    }
    let loaded = radiant::scene::from_str(&text, Path::new("blends.yaml"), Path::new("."))
        .unwrap_or_else(|e| panic!("the test scene parses: {e}"));
    let overrides = Overrides {
        width: Some(16),
        height: Some(8),
        spp: Some(4),
        ..Overrides::default()
    };
    let scene = extract(&loaded, &radiant::builtin_registry(), &overrides)
        .unwrap_or_else(|e| panic!("the test scene extracts: {e}"));
    let rendered = backend()
        .render(&scene, &radiant::backend::cpu::Progress::none())
        .unwrap_or_else(|e| panic!("the GPU renders the blends: {e}"));
    assert_eq!(rendered.invalid_samples, 0, "NaN or infinite samples");
    let sum: f32 = rendered.image.pixels.iter().map(|p| p.x + p.y + p.z).sum();
    assert!(sum > 0.0, "the spheres are lit");
}

#[test]
fn normal_map() {
    agree(&[
        "{type: normal_map, normals: bumps, material: {type: diffuse, reflectance: 0.8}}",
        "{type: normal_map, normals: [0.75, 0.4, 0.85], material: {type: conductor, material: Cu, alpha_u: 0.4, alpha_v: 0.05}}",
        "{type: normal_map, normals: bumps, flip_invalid_normals: false, use_shadowing_function: false, material: {type: plastic, alpha: 0.1}}",
        "{type: normal_map, normals: bumps, material: {type: dielectric, alpha: 0.3}}",
    ]);
}

#[test]
fn bump() {
    agree(&[
        "{type: bump, height: ridges, scale: 0.1, material: {type: diffuse, reflectance: [0.7, 0.5, 0.3]}}",
        "{type: bump, height: ridges, scale: -0.02, material: {type: conductor, material: Au, alpha: 0.2}}",
        "{type: bump, height: ridges, scale: 0.05, use_shadowing_function: false, material: {type: ward, alpha_u: 0.3, alpha_v: 0.05}}",
    ]);
}

/// Wrappers inside blends and blends inside wrappers: the nested
/// composite's code is included renamed.
#[test]
fn composites_nest() {
    agree(&[
        "{type: blend, weight: 0.4, materials: [{type: diffuse}, {type: bump, height: ridges, scale: 0.05, material: {type: conductor, alpha: 0.3}}]}",
        "{type: normal_map, normals: bumps, material: {type: blend, weight: 0.5, materials: [{type: diffuse}, {type: plastic, alpha: 0.2}]}}",
        "{type: bump, height: ridges, scale: 0.05, material: {type: normal_map, normals: [0.6, 0.5, 0.9], material: {type: rough_diffuse, alpha: 0.5}}}",
    ]);
}

/// A probe whose shader scales the sample weight by 1.02 fails the
/// comparison: the tolerances are tight enough to notice a 2 % error.
#[test]
fn comparison_has_power() {
    let materials = [
        "{type: diffuse, reflectance: [0.9, 0.5, 0.1]}",
        "{type: dielectric, alpha: 0.3}",
        "{type: principled, metallic: 0.3, transmission: 0.5}",
        "{type: blend, weight: 0.3, materials: [{type: diffuse}, {type: ward}]}",
    ];
    let scene = scene(&materials);
    for (j, yaml) in materials.iter().enumerate() {
        let name = format!("m{j}");
        let m = scene
            .material_names
            .iter()
            .position(|n| *n == name)
            .unwrap_or_else(|| panic!("material {name} is in the scene"));
        let module = scene.shaders[m]
            .gpu()
            .unwrap_or_else(|| panic!("{yaml} has a GPU side"));
        let recs = records(&scene, m, 0xfeed + j as u64);
        let c = cpu(&scene, m, &recs);
        let honest = compare(&recs, &c, &gpu(&scene, &module, &recs, ""), RELATIVE);
        assert!(honest.passes(), "{yaml}: the honest probe agrees");
        let tampered = compare(
            &recs,
            &c,
            &gpu(&scene, &module, &recs, "r.weight *= 1.02;"),
            RELATIVE,
        );
        eprintln!(
            "{yaml}: with the weight scaled by 1.02, {} of {} records disagree",
            tampered.disagree, tampered.total
        );
        assert!(
            !tampered.passes(),
            "{yaml}: a 1.02× sample weight went unnoticed"
        );
    }
}
