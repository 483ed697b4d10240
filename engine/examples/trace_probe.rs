//! Micro-benchmark of the ray-tracing core ([`radiant::accel`]): nanoseconds
//! per closest-hit ray and per shadow ray, single-threaded, traced in
//! batches as the renderer traces them (`Accel::intersect_slots`,
//! `Accel::occluded_each`).
//!
//! * Cornell box (`scenes/cornell-box.yaml`, 36 triangles): rays start at
//!   random points inside the box and go in random directions; shadow rays
//!   are the same rays cut at distance 0.5. Measured twice: as the renderer
//!   queries a scene of static shapes (one hierarchy, no top level), and
//!   through a top level with one instance under an identity transform.
//! * Optionally a mesh given on the command line (e.g. the 69k-triangle
//!   Stanford bunny): rays start on a sphere around the mesh and aim at
//!   random points of its bounding box; shadow rays end at that point.
//! * With `--instances N`, also a field of N turned and scaled copies of
//!   the mesh, instances of one bottom level under a top level: rays from
//!   near a camera above the field's edge towards random points of the
//!   field's box.
//!
//! Each query runs over the same rays several times; the fastest pass is
//! reported, which keeps noise from other processes out of the numbers.
//! `--rays N --passes N --mesh-only` make a run small enough to profile
//! under callgrind (`--mesh-only` skips the Cornell box).
//!
//! `--cornell-obj OUT.obj` also writes the Cornell box's triangles as the
//! probe traces them (render space) to an OBJ file, so that
//! `engine/benches/embree_peer.py --cornell` can time Embree on the same
//! triangles with the same ray distribution.
//!
//! ```text
//! cargo run --release --example trace_probe [-- [--cornell-obj OUT.obj] [--rays N] [--passes N] [--mesh-only] [--instances N] path/to/mesh.obj]
//! ```

use anyhow::{Context, Result};
use glam::Vec3;
use radiant::accel::{Accel, BuildQuality, Hit, Instance, Place, Placement, Primitive};
use radiant::extract::{Overrides, extract};
use std::fmt::Write as _;
use std::hint::black_box;
use std::path::{Path, PathBuf};
use std::time::Instant;

/// How much to measure: rays per pass and passes per query (the fastest
/// counts). Fewer of both make a profile under callgrind affordable.
#[derive(Debug, Clone, Copy)]
struct Size {
    rays: usize,
    passes: usize,
}

impl Default for Size {
    fn default() -> Self {
        Self {
            rays: 1_000_000,
            passes: 5,
        }
    }
}

/// A ray query: origin, direction and the distance it is traced to.
type Query = (Vec3, Vec3, f32);

/// A small deterministic generator of uniform numbers in [0, 1).
struct Lcg(u64);

impl Lcg {
    fn next(&mut self) -> f32 {
        self.0 = self
            .0
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        (self.0 >> 40) as f32 / (1u64 << 24) as f32
    }

    fn vec3(&mut self) -> Vec3 {
        Vec3::new(self.next(), self.next(), self.next())
    }

    fn direction(&mut self) -> Vec3 {
        loop {
            let v = self.vec3() * 2.0 - 1.0;
            let l2 = v.length_squared();
            if l2 > 1e-4 && l2 <= 1.0 {
                return v / l2.sqrt();
            }
        }
    }
}

/// Times `accel` on closest-hit rays `closest` and shadow rays `shadow`,
/// as the renderer traces them: in batches ([`Accel::intersect_slots`],
/// [`Accel::occluded_each`]).
fn measure(name: &str, accel: &Accel, closest: &[Query], shadow: &[Query], size: Size) {
    let origins: Vec<Vec3> = closest.iter().map(|q| q.0).collect();
    let dirs: Vec<Vec3> = closest.iter().map(|q| q.1).collect();
    let slots: Vec<u32> = (0..closest.len() as u32).collect();
    let mut hit = vec![Hit::MISS; closest.len()];
    // Shadow rays as the renderer spawns them: the direction spans the
    // segment, which ends at t = 1.
    let shadow_origins: Vec<Vec3> = shadow.iter().map(|q| q.0).collect();
    let shadow_dirs: Vec<Vec3> = shadow.iter().map(|q| q.1 * q.2).collect();
    let mut is_blocked = vec![false; shadow.len()];
    let mut best = [f64::INFINITY; 2];
    for _ in 0..size.passes {
        let start = Instant::now();
        accel.intersect_slots(&slots, black_box(&origins), &dirs, None, &mut hit);
        best[0] = best[0].min(start.elapsed().as_secs_f64());
        let start = Instant::now();
        accel.occluded_each(
            black_box(&shadow_origins),
            &shadow_dirs,
            None,
            1.0,
            &mut is_blocked,
        );
        best[1] = best[1].min(start.elapsed().as_secs_f64());
    }
    let hits = hit.iter().filter(|h| h.prim != Hit::MISS.prim).count();
    let blocked = is_blocked.iter().filter(|&&b| b).count();
    let ns = |s: f64, n: usize| s / n as f64 * 1e9;
    println!(
        "{name}: {} primitives, built in {:.1} ms",
        accel.blases().iter().map(|b| b.len()).sum::<usize>(),
        accel.build_time.as_secs_f64() * 1e3
    );
    println!(
        "  closest:  {:6.1} ns/ray ({hits} of {} hit)",
        ns(best[0], closest.len()),
        closest.len()
    );
    println!(
        "  occluded: {:6.1} ns/ray ({blocked} of {} blocked)",
        ns(best[1], shadow.len()),
        shadow.len()
    );
}

