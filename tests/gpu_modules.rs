//! Every module's GPU side against its Rust implementation: lights,
//! cameras and textures built from small scenes, the same few thousand
//! random inputs through the Rust trait methods and through the WGSL (the
//! GPU backend's probe), and the answers compared record by record.
//!
//! A result field (a point, a colour, a density) agrees where each of its
//! components is within 1e-3 of the Rust field's largest component plus
//! 1e-5: float precision, not noise. At most 0.5 % of the records may
//! disagree (inputs at a branch threshold that rounding sends the other
//! way); a failure prints the worst records. Each comparison is also run
//! with every GPU result scaled by 1.02, which must fail it.

use radiant::backend::gpu::probe::{Probe, ProbeKind};
use radiant::extract::{Overrides, RenderScene, extract};
use radiant_core::glam::{Vec2, Vec3};
use radiant_core::{
    CameraRays, Effects, EmitterEval, EmitterHit, GpuModule, LightSample, Rgb, TextureId,
    TextureRef,
};
use radiant_tests::SplitMix as Rng;
use std::ops::Range;

/// Records per comparison.
const RECORDS: usize = 4096;

/// Share of records allowed to disagree.
const ALLOWED: f64 = 0.005;

/// The inputs the module probes draw, from the tests' SplitMix64.
trait Inputs {
    /// Uniform in [a, b).
    fn range(&mut self, a: f32, b: f32) -> f32;
    /// Each coordinate uniform in [a, b).
    fn vec3(&mut self, a: f32, b: f32) -> Vec3;
    /// A uniform unit vector.
    fn direction(&mut self) -> Vec3;
    /// A sample in [0, 1)², now and then at its edges.
    fn sample2(&mut self) -> Vec2;
}

impl Inputs for Rng {
    fn range(&mut self, a: f32, b: f32) -> f32 {
        a + (b - a) * self.unit()
    }

    fn vec3(&mut self, a: f32, b: f32) -> Vec3 {
        Vec3::new(self.range(a, b), self.range(a, b), self.range(a, b))
    }

    fn direction(&mut self) -> Vec3 {
        radiant_core::warp::square_to_uniform_sphere(Vec2::new(self.unit(), self.unit()))
    }

    fn sample2(&mut self) -> Vec2 {
        let mut c = || match self.bits() % 64 {
            0 => 0.0,
            1 => 0.999_999_94,
            _ => self.unit(),
        };
        Vec2::new(c(), c())
    }
}

/// The scene `yaml` written with `files` into a temporary folder, loaded
/// and extracted with the built-in modules.
fn scene(yaml: &str, files: &[(&str, Vec<u8>)]) -> RenderScene {
    // `expect` in this test code is the assertion: the test writes its own
    // scene into a fresh temporary folder, so each step must succeed.
    let dir = tempfile::tempdir().expect("a temporary folder");
    for (name, bytes) in files {
        std::fs::write(dir.path().join(name), bytes).expect("the scene's file is written");
    }
    let path = dir.path().join("scene.yaml");
    std::fs::write(&path, yaml).expect("the scene is written");
    let loaded = radiant::scene::load(&path).expect("the test scene loads");
    extract(&loaded, &radiant::builtin_registry(), &Overrides::default())
        .expect("the test scene extracts")
}

/// A scene of one ground rectangle seen by a perspective camera, with
/// `extra` (top-level YAML: lights, more shapes, textures) added.
fn scene_with(extra: &str, files: &[(&str, Vec<u8>)]) -> RenderScene {
    let yaml = format!(
        "integrator: {{type: path, max_depth: 4}}\n\
         film: {{width: 64, height: 48}}\n\
         sampler: {{type: independent, spp: 1}}\n\
         camera: {{type: perspective, fov: 45, look_at: {{origin: [0, 2, 6], target: [0, 0, 0], up: [0, 1, 0]}}}}\n\
         {extra}\n"
    );
    scene(&yaml, files)
}

/// The ground every light scene stands on (after `shapes:`).
const GROUND: &str = "  - {name: ground, type: rectangle, material: {type: diffuse, reflectance: 0.5}, transform: [{rotate: {axis: [1, 0, 0], angle: -90}}, {scale: 4}]}\n";

