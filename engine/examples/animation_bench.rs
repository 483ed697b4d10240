//! Benchmarks of the frame loop (figures, not tests; see
//! `engine/benches/ANIMATION.md` for the last measurements).
//!
//! ```text
//! cargo run --release --example animation_bench -- deform MESH.obj [FRAMES]
//! cargo run --release --example animation_bench -- instances MESH.obj [COUNT]
//! ```
//!
//! * `deform`: the mesh deformed by a travelling, twisting wave, written
//!   as an OBJ sequence of FRAMES frames (default 100) into a temporary
//!   folder and rendered at 256×256, 16 spp, once per BVH update policy —
//!   refitted and rebuilt past SAH-cost thresholds of 1.1, 1.3 and 2,
//!   refitted only — each paired frame by frame with the same sequence
//!   rebuilt every frame (rendered alternately, so the host's changing
//!   speed falls on both alike). Per policy: BVH update and render time,
//!   the SAH cost over the built cost, rays per second, render time over
//!   the rebuilt sequence's; plus the time of one refit against one
//!   rebuild.
//! * `instances`: COUNT copies (default 10,000) of the mesh scattered over
//!   a field against the mesh alone: memory in use after extract, and rays
//!   per second rendering 256×256 at 16 spp. `instances-scene MESH.obj
//!   [COUNT]` prints that scene (for `radiant render` or a profiler).

use anyhow::{Context, Result, bail};
use radiant::accel::UpdatePolicy;
use radiant::backend::cpu::{Progress, render};
use radiant::extract::{Overrides, Sequence, SequenceOptions};
use radiant::scene::mesh::MeshOptions;
use std::fmt::Write as _;
use std::path::Path;
use std::time::Duration;

/// Resident memory of this process in bytes (Linux).
fn resident_bytes() -> u64 {
    let status = std::fs::read_to_string("/proc/self/status").unwrap_or_default();
    status
        .lines()
        .find_map(|l| l.strip_prefix("VmRSS:"))
        .and_then(|v| v.trim().trim_end_matches("kB").trim().parse::<u64>().ok())
        .map_or(0, |kb| kb * 1024)
}

/// A mesh's positions and triangles.
type Mesh = (Vec<[f32; 3]>, Vec<[u32; 3]>);

/// The mesh's positions and triangles.
fn read_mesh(path: &Path) -> Result<Mesh> {
    let mesh =
        radiant::scene::mesh::load(path, MeshOptions::default()).map_err(anyhow::Error::msg)?;
    Ok((
        mesh.positions.iter().map(|p| p.to_array()).collect(),
        mesh.triangles,
    ))
}

/// The box around `positions`.
fn bounds(positions: &[[f32; 3]]) -> ([f32; 3], [f32; 3]) {
    let mut lo = [f32::INFINITY; 3];
    let mut hi = [f32::NEG_INFINITY; 3];
    for p in positions {
        for a in 0..3 {
            lo[a] = lo[a].min(p[a]);
            hi[a] = hi[a].max(p[a]);
        }
    }
    (lo, hi)
}

/// Writes frame `f` of the deformed mesh: a wave travelling up the mesh
/// pushes vertices sideways, and the whole mesh twists back and forth
/// about its vertical axis, more at the top.
fn write_deformed(
    path: &Path,
    positions: &[[f32; 3]],
    triangles: &[[u32; 3]],
    f: u32,
) -> Result<()> {
    let (lo, hi) = bounds(positions);
    let size = (0..3).map(|a| hi[a] - lo[a]).fold(0.0f32, f32::max);
    let centre = [(lo[0] + hi[0]) / 2.0, (lo[2] + hi[2]) / 2.0];
    let t = f as f32;
    let mut obj = String::with_capacity(positions.len() * 40 + triangles.len() * 30);
    for p in positions {
        let h = (p[1] - lo[1]) / (hi[1] - lo[1]).max(1e-6);
        let wave = 0.12 * size * (std::f32::consts::TAU * (2.0 * h - 0.04 * t)).sin();
        let twist = 2.0 * h * (0.05 * t).sin();
        let (s, c) = twist.sin_cos();
        let (x, z) = (p[0] - centre[0] + wave, p[2] - centre[1]);
        let _ = writeln!(
            obj,
            "v {} {} {}",
            centre[0] + c * x - s * z,
            p[1],
            centre[1] + s * x + c * z
        );
    }
    for t in triangles {
        let _ = writeln!(obj, "f {} {} {}", t[0] + 1, t[1] + 1, t[2] + 1);
    }
    std::fs::write(path, obj).with_context(|| format!("writing {}", path.display()))
}

