//! The CPU backend: the frame is cut into tiles, each tile's samples are
//! rendered as wavefront batches on a rayon worker, and tile films are
//! merged in tile order (so results do not depend on the thread count).

pub use super::{Progress, Rendered};
use crate::extract::RenderScene;
use crate::film::memory::FrameTooLarge;
use crate::film::{Film, Reconstruction, TileFilm};
use crate::integrators::path::{Batch, Wavefront};
use rayon::prelude::*;
use std::time::{Duration, Instant};

/// Tile edge in pixels.
const TILE: u32 = 16;
/// Paths per wavefront batch (about): a tile's pixels × a few samples.
const BATCH_PATHS: u32 = 1024;

/// Renders `scene` on all threads of the current rayon pool.
///
/// # Panics
///
/// Where the frame's film cannot be allocated; [`try_render`] reports
/// that instead.
pub fn render(scene: &RenderScene, progress: &Progress<'_>) -> Rendered {
    try_render(scene, progress).unwrap_or_else(|e| panic!("{e}"))
}

/// Renders `scene` as [`render`] does, or says what the frame needed where
/// its film cannot be allocated (before any sample is traced).
pub fn try_render(scene: &RenderScene, progress: &Progress<'_>) -> Result<Rendered, FrameTooLarge> {
    let s = &scene.settings;
    let mut film = Film::try_new(s.width, s.height)?;
    let pass = render_samples(scene, &mut film, 0..s.spp, progress);
    let image = film.try_develop()?;
    Ok(Rendered {
        image,
        time: pass.time,
        samples: pass.samples,
        rays: pass.rays,
        invalid_samples: film.invalid_samples,
    })
}

/// What one call of [`render_samples`] did.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Pass {
    /// Wall time of the pass.
    pub time: Duration,
    /// Camera paths traced (pixels × samples of the pass).
    pub samples: u64,
    /// Rays traced (camera, continuation and shadow rays).
    pub rays: u64,
}

/// Tiles each thread renders per group, at least (see [`render_samples`]).
const GROUP_TILES_PER_THREAD: usize = 16;

/// Progressive rendering: renders the sample indices `samples` of every
/// pixel and adds them to `film`. Calling it with consecutive ranges
/// (`0..4`, `4..8`, …) accumulates the same image as one render of all
/// of them, so a caller can develop the film between passes and watch the
/// estimate converge.
pub fn render_samples(
    scene: &RenderScene,
    film: &mut Film,
    samples: std::ops::Range<u32>,
    progress: &Progress<'_>,
) -> Pass {
    let start = Instant::now();
    let s = &scene.settings;
    let (w, h) = (s.width, s.height);
    let reconstruction = Reconstruction::new(scene.filter.as_ref(), s.filter_sampling);
    let tiles: Vec<(u32, u32)> = (0..h.div_ceil(TILE))
        .flat_map(|ty| (0..w.div_ceil(TILE)).map(move |tx| (tx * TILE, ty * TILE)))
        .collect();
    let spp = samples.len() as u32;
    let total = w as u64 * h as u64 * spp as u64;
    let done = std::sync::atomic::AtomicU64::new(0);
    let render_tile = |wave: &mut Wavefront, &(x0, y0): &(u32, u32)| {
        let (x1, y1) = ((x0 + TILE).min(w), (y0 + TILE).min(h));
        let pixels = (x1 - x0) * (y1 - y0);
        let chunk = (BATCH_PATHS / pixels).max(1);
        let mut tile = TileFilm::new(x0, y0, x1, y1, (w, h), reconstruction.reach());
        let rays_before = wave.rays;
        let mut first = samples.start;
        while first < samples.end {
            let count = chunk.min(samples.end - first);
            let batch = Batch {
                x0,
                y0,
                x1,
                y1,
                first_sample: first,
                samples: count,
            };
            wave.render(scene, batch, &reconstruction, &mut tile);
            first += count;
            if progress.is_active() {
                let n = pixels as u64 * count as u64;
                let d = done.fetch_add(n, std::sync::atomic::Ordering::Relaxed) + n;
                progress.report(d, total);
            }
        }
        (tile, wave.rays - rays_before)
    };
    // Tiles are rendered a group at a time and merged in tile order (so the
    // image does not depend on the thread count), which keeps the tile
    // films of one group in memory, not those of the whole image.
    let group =
        (w.div_ceil(TILE) as usize).max(GROUP_TILES_PER_THREAD * rayon::current_num_threads());
    let mut rays = 0;
    for tiles in tiles.chunks(group) {
        let results: Vec<(TileFilm, u64)> = tiles
            .par_iter()
            .map_init(Wavefront::default, render_tile)
            .collect();
        for (tile, r) in &results {
            film.merge(tile);
            rays += r;
        }
    }
    Pass {
        time: start.elapsed(),
        samples: total,
        rays,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::extract::{Overrides, extract};
    use crate::film::Image;
    use std::path::Path;

    /// Renders the Cornell box at `width`² pixels and `spp` on a pool of
    /// `threads` threads.
    fn cornell(width: u32, spp: u32, threads: usize) -> Image {
        // `expect` in this test code is the assertion: the committed scene
        // loads and extracts, and a thread pool can be built.
        let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("../scenes/cornell-box.yaml");
        let scene = crate::scene::load(&path).expect("scene loads");
        let overrides = Overrides {
            spp: Some(spp),
            width: Some(width),
            height: Some(width),
            ..Overrides::default()
        };
        let r = extract(&scene, &crate::builtin_registry(), &overrides).expect("scene extracts");
        rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .expect("thread pool")
            .install(|| render(&r, &Progress::none()).image)
    }

    #[test]
    fn images_do_not_depend_on_the_thread_count() {
        // 48² pixels are 9 tiles of 8 samples: threads take them in any
        // order, the film adds them up in tile order.
        let one = cornell(48, 8, 1);
        for threads in [2, 5] {
            assert!(
                one.pixels == cornell(48, 8, threads).pixels,
                "{threads} threads"
            );
        }
        assert!(one.mean() > 0.0);
    }
}