/// One result field: its WGSL expression and its number of floats.
type Field = (&'static str, usize);

/// What to run and compare: the module, its kind and textures, WGSL that
/// computes the results from the inputs (`input(i, k)`), and the fields
/// of each result record.
struct Case<'a> {
    name: String,
    module: GpuModule,
    kind: ProbeKind,
    scene: &'a RenderScene,
    compute: String,
    fields: &'a [Field],
    inputs_per_record: usize,
}

impl Case<'_> {
    /// The probe body: `compute`, then each field's floats times `scale`.
    fn body(&self, scale: f32) -> String {
        let mut body = format!("let s = {scale:?};\n{}\n", self.compute);
        let mut k = 0;
        for (expr, width) in self.fields {
            let comps: &[&str] = match width {
                1 => &[""],
                2 => &[".x", ".y"],
                _ => &[".x", ".y", ".z"],
            };
            for c in comps {
                body += &format!("output(i, {k}u, ({expr}){c} * s);\n");
                k += 1;
            }
        }
        body
    }

    fn width(&self) -> usize {
        self.fields.iter().map(|f| f.1).sum()
    }

    /// The GPU's results for `inputs`, scaled by `scale`.
    fn run(&self, inputs: &[f32], scale: f32) -> Vec<f32> {
        let body = self.body(scale);
        let probe = Probe {
            module: self.module.clone(),
            kind: self.kind,
            textures: &self.scene.textures,
            body: &body,
            inputs_per_record: self.inputs_per_record,
            outputs_per_record: self.width(),
        };
        radiant_tests::gpu::backend()
            .probe(&probe, inputs)
            .unwrap_or_else(|e| panic!("{}: the probe failed: {e}\n{body}", self.name))
    }

    /// Asserts that the GPU agrees with `cpu` on `inputs`, and that
    /// results 2 % too large would not.
    fn agrees(&self, inputs: &[f32], cpu: &[f32]) {
        let records = inputs.len() / self.inputs_per_record;
        self.agrees_in_groups(inputs, cpu, &[(String::new(), 0..records)]);
    }

    /// [`Case::agrees`] with the records compared group by group: each
    /// group (a name and its records) must agree, and fail when scaled.
    fn agrees_in_groups(&self, inputs: &[f32], cpu: &[f32], groups: &[(String, Range<usize>)]) {
        let (ni, no) = (self.inputs_per_record, self.width());
        assert_eq!(cpu.len(), inputs.len() / ni * no);
        let gpu = self.run(inputs, 1.0);
        let scaled = self.run(inputs, 1.02);
        for (group, records) in groups {
            let name = format!("{}{group}", self.name);
            let part = |v: &[f32], n: usize| v[records.start * n..records.end * n].to_vec();
            let (inputs, cpu) = (part(inputs, ni), part(cpu, no));
            match compare(self.fields, &inputs, ni, &cpu, &part(&gpu, no)) {
                Ok(summary) => eprintln!("{name}: {summary}"),
                Err(report) => panic!("{name}: the GPU disagrees with the CPU: {report}"),
            }
            if let Ok(summary) = compare(self.fields, &inputs, ni, &cpu, &part(&scaled, no)) {
                panic!("{name}: results 2 % too large went unnoticed: {summary}");
            }
        }
    }
}

/// How far component `g` of the GPU is from `c` of the CPU, in units of
/// the tolerance of a field whose largest CPU component is `max`
/// (> 1: disagreement).
fn excess(g: f32, c: f32, max: f32) -> f64 {
    if (g.is_nan() && c.is_nan()) || g == c {
        return 0.0;
    }
    let tolerance = 1e-3 * max as f64 + 1e-5;
    let d = (g as f64 - c as f64).abs();
    if d.is_nan() {
        f64::INFINITY
    } else {
        d / tolerance
    }
}