/// A scene of the mesh at `filename` framed by the camera, `frames`
/// frames long, at 256×256 and 16 spp.
fn scene_text(filename: &str, lo: [f32; 3], hi: [f32; 3], frames: u32, extra: &str) -> String {
    let c = [
        (lo[0] + hi[0]) / 2.0,
        (lo[1] + hi[1]) / 2.0,
        (lo[2] + hi[2]) / 2.0,
    ];
    let size = (0..3).map(|a| hi[a] - lo[a]).fold(0.0f32, f32::max);
    format!(
        "integrator: {{type: path, max_depth: 5}}
film: {{width: 256, height: 256}}
sampler: {{type: independent, spp: 16}}
animation: {{fps: 24, frames: [1, {frames}]}}
camera: {{type: perspective, fov: 45, look_at: {{origin: [{}, {}, {}], target: [{}, {}, {}]}}}}
materials:
  gold: {{type: conductor, material: Au, alpha: 0.2}}
shapes:
  - {{type: mesh, filename: '{filename}', material: gold{extra}}}
  - {{type: rectangle, transform: [{{translate: [{}, {}, {}]}}, {{rotate: {{axis: [1, 0, 0], angle: -90}}}}, {{scale: {}}}]}}
lights:
  - {{type: environment, radiance: 0.6}}
  - {{type: point, position: [{}, {}, {}], intensity: {}}}
",
        c[0] + 0.3 * size,
        c[1] + 0.4 * size,
        c[2] + 1.6 * size,
        c[0],
        c[1],
        c[2],
        c[0],
        lo[1],
        c[2],
        3.0 * size,
        c[0] + size,
        hi[1] + size,
        c[2] + size,
        2.0 * size * size
    )
}

/// What a paired run measured: a sequence with a policy against the same
/// sequence rebuilt every frame, frame by frame, rendered alternately so
/// that the host's changing speed falls on both alike.
#[derive(Default)]
struct Paired {
    /// BVH update time, whole update time, render time and rays of the
    /// policy's sequence.
    bvh: Duration,
    update: Duration,
    render: Duration,
    rays: u64,
    /// Render time of the sequence rebuilt every frame.
    rebuilt_render: Duration,
    /// Its BVH update time.
    rebuilt_bvh: Duration,
    rebuilds: usize,
    worst_sah: f32,
    mean_sah: f64,
}

fn run_paired(text: &str, dir: &Path, frames: u32, policy: UpdatePolicy) -> Result<Paired> {
    let registry = radiant::builtin_registry();
    let load = || radiant::scene::from_str(text, &dir.join("bench.yaml"), dir);
    let (mut scene_a, mut scene_b) = (load()?, load()?);
    let options = |rebuild_above| SequenceOptions {
        policy: UpdatePolicy { rebuild_above },
        ..SequenceOptions::default()
    };
    let o = Overrides::default();
    let (mut a, _) = Sequence::new(&mut scene_a, &registry, &o, &options(0.0), 1)?;
    let (mut b, _) = Sequence::new(
        &mut scene_b,
        &registry,
        &o,
        &options(policy.rebuild_above),
        1,
    )?;
    let mut run = Paired::default();
    for f in 1..=frames {
        if f > 1 {
            let ua = a.go_to(&mut scene_a, &registry, i64::from(f))?;
            let ub = b.go_to(&mut scene_b, &registry, i64::from(f))?;
            run.rebuilt_bvh += ua.bvh;
            run.bvh += ub.bvh;
            run.update += ub.update;
            run.rebuilds += ub.geometry.rebuilt;
            run.worst_sah = run.worst_sah.max(ub.geometry.degradation);
            run.mean_sah += f64::from(ub.geometry.degradation) / f64::from(frames - 1);
        }
        let time = |s: &Sequence| {
            let r = render(s.scene(), &Progress::none());
            (r.time, r.rays)
        };
        let ((ta, _), (tb, rays)) = if f % 2 == 0 {
            let x = time(&a);
            (x, time(&b))
        } else {
            let y = time(&b);
            (time(&a), y)
        };
        run.rebuilt_render += ta;
        run.render += tb;
        run.rays += rays;
    }
    Ok(run)
}

