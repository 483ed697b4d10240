//! `radiant render` of a frame too large to keep its film whole (over 16
//! Mpixels, see `progressive.rs`): the CPU renders it in bands of rows
//! straight to its file (`radiant::backend::cpu::write_until`). Ctrl-C
//! stops it after the tiles in flight. A single frame's file is then
//! written, atomically, with the rows finished so far and black below
//! them, and the render says how many rows and samples it holds (the
//! caller exits with status 130); a frame of a sequence writes nothing,
//! so that its file appears only when it is finished. A banded frame keeps
//! no state for `--resume`: its film holds only the rows in flight, and a
//! state would be the whole film the bands exist to avoid.

use radiant::backend::{Backend, Interrupt, Progress, RenderError, Written};
use radiant::extract::RenderScene;
use std::path::Path;
use std::sync::atomic::Ordering;
use std::time::Duration;

/// Renders `scene` to `path` on `backend`, stopping where `interrupt` is
/// raised; says through `note` what an interrupted frame kept.
pub(super) fn write(
    backend: &mut dyn Backend,
    scene: &RenderScene,
    path: &Path,
    progress: &Progress<'_>,
    note: &dyn Fn(&str),
    interrupt: Interrupt<'_>,
) -> miette::Result<Written> {
    let s = &scene.settings;
    match backend.write_until(scene, path, progress, interrupt) {
        Ok(written) => {
            let row = u64::from(s.width) * u64::from(s.spp);
            let rows = written.samples / row.max(1);
            if interrupt.flag.load(Ordering::Relaxed) && rows < u64::from(s.height) {
                note(&format!(
                    "interrupted: the top {rows} of {} rows finished, {} samples ({} spp a \
                     pixel), written to {}; the rows below are black (a frame this large \
                     renders in bands and keeps no state for --resume: render it again to \
                     finish it)",
                    s.height,
                    written.samples,
                    s.spp,
                    path.display()
                ));
            }
            Ok(written)
        }
        Err(RenderError::Interrupted) => {
            note(if interrupt.keep {
                "interrupted before the first band of rows was finished: nothing written"
            } else {
                "interrupted: this frame is not written (a frame this large renders in bands \
                 and keeps no state; its file appears only when it is finished)"
            });
            Ok(Written {
                time: Duration::ZERO,
                samples: 0,
                rays: 0,
                invalid_samples: 0,
            })
        }
        Err(e) => Err(miette::miette!("{e}")),
    }
}