/// Compares the records of `cpu` and `gpu`: Ok with a summary where at
/// most [`ALLOWED`] of them disagree, else Err with the worst.
fn compare(
    fields: &[Field],
    inputs: &[f32],
    inputs_per_record: usize,
    cpu: &[f32],
    gpu: &[f32],
) -> Result<String, String> {
    let width: usize = fields.iter().map(|f| f.1).sum();
    let records = cpu.len() / width;
    // Per record: its worst excess and the field it is in.
    let mut worst: Vec<(f64, usize, &str)> = Vec::with_capacity(records);
    for i in 0..records {
        let mut at = i * width;
        let mut record = (0.0f64, i, "");
        for (name, w) in fields {
            let c = &cpu[at..at + w];
            let g = &gpu[at..at + w];
            let max = c.iter().fold(0.0f32, |m, x| m.max(x.abs()));
            for k in 0..*w {
                let e = excess(g[k], c[k], max);
                if e > record.0 {
                    record = (e, i, name);
                }
            }
            at += w;
        }
        worst.push(record);
    }
    worst.sort_by(|a, b| b.0.total_cmp(&a.0));
    let bad = worst.iter().filter(|w| w.0 > 1.0).count();
    let summary = format!(
        "{bad} of {records} records disagree (allowed {:.1}); the worst is {:.3} tolerances off",
        ALLOWED * records as f64,
        worst.first().map_or(0.0, |w| w.0)
    );
    if bad as f64 <= ALLOWED * records as f64 {
        return Ok(summary);
    }
    let mut report = format!("{summary}\n");
    for &(e, i, name) in worst.iter().take(8) {
        let slice = |v: &[f32], n: usize| v[i * n..(i + 1) * n].to_vec();
        report += &format!(
            "  record {i}: `{name}` {e:.2} tolerances off\n    inputs {:?}\n    cpu    {:?}\n    gpu    {:?}\n",
            slice(inputs, inputs_per_record),
            slice(cpu, width),
            slice(gpu, width),
        );
    }
    Err(report)
}

// ---------------------------------------------------------------- lights

const LIGHT_SAMPLE: &[Field] = &[("ls.p", 3), ("ls.n", 3), ("ls.radiance", 3), ("ls.pdf", 1)];
const EMITTER_EVAL: &[Field] = &[("e.radiance", 3), ("e.pdf", 1)];

