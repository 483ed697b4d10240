//! `radiant render --strategies DIR`: renders a frame on the CPU and
//! writes, beside the image, one linear EXR per sampling strategy of its
//! integrator (`bdpt`: `DIR/s{s}_t{t}.exr`, s light and t camera
//! vertices), each the strategy's MIS-weighted contributions — Veach's
//! per-strategy images, which sum to the image. What the flag cannot go
//! with is refused in `whole_cpu.rs`; what the frame cannot be split by,
//! by the library before anything renders.

use radiant::backend::{Progress, Written, cpu};
use radiant::extract::RenderScene;
use radiant::film::encoding::{Encoding, ExrSamples};
use radiant::film::output::write_encoded;
use std::path::Path;

/// Renders `scene`, writes each strategy's image to `dir` (created if
/// missing) as 32-bit float EXR and then the image to `path` (every file
/// atomically, the image last: an existing image means a finished
/// frame), and says on stderr how many were written.
pub(super) fn write(
    scene: &RenderScene,
    path: &Path,
    dir: &Path,
    progress: &Progress<'_>,
    note: &dyn Fn(&str),
) -> miette::Result<Written> {
    let (rendered, images) =
        cpu::try_render_strategies(scene, progress).map_err(|e| miette::miette!("{e}"))?;
    std::fs::create_dir_all(dir).map_err(|e| {
        miette::miette!(
            "cannot create the folder {} for --strategies: {e}",
            dir.display()
        )
    })?;
    // Half floats would round the images so that they no longer sum to
    // the image.
    let float = Encoding {
        exr: ExrSamples::Float,
        ..scene.settings.output
    };
    for (name, image) in &images {
        write_encoded(dir.join(format!("{name}.exr")), image, &float)
            .map_err(|e| miette::miette!("{e}"))?;
    }
    write_encoded(path, &rendered.image, &scene.settings.output)
        .map_err(|e| miette::miette!("{e}"))?;
    note(&format!(
        "{} per-strategy images (s light, t camera vertices) → {}",
        images.len(),
        dir.display()
    ));
    Ok(Written::from(&rendered))
}