fn deform(mesh: &Path, frames: u32) -> Result<()> {
    let (positions, triangles) = read_mesh(mesh)?;
    let dir = tempfile::tempdir()?;
    for f in 1..=frames {
        write_deformed(
            &dir.path().join(format!("m_{f:04}.obj")),
            &positions,
            &triangles,
            f,
        )?;
    }
    let (lo, hi) = bounds(&positions);
    let text = scene_text("m_####.obj", lo, hi, frames, "");
    println!(
        "{}: {} triangles deformed over {frames} frames, 256x256, 16 spp",
        mesh.display(),
        triangles.len()
    );
    println!(
        "policy: rebuild above | rebuilds | BVH update | render | BVH share of frame | Mrays/s | SAH cost / built, mean and worst | render time / rebuilt every frame's"
    );
    for above in [1.1f32, 1.3, 2.0, f32::INFINITY] {
        let r = run_paired(
            &text,
            dir.path(),
            frames,
            UpdatePolicy {
                rebuild_above: above,
            },
        )?;
        let frame = r.update + r.render;
        let name = if above.is_infinite() {
            "never (refit)".to_string()
        } else {
            format!("{above}")
        };
        println!(
            "{name} | {} | {:.2} s | {:.2} s | {:.2} % | {:.2} | {:.3} / {:.3} | {:.3}",
            r.rebuilds,
            r.bvh.as_secs_f64(),
            r.render.as_secs_f64(),
            100.0 * r.bvh.as_secs_f64() / frame.as_secs_f64(),
            r.rays as f64 / r.render.as_secs_f64() / 1e6,
            r.mean_sah,
            r.worst_sah,
            r.render.as_secs_f64() / r.rebuilt_render.as_secs_f64()
        );
        if above == 1.1 {
            let rebuilt_frame = r.rebuilt_bvh + r.rebuilt_render + r.update - r.bvh;
            println!(
                "(rebuilt every frame: BVH update {:.2} s, {:.2} % of its frame time)",
                r.rebuilt_bvh.as_secs_f64(),
                100.0 * r.rebuilt_bvh.as_secs_f64() / rebuilt_frame.as_secs_f64()
            );
        }
    }
    // One refit against one rebuild of the mesh's hierarchy.
    let prims = |f: u32| -> Result<Vec<radiant::accel::Primitive>> {
        let path = dir.path().join(format!("m_{f:04}.obj"));
        let m = radiant::scene::mesh::load_frame(&path, MeshOptions::default())
            .map_err(anyhow::Error::msg)?;
        Ok(m.triangles
            .iter()
            .map(|t| radiant::accel::Primitive::Triangle(t.map(|i| m.positions[i as usize])))
            .collect())
    };
    let (a, b) = (prims(1)?, prims(frames / 2)?);
    let quality = radiant::accel::BuildQuality::default_for(a.len());
    let mut blas = radiant::accel::Blas::build(&a, None, quality);
    let never = UpdatePolicy {
        rebuild_above: f32::INFINITY,
    };
    let refit = (0..5)
        .map(|i| {
            blas.update(if i % 2 == 0 { &b } else { &a }, None, never)
                .time
        })
        .min()
        .unwrap_or_default();
    let always = UpdatePolicy { rebuild_above: 0.0 };
    let rebuild = (0..3)
        .map(|i| {
            blas.update(if i % 2 == 0 { &b } else { &a }, None, always)
                .time
        })
        .min()
        .unwrap_or_default();
    println!(
        "one update of {} triangles: refit {:.2} ms, rebuild {:.1} ms ({:.1}x)",
        a.len(),
        refit.as_secs_f64() * 1e3,
        rebuild.as_secs_f64() * 1e3,
        rebuild.as_secs_f64() / refit.as_secs_f64()
    );
    Ok(())
}

/// The scene of `count` copies of the mesh at `mesh` (1: the mesh alone).
fn instances_scene(mesh: &Path, count: u32) -> Result<String> {
    let (positions, _) = read_mesh(mesh)?;
    let (lo, hi) = bounds(&positions);
    let size = (0..3).map(|a| hi[a] - lo[a]).fold(0.0f32, f32::max);
    let filename = mesh
        .canonicalize()
        .with_context(|| format!("{} not found", mesh.display()))?
        .to_string_lossy()
        .into_owned();
    // A field of copies seen from its edge at a slant, near copies filling
    // much of the view and far ones a pixel or less; or the mesh alone,
    // filling the view, under the same lights on the same ground.
    let side = size * (count as f32).sqrt() * 1.6;
    let h = side / 2.0;
    let (camera, placement) = if count == 1 {
        (
            format!(
                "{{origin: [{}, {}, {}], target: [0, {}, 0]}}",
                0.3 * size,
                0.6 * size,
                1.5 * size,
                0.35 * size
            ),
            String::new(),
        )
    } else {
        (
            format!(
                "{{origin: [0, {}, {}], target: [0, 0, 0]}}",
                2.5 * size,
                h + size
            ),
            format!(
                "\n    instances: {{scatter: {{count: {count}, min: [{}, 0, {}], max: [{h}, 0, {h}], seed: 1, rotate: [0, 360], scale: [0.8, 1.2]}}}}",
                -h, -h
            ),
        )
    };
    let ground = side.max(4.0 * size);
    Ok(format!(
        "integrator: {{type: path, max_depth: 5}}
film: {{width: 256, height: 256}}
sampler: {{type: independent, spp: 16}}
camera: {{type: perspective, fov: 50, look_at: {camera}}}
materials:
  gold: {{type: conductor, material: Au, alpha: 0.2}}
shapes:
  - type: mesh
    filename: '{filename}'
    material: gold
    transform: {{translate: [{}, {}, {}]}}{placement}
  - {{type: rectangle, transform: [{{rotate: {{axis: [1, 0, 0], angle: -90}}}}, {{scale: {ground}}}]}}
lights:
  - {{type: environment, radiance: 0.6}}
  - {{type: directional, direction: [-0.3, -1, -0.4], irradiance: 3}}
",
        -(lo[0] + hi[0]) / 2.0,
        -lo[1],
        -(lo[2] + hi[2]) / 2.0,
    ))
}