/// Checks `sample` of every light of `scene`, with reference points in
/// the cube [−`reach`, `reach`]³, and `eval_hits` or `eval_escaped` where
/// the light has them. Returns the identifiers of the lights checked.
fn check_lights(label: &str, scene: &RenderScene, reach: f32, seed: u64) -> Vec<String> {
    let mut rng = Rng(seed);
    let mut checked = Vec::new();
    for (l, light) in scene.lights.lights().iter().enumerate() {
        // `expect` in this test code is the assertion: every built-in light
        // has a GPU side.
        let module = light.gpu().expect("the light has a GPU side");
        let ident = module.ident.to_string();
        let case = |what: &str, compute: String, fields, inputs_per_record| Case {
            name: format!("{label}: light #{l} ({ident}) {what}"),
            module: module.clone(),
            kind: ProbeKind::Light,
            scene,
            compute,
            fields,
            inputs_per_record,
        };
        // sample
        let refs: Vec<Vec3> = (0..RECORDS).map(|_| rng.vec3(-reach, reach)).collect();
        let u: Vec<Vec2> = (0..RECORDS).map(|_| rng.sample2()).collect();
        let mut out = vec![LightSample::default(); RECORDS];
        light.sample(&refs, &u, &mut out);
        let inputs: Vec<f32> = refs
            .iter()
            .zip(&u)
            .flat_map(|(r, u)| [r.x, r.y, r.z, u.x, u.y])
            .collect();
        let cpu: Vec<f32> = out
            .iter()
            .flat_map(|s| {
                let mut v = s.p.to_array().to_vec();
                v.extend(s.n.to_array());
                v.extend(s.radiance.to_array());
                v.push(s.pdf);
                v
            })
            .collect();
        case(
            "sample",
            format!(
                "let ls = light_sample_{ident}(P, vec3f(input(i, 0u), input(i, 1u), input(i, 2u)), vec2f(input(i, 3u), input(i, 4u)));"
            ),
            LIGHT_SAMPLE,
            5,
        )
        .agrees(&inputs, &cpu);
        let effects = light.effects();
        if effects.contains(Effects::AREA_LIGHTS) {
            // Rays from anywhere to anywhere, on any primitive: the density
            // is a function of all of them.
            let hits: Vec<EmitterHit> = (0..RECORDS)
                .map(|_| EmitterHit {
                    origin: rng.vec3(-reach, reach),
                    p: rng.vec3(-reach, reach),
                    n: rng.direction(),
                    primitive: (rng.bits() % 24) as u32,
                })
                .collect();
            let mut out = vec![EmitterEval::default(); RECORDS];
            light.eval_hits(&hits, &mut out);
            let inputs: Vec<f32> = hits
                .iter()
                .flat_map(|h| {
                    let mut v = h.origin.to_array().to_vec();
                    v.extend(h.p.to_array());
                    v.extend(h.n.to_array());
                    v.push(h.primitive as f32);
                    v
                })
                .collect();
            case(
                "eval_hits",
                format!(
                    "let e = light_hit_{ident}(P, EmitterHit(vec3f(input(i, 0u), input(i, 1u), input(i, 2u)), vec3f(input(i, 3u), input(i, 4u), input(i, 5u)), vec3f(input(i, 6u), input(i, 7u), input(i, 8u)), u32(input(i, 9u))));"
                ),
                EMITTER_EVAL,
                10,
            )
            .agrees(&inputs, &eval_floats(&out));
        }
        if effects.contains(Effects::ENVIRONMENT) {
            // Random directions, the poles, and directions sampled from
            // the light (where a map's density is high) with samples off
            // the cell edges (an edge sample gives a direction on the
            // border of a cell, which rounding may put in its neighbour).
            let mut dirs: Vec<Vec3> = (0..RECORDS / 2).map(|_| rng.direction()).collect();
            dirs.extend([Vec3::Y, -Vec3::Y, Vec3::X, -Vec3::Z]);
            let n = RECORDS / 2 - 4;
            let u: Vec<Vec2> = (0..n).map(|_| Vec2::new(rng.unit(), rng.unit())).collect();
            let mut sampled = vec![LightSample::default(); n];
            light.sample(&refs[..n], &u, &mut sampled);
            dirs.extend(
                refs.iter()
                    .zip(&sampled)
                    .map(|(r, s)| (s.p - *r).normalize_or(Vec3::Z)),
            );
            let mut out = vec![EmitterEval::default(); dirs.len()];
            light.eval_escaped(&dirs, &mut out);
            let inputs: Vec<f32> = dirs.iter().flat_map(|d| d.to_array()).collect();
            case(
                "eval_escaped",
                format!(
                    "let e = light_escaped_{ident}(P, vec3f(input(i, 0u), input(i, 1u), input(i, 2u)));"
                ),
                EMITTER_EVAL,
                3,
            )
            .agrees(&inputs, &eval_floats(&out));
        }
        checked.push(ident);
    }
    checked
}

fn eval_floats(out: &[EmitterEval]) -> Vec<f32> {
    out.iter()
        .flat_map(|e| {
            let mut v = e.radiance.to_array().to_vec();
            v.push(e.pdf);
            v
        })
        .collect()
}

#[test]
fn area_lights() {
    // A rectangle (solid-angle sampled near it), a cube (six rectangles),
    // a sphere (cone sampling from outside, area from inside), a sheared
    // quad (two triangles) and a one-triangle mesh (by area).
    let obj = b"v 0 0 0\nv 1.5 0 0.2\nv 0.3 1 0\nf 1 2 3\n".to_vec();
    let shapes = [
        "  - {name: panel, type: rectangle, material: {type: diffuse}, transform: [{translate: [0, 2, 0]}, {rotate: {axis: [1, 0, 0], angle: 90}}, {scale: [0.8, 0.5, 1]}], emitter: {type: area, radiance: [4, 3, 2]}}",
        "  - {name: box, type: cube, material: {type: diffuse}, transform: [{translate: [1.5, 0.5, 0]}, {rotate: {axis: [0, 1, 0], angle: 30}}, {scale: 0.4}], emitter: {type: area, radiance: 1.5}}",
        "  - {name: ball, type: sphere, center: [-1.2, 0.6, 0.5], radius: 0.6, material: {type: diffuse}, emitter: {type: area, radiance: [1, 2, 3]}}",
        "  - {name: sheared, type: rectangle, material: {type: diffuse}, emitter: {type: area, radiance: 2}, transform: {matrix: [[1, 0.6, 0, 0.5], [0, 0.2, -1, 1.5], [0, 1, 0.3, -1], [0, 0, 0, 1]]}}",
        "  - {name: triangle, type: mesh, filename: triangle.obj, material: {type: diffuse}, emitter: {type: area, radiance: [3, 1, 0.5]}}",
    ];
    let r = scene_with(
        &format!("shapes:\n{GROUND}{}\n", shapes.join("\n")),
        &[("triangle.obj", obj)],
    );
    let checked = check_lights("area lights", &r, 3.0, 1);
    assert_eq!(checked, ["area"; 5], "one area light per emitting shape");
}

