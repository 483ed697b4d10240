//! `radiant info`: what a scene contains and what it needs.

use super::diagnostic::report;
use clap::Args;
use radiant::Registry;
use radiant::backend::{BvhLayout, GpuKernel};
use radiant::extract::{Overrides, RenderScene, extract};
use std::path::{Path, PathBuf};

/// Options of `radiant info`.
#[derive(Args)]
pub struct InfoArgs {
    /// The scene file.
    scene: PathBuf,
    /// With `gpu`, also list what the GPU kernel of the scene compiles in
    /// (module types, features); fails, naming it, where a module has no
    /// GPU code.
    #[arg(long, value_enum, default_value_t = InfoBackend::Cpu)]
    backend: InfoBackend,
    /// Write the scene's generated GPU kernel to DIR/kernel.wgsl (implies
    /// `--backend gpu`).
    #[arg(long, value_name = "DIR")]
    dump_wgsl: Option<PathBuf>,
    /// The GPU hierarchy layout to describe: `binary` (two child boxes per
    /// node) or `wide` (compressed wide BVH, eight children per node).
    #[arg(long, value_enum, default_value_t = BvhLayout::Binary)]
    gpu_bvh: BvhLayout,
    /// The GPU kernel to describe: `megakernel` or `wavefront` (stages).
    #[arg(long, value_enum, default_value_t = GpuKernel::Megakernel)]
    gpu_kernel: GpuKernel,
}

/// The backends `radiant info` can describe.
#[derive(Debug, Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
pub enum InfoBackend {
    /// The scene alone.
    Cpu,
    /// The scene and its GPU kernel.
    Gpu,
}

/// Prints what the GPU kernel of `r` compiles in; writes it to
/// `dump/kernel.wgsl` if asked.
#[cfg(feature = "gpu")]
fn gpu_kernel(
    r: &RenderScene,
    bvh: BvhLayout,
    kernel: GpuKernel,
    dump: Option<&Path>,
) -> miette::Result<()> {
    let plan = radiant::backend::gpu::Plan::with_bvh(r, bvh)
        .map_err(|e| miette::miette!("{e}"))?
        .for_kernel(kernel, false);
    for (kind, types) in plan.modules.summary() {
        if !types.is_empty() {
            println!("gpu {kind:<9} {}", types.join(", "));
        }
    }
    let features = plan.kernel.features.names();
    println!(
        "gpu features {}",
        if features.is_empty() {
            "none".to_string()
        } else {
            features.join(", ")
        }
    );
    println!("gpu bvh      {}", plan.geometry.layout);
    println!("gpu paths    {kernel}");
    println!(
        "gpu kernel   {} lines of WGSL, {} BVH nodes ({} KiB), {} primitives",
        plan.kernel.source.lines().count(),
        plan.geometry.node_count(),
        plan.geometry.nodes.len() * 16 / 1024,
        plan.geometry.prims.len() / plan.geometry.prim_rows()
    );
    if let Some(dir) = dump {
        std::fs::create_dir_all(dir)
            .map_err(|e| miette::miette!("cannot create `{}`: {e}", dir.display()))?;
        let file = dir.join("kernel.wgsl");
        std::fs::write(&file, &plan.kernel.source)
            .map_err(|e| miette::miette!("cannot write `{}`: {e}", file.display()))?;
        println!("gpu source   {}", file.display());
    }
    Ok(())
}

/// [`gpu_kernel`] in a build without the GPU backend: says how to get it.
#[cfg(not(feature = "gpu"))]
fn gpu_kernel(_: &RenderScene, _: BvhLayout, _: GpuKernel, _: Option<&Path>) -> miette::Result<()> {
    Err(miette::miette!(
        "{}",
        radiant::backend::RenderError::GpuNotBuilt
    ))
}