/// Writes the triangles of `prims` as an OBJ file (three vertices per face).
fn write_obj(prims: &[Primitive], path: &Path) -> Result<()> {
    let mut obj = String::new();
    for (face, prim) in prims.iter().enumerate() {
        let Primitive::Triangle(v) = prim else {
            anyhow::bail!("the scene has a non-triangle primitive; OBJ holds triangles only");
        };
        for p in v {
            writeln!(obj, "v {} {} {}", p.x, p.y, p.z)?;
        }
        writeln!(obj, "f {} {} {}", face * 3 + 1, face * 3 + 2, face * 3 + 3)?;
    }
    std::fs::write(path, obj).with_context(|| format!("writing {}", path.display()))
}

/// Rays inside the Cornell box (render space puts the camera at the origin
/// and the box's centre at z = -3.9); writes its triangles to `obj` if given.
fn cornell(rng: &mut Lcg, obj: Option<&Path>, size: Size) -> Result<()> {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("../scenes/cornell-box.yaml");
    let scene = radiant::scene::load(&path)?;
    let render = extract(&scene, &radiant::builtin_registry(), &Overrides::default())?;
    if let Some(obj) = obj {
        write_obj(render.accel.blases()[0].primitives(), obj)?;
    }
    let closest: Vec<Query> = (0..size.rays)
        .map(|_| {
            let o = (rng.vec3() * 1.8 - 0.9) - Vec3::new(0.0, 0.0, 3.9);
            (o, rng.direction(), f32::INFINITY)
        })
        .collect();
    let shadow: Vec<Query> = closest.iter().map(|&(o, d, _)| (o, d, 0.5)).collect();
    measure("cornell box", &render.accel, &closest, &shadow, size);
    // The same bottom level entered through a top level and an (identity)
    // transform, as it would be without the direct path for static scenes.
    let blas = render.accel.blases()[0].clone();
    let place = Placement::new(glam::DMat4::IDENTITY).context("the identity is invertible")?;
    let two = Accel::new(
        vec![blas],
        vec![Instance {
            blas: 0,
            place: Place::Fixed(place),
        }],
        BuildQuality::High,
    );
    measure(
        "cornell box through a top level",
        &two,
        &closest,
        &shadow,
        size,
    );
    Ok(())
}

/// Rays from a sphere around the mesh at `path` towards its bounding box.
fn mesh(path: &Path, rng: &mut Lcg, size: Size, instances: Option<usize>) -> Result<()> {
    let mesh = radiant::scene::mesh::load(path, radiant::scene::mesh::MeshOptions::default())
        .map_err(anyhow::Error::msg)?;
    let prims: Vec<Primitive> = mesh
        .triangles
        .iter()
        .map(|t| Primitive::Triangle(t.map(|i| mesh.positions[i as usize])))
        .collect();
    let (accel, _) = Accel::build(&prims, BuildQuality::default_for(prims.len()));
    let (lo, hi) = mesh
        .positions
        .iter()
        .fold((Vec3::INFINITY, Vec3::NEG_INFINITY), |(lo, hi), &p| {
            (lo.min(p), hi.max(p))
        });
    let centre = (lo + hi) * 0.5;
    let radius = (hi - lo).length();
    let (closest, shadow) = aimed(rng, size, (lo, hi), |rng| centre + rng.direction() * radius);
    let name = path.file_name().unwrap_or(path.as_os_str());
    measure(&name.to_string_lossy(), &accel, &closest, &shadow, size);
    if let Some(count) = instances {
        field(&prims, (lo, hi), count, rng, size)?;
    }
    Ok(())
}