#[test]
fn delta_lights() {
    let lights = [
        "  - {type: point, position: [0.5, 2, -0.3], intensity: [5, 4, 3]}",
        "  - {type: spot, position: [-1, 2.5, 1], target: [0, 0, 0], intensity: [30, 25, 20], cutoff_angle: 40, beam_width: 15}",
        "  - {type: spot, position: [0, 1, 0], direction: [0.2, -1, 0.1], intensity: 3, cutoff_angle: 25, beam_width: 25}",
        "  - {type: spot, position: [0.3, 0.2, 0], direction: [1, 0, 0], intensity: 2, cutoff_angle: 180}",
        "  - {type: directional, direction: [1, -0.5, -0.3], irradiance: [0.6, 0.7, 0.9]}",
        "  - {type: directional, irradiance: 2, transform: {rotate: {axis: [1, 1, 0], angle: 70}}}",
    ];
    let r = scene_with(
        &format!("shapes:\n{GROUND}lights:\n{}\n", lights.join("\n")),
        &[],
    );
    let checked = check_lights("delta lights", &r, 3.0, 2);
    assert_eq!(
        checked,
        [
            "point",
            "spot",
            "spot",
            "spot",
            "directional",
            "directional"
        ]
    );
}

/// A Radiance HDR file of `w × h` pixels from `pixel(x, y)` as RGBE bytes
/// (flat scanlines: the first byte of each row is at least 128, so no row
/// reads as run-length encoded).
fn hdr(w: u32, h: u32, mut pixel: impl FnMut(u32, u32) -> [u8; 4]) -> Vec<u8> {
    let mut bytes = format!("#?RADIANCE\nFORMAT=32-bit_rle_rgbe\n\n-Y {h} +X {w}\n").into_bytes();
    for y in 0..h {
        for x in 0..w {
            bytes.extend(pixel(x, y));
        }
    }
    bytes
}

#[test]
fn environment_lights() {
    let sky = radiant_tests::root().join("scenes/environment-sky.exr");
    // A map with black rows and a black column (cells of weight zero, a
    // cell row of weight zero), turned about a slanted axis.
    let mut rng = Rng(3);
    let patchy = hdr(9, 7, |x, y| {
        if y == 2 || y == 3 || x == 4 {
            [0, 0, 0, 0]
        } else {
            let m = |rng: &mut Rng| 128 + (rng.bits() % 128) as u8;
            [
                m(&mut rng),
                m(&mut rng),
                m(&mut rng),
                126 + (rng.bits() % 6) as u8,
            ]
        }
    });
    // The smallest map: 1 × 2 pixels.
    let tiny = hdr(1, 2, |_, y| [200, 100 + 50 * y as u8, 30, 129]);
    let lights = [
        "{type: environment, radiance: [0.5, 0.7, 1.0], scale: 2}".to_string(),
        format!(
            "{{type: environment, filename: {}, transform: {{rotate: {{axis: [0, 1, 0], angle: 60}}}}}}",
            sky.display()
        ),
        "{type: environment, filename: patchy.hdr, scale: 3, transform: {rotate: {axis: [1, 2, 0.5], angle: 40}}}".into(),
        "{type: environment, filename: tiny.hdr}".into(),
    ];
    for (k, light) in lights.iter().enumerate() {
        let r = scene_with(
            &format!("shapes:\n{GROUND}lights:\n  - {light}\n"),
            &[("patchy.hdr", patchy.clone()), ("tiny.hdr", tiny.clone())],
        );
        let checked = check_lights(&format!("environment {light}"), &r, 3.0, 10 + k as u64);
        assert_eq!(checked, ["environment"]);
    }
}

