//! `radiant render --strategies DIR`: renders a frame on the CPU and
//! writes, beside the image, one linear EXR per sampling strategy of its
//! integrator (`bdpt`: `DIR/s{s}_t{t}.exr`, s light and t camera
//! vertices), each the strategy's MIS-weighted contributions — Veach's
//! per-strategy images, which sum to the image.

use super::RenderArgs;
use radiant::backend::{Progress, Written, cpu};
use radiant::extract::RenderScene;
use radiant::integrators::module::Family;
use radiant::settings::FilterSampling;
use std::path::Path;

/// Checks, before anything renders, that the images can be made as asked:
/// on the CPU, in one whole render of the image alone.
pub(super) fn check(args: &RenderArgs, planes: bool) -> miette::Result<()> {
    if args.strategies.is_none() {
        return Ok(());
    }
    let conflict = match super::whole_cpu_render_conflict(args, planes) {
        None if args.spp_map.is_some() => Some("--spp-map"),
        other => other,
    };
    match conflict {
        Some(what) => miette::bail!(
            "--strategies cannot be combined with {what}: it splits one whole CPU render by \
             strategy"
        ),
        None => Ok(()),
    }
}

/// Why `scene`'s frame cannot be split by strategy, if it cannot.
fn refusal(scene: &RenderScene) -> Option<String> {
    let s = &scene.settings;
    let name = cpu::integrator_name(scene);
    let Family::Tiles(tiles) = scene.integrator.family() else {
        return Some(no_strategies(scene));
    };
    if tiles.strategies(scene).is_empty() {
        return Some(no_strategies(scene));
    }
    if s.max_depth < 0 {
        return Some(format!(
            "--strategies needs a finite max_depth (one image per strategy of every path \
             length); the scene's `{name}` has max_depth -1: set it, or pass --max-depth N"
        ));
    }
    if s.adaptive.is_some() {
        return Some(
            "--strategies needs a fixed spp: the scene's sampler has `adaptive:`, whose \
             samples per pixel vary"
                .into(),
        );
    }
    if s.filter_sampling != FilterSampling::Splat {
        return Some(
            "--strategies needs `film: {filter_sampling: splat}` (the default): the \
             per-strategy images splat every contribution through the filter"
                .into(),
        );
    }
    None
}

/// The refusal of an integrator without strategies.
fn no_strategies(scene: &RenderScene) -> String {
    format!(
        "--strategies needs an integrator with sampling strategies to split (`bdpt`); the \
         scene's `{}` has none",
        cpu::integrator_name(scene)
    )
}

/// Renders `scene`, writes the image to `path` and each strategy's image
/// to `dir` (created if missing; every file atomically), and says on
/// stderr how many were written.
pub(super) fn write(
    scene: &RenderScene,
    path: &Path,
    dir: &Path,
    progress: &Progress<'_>,
    note: &dyn Fn(&str),
) -> miette::Result<Written> {
    if let Some(why) = refusal(scene) {
        miette::bail!("{why}");
    }
    std::fs::create_dir_all(dir).map_err(|e| {
        miette::miette!(
            "cannot create the folder {} for --strategies: {e}",
            dir.display()
        )
    })?;
    let (rendered, images) = cpu::try_render_strategies(scene, progress)
        .map_err(|e| miette::miette!("{e}"))?
        .ok_or_else(|| miette::miette!("{}", no_strategies(scene)))?;
    let output = &scene.settings.output;
    radiant::film::output::write_encoded(path, &rendered.image, output)
        .map_err(|e| miette::miette!("{e}"))?;
    for (name, image) in &images {
        radiant::film::output::write_encoded(dir.join(format!("{name}.exr")), image, output)
            .map_err(|e| miette::miette!("{e}"))?;
    }
    note(&format!(
        "{} per-strategy images (s light, t camera vertices) → {}",
        images.len(),
        dir.display()
    ));
    Ok(Written::from(&rendered))
}
