//! `radiant info`: what a scene contains and what it needs.

use super::diagnostic::report;
use radiant::Registry;
use radiant::extract::{Overrides, extract};
use std::path::Path;

/// Prints counts, modules and effects of the scene at `path`.
pub fn run(registry: &Registry, path: &Path) -> miette::Result<()> {
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
        "integrator   path, max_depth {depth}, rr_depth {}",
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
    println!(
        "bvh build    {:.3} ms",
        r.stats.bvh_build.as_secs_f64() * 1e3
    );
    Ok(())
}