// ---------------------------------------------------------------- cameras

const CAMERA_RAY: &[Field] = &[("ray.origin", 3), ("ray.dir", 3), ("ray.weight", 1)];

/// Checks the scene's camera on random film positions and lens samples.
fn check_camera(label: &str, camera: &str, seed: u64) {
    let (w, h) = (64.0f32, 48.0f32);
    let r = scene(
        &format!(
            "film: {{width: {w}, height: {h}}}\n\
             camera: {camera}\n\
             shapes:\n{GROUND}"
        ),
        &[],
    );
    // `expect` in this test code is the assertion: every built-in camera
    // has a GPU side.
    let module = r.camera.gpu().expect("the camera has a GPU side");
    let mut rng = Rng(seed);
    let film: Vec<Vec2> = (0..RECORDS)
        .map(|_| Vec2::new(rng.range(0.0, w), rng.range(0.0, h)))
        .collect();
    let lens: Vec<Vec2> = (0..RECORDS).map(|_| rng.sample2()).collect();
    let (mut origins, mut directions, mut weights) = (
        vec![Vec3::ZERO; RECORDS],
        vec![Vec3::ZERO; RECORDS],
        vec![0.0f32; RECORDS],
    );
    r.camera.generate(
        &film,
        &lens,
        CameraRays {
            origins: &mut origins,
            directions: &mut directions,
            weights: &mut weights,
        },
    );
    let inputs: Vec<f32> = film
        .iter()
        .zip(&lens)
        .flat_map(|(f, l)| [f.x, f.y, l.x, l.y])
        .collect();
    let cpu: Vec<f32> = (0..RECORDS)
        .flat_map(|i| {
            let mut v = origins[i].to_array().to_vec();
            v.extend(directions[i].to_array());
            v.push(weights[i]);
            v
        })
        .collect();
    let ident = module.ident.to_string();
    assert_eq!(ident, label, "the camera's GPU identifier");
    Case {
        name: format!("camera {camera}"),
        module,
        kind: ProbeKind::Camera,
        scene: &r,
        compute: format!(
            "let ray = camera_ray_{ident}(P, vec2f(input(i, 0u), input(i, 1u)), vec2f(input(i, 2u), input(i, 3u)));"
        ),
        fields: CAMERA_RAY,
        inputs_per_record: 4,
    }
    .agrees(&inputs, &cpu);
}

#[test]
fn perspective_camera() {
    check_camera(
        "perspective",
        "{type: perspective, fov: 50, fov_axis: smaller, look_at: {origin: [1, 2, 6], target: [0, 0.5, 0], up: [0, 1, 0]}}",
        20,
    );
    check_camera(
        "perspective",
        "{type: perspective, fov: 30, fov_axis: diagonal, transform: [{translate: [0.5, 1, 4]}, {rotate: {axis: [0, 1, 0], angle: 170}}]}",
        21,
    );
}

#[test]
fn thin_lens_camera() {
    check_camera(
        "thin_lens",
        "{type: thin_lens, fov: 40, aperture_radius: 0.2, focus_distance: 5, look_at: {origin: [1, 2, 6], target: [0, 0.5, 0], up: [0, 1, 0]}}",
        22,
    );
    check_camera(
        "thin_lens",
        "{type: thin_lens, fov: 70, fov_axis: y, aperture_radius: 0.05, focus_distance: 0.7, transform: [{translate: [0, 1, 3]}, {rotate: {axis: [1, 0, 0], angle: -20}}]}",
        23,
    );
}

#[test]
fn orthographic_camera() {
    check_camera(
        "orthographic",
        "{type: orthographic, width: 5, look_at: {origin: [1, 2, 6], target: [0, 0.5, 0], up: [0, 1, 0]}}",
        24,
    );
    // A scale in the pose resizes the window.
    check_camera(
        "orthographic",
        "{type: orthographic, transform: [{translate: [0, 1, 5]}, {rotate: {axis: [0, 1, 0], angle: 160}}, {scale: [2, 1.5, 1]}]}",
        25,
    );
}