/// What besides shapes animates: the camera, lights, materials and
/// textures with keyframes.
fn animated_modules(scene: &radiant::scene::Scene) -> Vec<String> {
    use radiant::world::{CameraAnimation, CameraPose, EmitterSpec, LightSpec};
    let mut out = Vec::new();
    let world = &scene.world;
    for (pose, animation) in world
        .query::<(&CameraPose, Option<&CameraAnimation>)>()
        .iter()
    {
        if animation.is_some() || !pose.module.tracks.is_empty() {
            out.push(format!("camera {}", pose.module.type_name));
        }
    }
    for (spec, moving) in world
        .query::<(&LightSpec, Option<&radiant::world::Animation>)>()
        .iter()
    {
        if moving.is_some() || !spec.0.tracks.is_empty() {
            out.push(format!("light {}", spec.0.type_name));
        }
    }
    for spec in world.query::<&EmitterSpec>().iter() {
        if !spec.0.tracks.is_empty() {
            out.push(format!("emitter {}", spec.0.type_name));
        }
    }
    for (kind, list) in [("texture", &scene.textures), ("material", &scene.materials)] {
        for (name, spec) in list.iter() {
            if !spec.tracks.is_empty() {
                out.push(format!("{kind} {name}"));
            }
        }
    }
    out
}

/// Prints counts, modules and effects of the scene `args.scene`, and with
/// `--backend gpu` its GPU kernel.
pub fn run(registry: &Registry, args: &InfoArgs) -> miette::Result<()> {
    let path = &args.scene;
    let scene = radiant::scene::load(path).map_err(report)?;
    let r = extract(&scene, registry, &Overrides::default()).map_err(report)?;
    let s = &r.settings;
    println!("scene        {}", path.display());
    println!("film         {}x{}, {} spp", s.width, s.height, s.spp);
    let depth = if s.max_depth < 0 {
        "unlimited".to_string()
    } else {
        s.max_depth.to_string()
    };
    println!(
        "integrator   {}, max_depth {depth}, rr_depth {}",
        radiant::backend::cpu::integrator_name(&r),
        s.rr_depth
    );
    println!("triangles    {}", r.stats.triangles);
    println!("spheres      {}", r.stats.spheres);
    println!(
        "lights       {} ({} on shapes)",
        r.lights.len(),
        r.stats.emissive_shapes
    );
    println!("materials    {}", r.material_names.len());
    let modules: Vec<String> = r.modules.iter().map(|(k, t)| format!("{k} {t}")).collect();
    println!("modules      {}", modules.join(", "));
    println!("effects      {}", r.effects.names().join(", "));
    let repairs = &r.stats.repairs;
    println!(
        "repairs      {} non-finite and {} degenerate triangles dropped, {} vertex normals replaced, {} texture coordinates reset",
        repairs.non_finite, repairs.degenerate, repairs.bad_normals, repairs.bad_uvs
    );
    for (shape, what) in &r.stats.repaired_shapes {
        println!("             {shape}: {}", what.describe());
    }
    if repairs.missing_uvs {
        println!("uvs          missing in some meshes: (0,0), (1,0), (0,1) per triangle");
    }
    for warning in radiant::extract::facing::back_facing(&r) {
        eprintln!("warning: {warning}");
    }
    println!(
        "bvh build    {:.3} ms",
        r.stats.bvh_build.as_secs_f64() * 1e3
    );
    let t = &scene.timeline;
    let shutter = match t.shutter {
        Some((open, close)) => format!("shutter [{open}, {close}] frames (motion blur)"),
        None => "no shutter".to_string(),
    };
    println!(
        "animation    frames {}..{} ({} at {} fps), {shutter}",
        t.start,
        t.end,
        t.len(),
        t.fps
    );
    let st = &r.stats;
    let animated = animated_modules(&scene);
    println!(
        "animated     {} shapes moving, {} deforming meshes, {} other entities and modules with keyframes{}",
        st.animated_shapes,
        st.deforming_meshes,
        animated.len(),
        if animated.is_empty() {
            String::new()
        } else {
            format!(" ({})", animated.join(", "))
        }
    );
    println!(
        "instances    {} in the top level ({} instanced shapes), {} triangles placed",
        st.instances, st.instanced_shapes, st.instanced_triangles
    );
    if args.backend == InfoBackend::Gpu || args.dump_wgsl.is_some() {
        gpu_kernel(&r, args.gpu_bvh, args.gpu_kernel, args.dump_wgsl.as_deref())?;
    }
    Ok(())
}