/// Extracts and renders the scene of `count` copies in this process;
/// prints its memory growth, rays per second and placed triangles.
fn measure_instances(mesh: &Path, count: u32) -> Result<()> {
    let text = instances_scene(mesh, count)?;
    let dir = tempfile::tempdir()?;
    let registry = radiant::builtin_registry();
    let before = resident_bytes();
    let scene = radiant::scene::from_str(&text, &dir.path().join("i.yaml"), dir.path())?;
    let r = radiant::extract::extract(&scene, &registry, &Overrides::default())?;
    let memory = resident_bytes().saturating_sub(before);
    // The best of five renders (the host's speed varies from run to run).
    let best = (0..5)
        .map(|_| {
            let rendered = render(&r, &Progress::none());
            rendered.rays as f64 / rendered.time.as_secs_f64() / 1e6
        })
        .fold(0.0, f64::max);
    println!("{memory} {best} {}", r.stats.instanced_triangles);
    Ok(())
}

/// Measures the mesh alone and `count` copies, each in a process of its
/// own (so that neither inherits the other's memory), alternately.
fn instances(mesh: &Path, count: u32) -> Result<()> {
    let me = std::env::current_exe()?;
    let run = |n: u32| -> Result<(f64, f64, u64)> {
        let out = std::process::Command::new(&me)
            .args(["measure-instances", &mesh.to_string_lossy(), &n.to_string()])
            .output()?;
        if !out.status.success() {
            bail!("{}", String::from_utf8_lossy(&out.stderr));
        }
        let text = String::from_utf8_lossy(&out.stdout);
        let v: Vec<&str> = text.split_whitespace().collect();
        Ok((v[0].parse()?, v[1].parse()?, v[2].parse()?))
    };
    // Alternately, three times each; the best rate of each counts.
    let (mut m1, mut r1, mut t1, mut m2, mut r2, mut t2) = (0.0, 0.0f64, 0, 0.0, 0.0f64, 0);
    for _ in 0..3 {
        let (m, r, t) = run(1)?;
        (m1, r1, t1) = (m, r1.max(r), t);
        let (m, r, t) = run(count)?;
        (m2, r2, t2) = (m, r2.max(r), t);
    }
    println!(
        "{}: one copy places {t1} triangles, {count} copies {t2}",
        mesh.display()
    );
    let table = f64::from(count) * (std::mem::size_of::<radiant::accel::Instance>() + 4 + 4) as f64;
    println!(
        "memory after extract: one {:.1} MB, {count} copies {:.1} MB = {:.2}x one; one plus the instance table ({:.2} MB): {:.2}x",
        m1 / 1e6,
        m2 / 1e6,
        m2 / m1,
        table / 1e6,
        m2 / (m1 + table)
    );
    println!(
        "rays per second: one {r1:.2} M, {count} copies {r2:.2} M ({:.2}x slower)",
        r1 / r2
    );
    Ok(())
}

fn main() -> Result<()> {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let number = |i: usize, default: u32| -> Result<u32> {
        args.get(i)
            .map_or(Ok(default), |s| s.parse().context("a whole number"))
    };
    match (args.first().map(String::as_str), args.get(1)) {
        (Some("deform"), Some(mesh)) => deform(Path::new(mesh), number(2, 100)?),
        (Some("instances"), Some(mesh)) => instances(Path::new(mesh), number(2, 10_000)?),
        (Some("measure-instances"), Some(mesh)) => {
            measure_instances(Path::new(mesh), number(2, 1)?)
        }
        (Some("instances-scene"), Some(mesh)) => {
            print!("{}", instances_scene(Path::new(mesh), number(2, 10_000)?)?);
            Ok(())
        }
        _ => bail!("usage: animation_bench deform MESH.obj [FRAMES] | instances MESH.obj [COUNT]"),
    }
}
