//! `radiant render --spp-map MAP.png`: renders a frame on the CPU counting
//! the image samples each pixel took, writes the image and, beside it, a
//! heat map of the counts — where adaptive sampling
//! (`sampler: {adaptive: …}`) spent its samples.

use radiant::backend::{Progress, Written, cpu};
use radiant::extract::RenderScene;
use radiant::integrators::module::Family;
use std::path::Path;

/// Renders `scene` counting samples per pixel, writes the image to `path`
/// and the heat map to `map` (both atomically), and says on stderr how
/// many samples pixels took (least, mean, most).
pub(super) fn write(
    scene: &RenderScene,
    path: &Path,
    map: &Path,
    progress: &Progress<'_>,
    note: &dyn Fn(&str),
) -> miette::Result<Written> {
    let chains = || {
        miette::miette!(
            "--spp-map needs a tile integrator: `{}` runs Markov chains, with no samples per pixel",
            cpu::integrator_name(scene)
        )
    };
    // Refused before rendering: a chain integrator's frame would be
    // rendered whole only to be dropped.
    if matches!(scene.integrator.family(), Family::Chains(_)) {
        return Err(chains());
    }
    let (rendered, counts) =
        cpu::try_render_counted(scene, progress).map_err(|e| miette::miette!("{e}"))?;
    let counts = counts.ok_or_else(chains)?;
    radiant::film::output::write_encoded(path, &rendered.image, &scene.settings.output)
        .map_err(|e| miette::miette!("{e}"))?;
    let most = counts.iter().copied().max().unwrap_or(0).max(1);
    let least = counts.iter().copied().min().unwrap_or(0);
    let mean = counts.iter().map(|&c| c as f64).sum::<f64>() / counts.len().max(1) as f64;
    let values: Vec<f32> = counts.iter().map(|&c| c as f32 / most as f32).collect();
    let s = &scene.settings;
    let heat = nv_flip::FlipImageFloat::with_data(s.width, s.height, &values);
    crate::cli::compare::write_heat_map(map, &heat).map_err(|e| miette::miette!("{e}"))?;
    note(&format!(
        "samples per pixel: least {least}, mean {mean:.1}, most {most} (the map's yellow) → {}",
        map.display()
    ));
    Ok(Written::from(&rendered))
}