#[test]
fn spherical_camera() {
    check_camera(
        "spherical",
        "{type: spherical, look_at: {origin: [1, 2, 6], target: [0, 0.5, 0], up: [0, 1, 0]}}",
        26,
    );
}

// ---------------------------------------------------------------- textures

const TEXTURE: &[Field] = &[("c", 3)];

/// Texture coordinates for the texture tests: mostly in [−2, 3]², some
/// large (the texel index arithmetic beyond 2²⁴ and 2³¹, and at the clamp
/// at 2⁴⁰), some on texel and check boundaries.
fn texture_coordinates(rng: &mut Rng, n: usize) -> Vec<Vec2> {
    (0..n)
        .map(|_| {
            let mut c = || match rng.bits() % 50 {
                0 => rng.range(-1e7, 1e7),
                1 => rng.range(-1e12, 1e12),
                2 => rng.range(-1e14, 1e14),
                3 => (rng.bits() % 41) as f32 * 0.125 - 2.0,
                _ => rng.range(-2.0, 3.0),
            };
            Vec2::new(c(), c())
        })
        .collect()
}

/// A float image with more distinct values than a palette holds.
fn float_image() -> Vec<u8> {
    let mut rng = Rng(7);
    hdr(13, 11, |_, _| {
        let mut m = || 128 + (rng.bits() % 128) as u8;
        [m(), m(), m(), 120 + (rng.bits() % 12) as u8]
    })
}