/// Rays from the points `from` draws towards uniform points of the box
/// (`lo`, `hi`): as closest-hit queries, and as shadow rays that end at
/// those points.
fn aimed(
    rng: &mut Lcg,
    size: Size,
    (lo, hi): (Vec3, Vec3),
    from: impl Fn(&mut Lcg) -> Vec3,
) -> (Vec<Query>, Vec<Query>) {
    let shadow: Vec<Query> = (0..size.rays)
        .map(|_| {
            let o = from(rng);
            let target = lo + rng.vec3() * (hi - lo);
            let d = (target - o).normalize();
            (o, d, (target - o).length())
        })
        .collect();
    let closest = shadow
        .iter()
        .map(|&(o, d, _)| (o, d, f32::INFINITY))
        .collect();
    (closest, shadow)
}

/// `count` copies of the mesh `prims` (bounds `lo`, `hi`) on a grid, each
/// turned about the vertical and scaled by 0.8–1.2, as instances of one
/// bottom level; rays from near a camera above the field's edge towards
/// uniform points of the field's box (shadow rays end there), as in
/// `animation_bench instances`.
fn field(
    prims: &[Primitive],
    (lo, hi): (Vec3, Vec3),
    count: usize,
    rng: &mut Lcg,
    size: Size,
) -> Result<()> {
    let extent = (hi - lo).max_element();
    let side = (count as f32).sqrt().ceil() as usize;
    let spacing = extent * 1.6;
    let h = spacing * side as f32 / 2.0;
    let centre = (lo + hi) * 0.5;
    let instances = (0..count)
        .map(|i| {
            let at = Vec3::new(
                (i % side) as f32 * spacing - h,
                0.0,
                (i / side) as f32 * spacing - h,
            );
            let m = glam::DMat4::from_scale_rotation_translation(
                glam::DVec3::splat(0.8 + 0.4 * f64::from(rng.next())),
                glam::DQuat::from_rotation_y(f64::from(rng.next()) * std::f64::consts::TAU),
                (at - centre).as_dvec3(),
            );
            let place = Placement::new(m).context("a turn and a scale are invertible")?;
            Ok(Instance {
                blas: 0,
                place: Place::Fixed(place),
            })
        })
        .collect::<Result<Vec<_>>>()?;
    let blas = radiant::accel::Blas::build(prims, None, BuildQuality::default_for(prims.len()));
    let accel = Accel::new(vec![blas], instances, BuildQuality::default_for(count));
    let camera = Vec3::new(0.0, 2.5 * extent, h + extent);
    let (box_lo, box_hi) = (Vec3::new(-h, -extent, -h), Vec3::new(h, extent, h));
    let (closest, shadow) = aimed(rng, size, (box_lo, box_hi), |rng| {
        camera + (rng.vec3() - 0.5) * extent
    });
    measure(
        &format!("field of {count}"),
        &accel,
        &closest,
        &shadow,
        size,
    );
    Ok(())
}

fn main() -> Result<()> {
    let mut args = std::env::args_os().skip(1);
    let mut cornell_obj: Option<PathBuf> = None;
    let mut mesh_path: Option<PathBuf> = None;
    let mut size = Size::default();
    let mut mesh_only = false;
    let mut instances = None;
    let count = |args: &mut dyn Iterator<Item = std::ffi::OsString>, flag: &str| {
        let value = args
            .next()
            .with_context(|| format!("{flag} needs a count"))?;
        value
            .to_str()
            .and_then(|v| v.parse::<usize>().ok())
            .filter(|&n| n > 0)
            .with_context(|| format!("{flag} {value:?}: not a positive whole number"))
    };
    while let Some(arg) = args.next() {
        if arg == "--cornell-obj" {
            let out = args.next().context("--cornell-obj needs an output path")?;
            cornell_obj = Some(out.into());
        } else if arg == "--mesh-only" {
            mesh_only = true;
        } else if arg == "--instances" {
            instances = Some(count(&mut args, "--instances")?);
        } else if arg == "--rays" {
            size.rays = count(&mut args, "--rays")?;
        } else if arg == "--passes" {
            size.passes = count(&mut args, "--passes")?;
        } else if mesh_path.is_none() {
            mesh_path = Some(arg.into());
        } else {
            anyhow::bail!(
                "unexpected argument {arg:?}; usage: trace_probe [--cornell-obj OUT.obj] \
                 [--rays N] [--passes N] [--mesh-only] [--instances N] [MESH.obj]"
            );
        }
    }
    let mut rng = Lcg(12345);
    if !mesh_only {
        cornell(&mut rng, cornell_obj.as_deref(), size).context("Cornell box benchmark")?;
    }
    if let Some(path) = mesh_path {
        mesh(&path, &mut rng, size, instances).context("mesh benchmark")?;
    }
    Ok(())
}