#[test]
fn textures() {
    let texels = radiant_tests::root().join("modules/textures/tests/data/texels-4x2.png");
    let texels = texels.display();
    let textures = [
        format!("  png: {{type: image, filename: {texels}}}"),
        format!("  png_nearest_clamp: {{type: image, filename: {texels}, filter: nearest, wrap: clamp}}"),
        format!("  png_raw_mirror: {{type: image, filename: {texels}, raw: true, wrap: mirror}}"),
        format!("  png_nearest_mirror: {{type: image, filename: {texels}, filter: nearest, wrap: mirror}}"),
        format!("  png_clamp: {{type: image, filename: {texels}, wrap: clamp}}"),
        "  float: {type: image, filename: float.hdr}".into(),
        "  float_nearest: {type: image, filename: float.hdr, filter: nearest}".into(),
        "  checks: {type: checkerboard, color0: [0.8, 0.7, 0.1], color1: 0.1}".into(),
        "  default_checks: {type: checkerboard}".into(),
        "  image_checks: {type: checkerboard, color0: png, color1: [0.2, 0.3, 0.4]}".into(),
        "  scaled_checks: {type: uv_transform, texture: checks, scale: 6}".into(),
        "  turned: {type: uv_transform, texture: float, scale: [3, -2], rotate: 30, offset: [0.25, 1]}".into(),
        "  turned_constant: {type: uv_transform, texture: 0.5, rotate: 10}".into(),
        "  layers: {type: layered, upper: png, lower: scaled_checks, mask: png_raw_mirror}".into(),
        "  layered_constants: {type: layered, upper: [1, 0, 0], lower: 0.25, mask: image_checks}".into(),
        "  nested: {type: checkerboard, color0: layers, color1: turned}".into(),
    ];
    let r = scene_with(
        &format!(
            "textures:\n{}\nmaterials:\n  textured: {{type: diffuse, reflectance: nested}}\nshapes:\n  - {{name: ground, type: rectangle, material: textured}}\n",
            textures.join("\n")
        ),
        &[("float.hdr", float_image())],
    );
    let table = &r.textures;
    // Any texture module's GPU side will do as the probe's module: the
    // body reads every texture through the table's directory.
    let probe_module = (0..table.len() as u32)
        .find_map(|i| match table.get(TextureId(i)) {
            TextureRef::Module(t) => t.gpu(),
            TextureRef::Constant(_) => None,
        })
        // `expect` in this test code is the assertion: the scene defines
        // texture modules.
        .expect("a texture module");
    // One probe for all textures: records of (id, u, v), in groups of
    // one texture each.
    let mut rng = Rng(30);
    let (mut idents, mut inputs, mut cpu, mut groups) = (vec![], vec![], vec![], vec![]);
    for id in 0..table.len() as u32 {
        let ident = match table.get(TextureId(id)) {
            TextureRef::Constant(_) => "constant".to_string(),
            // `expect` in this test code is the assertion: every built-in
            // texture with children in the table has a GPU side.
            TextureRef::Module(t) => t.gpu().expect("the texture has a GPU side").ident.into(),
        };
        // Far from the origin, a transform's rounding (an FMA or not)
        // moves the lookup by whole texels: transformed textures are
        // compared where that rounding is below a texel.
        let uv: Vec<Vec2> = if ident.contains("uv_transform") {
            (0..RECORDS / 2)
                .map(|_| Vec2::new(rng.range(-2.0, 3.0), rng.range(-2.0, 3.0)))
                .collect()
        } else {
            texture_coordinates(&mut rng, RECORDS / 2)
        };
        let mut out = vec![Rgb::ZERO; uv.len()];
        table.eval(TextureId(id), &uv, &mut out);
        let first = inputs.len() / 3;
        inputs.extend(uv.iter().flat_map(|p| [id as f32, p.x, p.y]));
        cpu.extend(out.iter().flat_map(|c| c.to_array()));
        groups.push((format!(" #{id} ({ident})"), first..first + uv.len()));
        idents.push(ident);
    }
    Case {
        name: "texture".into(),
        module: probe_module,
        kind: ProbeKind::Texture,
        scene: &r,
        compute: "let c = texture_eval(u32(input(i, 0u)), vec2f(input(i, 1u), input(i, 2u)));"
            .into(),
        fields: TEXTURE,
        inputs_per_record: 3,
    }
    .agrees_in_groups(&inputs, &cpu, &groups);
    for expected in [
        "image",
        "checkerboard_k_k",
        "checkerboard_5image_k",
        "uv_transform_16checkerboard_k_k",
        "uv_transform_5image",
        "uv_transform_k",
        "layered_5image_31uv_transform_16checkerboard_k_k_5image",
        "layered_k_k_21checkerboard_5image_k",
    ] {
        assert!(
            idents.iter().any(|i| i == expected),
            "no `{expected}` among the textures checked: {idents:?}"
        );
    }
    assert!(
        idents
            .iter()
            .any(|i| i.starts_with("checkerboard_55layered")),
        "the nested checkerboard was not checked: {idents:?}"
    );
}

/// The image texture's texel palette holds exactly the values the Rust
/// side decoded: an 8-bit image fits one, a float image with more than
/// 256 distinct values is stored as floats (both checked above); here
/// the palette's words are checked to be smaller than the floats'.
#[test]
fn eight_bit_images_take_one_word_per_texel() {
    let texels = radiant_tests::root().join("modules/textures/tests/data/texels-4x2.png");
    let r = scene_with(
        &format!(
            "textures:\n  png: {{type: image, filename: {}}}\n  float: {{type: image, filename: float.hdr}}\nmaterials:\n  a: {{type: diffuse, reflectance: png}}\n  b: {{type: diffuse, reflectance: float}}\nshapes:\n{GROUND}",
            texels.display()
        ),
        &[("float.hdr", float_image())],
    );
    let sizes: Vec<(usize, usize)> = (0..r.textures.len() as u32)
        .filter_map(|i| match r.textures.get(TextureId(i)) {
            TextureRef::Module(t) => t.gpu().map(|m| (i as usize, m.params.len())),
            TextureRef::Constant(_) => None,
        })
        .collect();
    // 4 × 2 texels of at most 24 distinct values (header 5 + palette +
    // 8 words) against 13 × 11 floats (header 5 + 3 words each).
    assert_eq!(sizes.len(), 2, "{sizes:?}");
    assert!(sizes[0].1 <= 5 + 24 + 8, "{sizes:?}");
    assert_eq!(sizes[1].1, 5 + 3 * 13 * 11, "{sizes:?}");
}
