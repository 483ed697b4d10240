//! The CPU backend: the frame is cut into tiles, each tile's samples are
//! rendered as wavefront batches on a rayon worker, and tile films are
//! merged in tile order (so results do not depend on the thread count).
//! Tiles are rendered a group of tile rows at a time. [`render_rows`]
//! holds only the band of film rows a group reaches
//! ([`film::band`](crate::film::band)) and hands finished rows to a row
//! encoder while the next group renders, so a frame written with
//! [`write`] needs memory in proportion to its width, not its area.

use super::RenderError;
pub use super::{Progress, Rendered, Written};
use crate::extract::RenderScene;
use crate::film::aov::{AovFilm, AovImage, AovTile};
use crate::film::band::Bands;
use crate::film::encode::{RowSink, write_encoded};
use crate::film::memory::FrameTooLarge;
use crate::film::{Film, Reconstruction, TileFilm};
use crate::integrators::path::{Batch, Wavefront};
use rayon::prelude::*;
use std::ops::Range;
use std::path::Path;
use std::sync::atomic::{AtomicU64, Ordering};
use std::time::{Duration, Instant};

/// Tile edge in pixels.
const TILE: u32 = 16;
/// Paths per wavefront batch (about): a tile's pixels × a few samples.
const BATCH_PATHS: u32 = 1024;
/// Tiles each thread renders per group, at least (see [`group_tile_rows`]).
const GROUP_TILES_PER_THREAD: usize = 16;
/// Groups of a whole-film pass are this many times larger: a pass may hold
/// a few samples of each tile, and every group ends in a wait for its last
/// tile, so small groups would wait more often than a banded render's do
/// (its groups hold all samples), while the tile films of a larger group
/// (about 32 KB a tile) are still few megabytes.
const WHOLE_GROUP_FACTOR: u32 = 8;

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

/// Renders `scene` as [`try_render`] does (the same image, bit for bit)
/// and also its output variables and alpha (see [`crate::film::aov`]):
/// the planes encoders and the denoiser read beside the image. The whole
/// film is held. Fails before any sample is traced where the films do not
/// fit in memory.
pub fn render_with_aovs(
    scene: &RenderScene,
    progress: &Progress<'_>,
) -> Result<(Rendered, AovImage), FrameTooLarge> {
    let s = &scene.settings;
    let mut film = Film::try_new(s.width, s.height)?;
    let mut aovs = AovFilm::try_new(s.width, s.height)?;
    let pass = render_samples_with_aovs(scene, &mut film, &mut aovs, 0..s.spp, progress);
    let rendered = Rendered {
        image: film.try_develop()?,
        time: pass.time,
        samples: pass.samples,
        rays: pass.rays,
        invalid_samples: film.invalid_samples,
    };
    Ok((rendered, aovs.develop()))
}

/// [`render_samples`] that also adds the camera rays' first hits to
/// `aovs` (whole films both): progressive rendering of the image and its
/// output variables.
pub fn render_samples_with_aovs(
    scene: &RenderScene,
    film: &mut Film,
    aovs: &mut AovFilm,
    samples: Range<u32>,
    progress: &Progress<'_>,
) -> Pass {
    Tiler::new(scene, samples, progress).whole(Tiler::render_aovs, |tiles| {
        for (tile, aov) in tiles {
            film.merge(tile);
            aovs.merge(aov);
        }
    })
}

/// Renders `scene` on all threads of the current rayon pool and writes the
/// image to `path` (atomically) as it goes, holding a band of the film
/// ([`band_tile_rows`] tile rows and the filter's reach):
/// the same image as [`render`], bit for bit. Fails before any sample is
/// traced where the band does not fit in memory.
pub fn write(
    scene: &RenderScene,
    path: &Path,
    progress: &Progress<'_>,
) -> Result<Written, RenderError> {
    let s = &scene.settings;
    let group = band_tile_rows(scene);
    write_encoded(path, &s.output, s.width, s.height, |rows| {
        render_rows(scene, rows, group, progress)
    })
}

/// Tile rows per group of a banded render on the current pool: one per
/// thread at least — a tile row is one EXR block of 16 scan lines, so
/// while the next group renders every thread has a block to compress —
/// and at least [`group_tile_rows`]; halved until the band fits in the
/// memory available, down to one tile row.
pub fn band_tile_rows(scene: &RenderScene) -> u32 {
    let s = &scene.settings;
    let threads = rayon::current_num_threads();
    let reach = Reconstruction::new(scene.filter.as_ref(), s.filter_sampling).reach();
    let mut group = group_tile_rows(s.width).max(threads as u32);
    while group > 1
        && Bands::new(s.width, s.height, TILE, group, reach)
            .need(threads)
            .check()
            .is_err()
    {
        group /= 2;
    }
    group
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

/// Tile rows per group for a frame `width` pixels wide on the current
/// pool: at least [`GROUP_TILES_PER_THREAD`] tiles per thread, so that
/// every thread stays busy until a group's last tiles, and at least one
/// tile row.
pub fn group_tile_rows(width: u32) -> u32 {
    let per_row = width.div_ceil(TILE).max(1) as usize;
    (GROUP_TILES_PER_THREAD * rayon::current_num_threads()).div_ceil(per_row) as u32
}

/// Progressive rendering: renders the sample indices `samples` of every
/// pixel and adds them to `film`, a whole film. Calling it with
/// consecutive ranges (`0..4`, `4..8`, …) accumulates the same image as
/// one render of all of them, so a caller can develop the film between
/// passes and watch the estimate converge.
pub fn render_samples(
    scene: &RenderScene,
    film: &mut Film,
    samples: Range<u32>,
    progress: &Progress<'_>,
) -> Pass {
    Tiler::new(scene, samples, progress).whole(Tiler::render, |tiles| film.merge_all(tiles))
}

/// Renders every sample of `scene` in groups of `group` tile rows and
/// hands the developed rows, top to bottom, to `rows`, holding only the
/// film rows a group reaches: the image of [`render`], bit for bit, since
/// tiles are rendered and merged exactly as there. Each group's finished
/// rows are encoded while the next group renders. Fails before any sample
/// is traced where the band does not fit in memory.
pub fn render_rows(
    scene: &RenderScene,
    rows: &mut dyn RowSink,
    group: u32,
    progress: &Progress<'_>,
) -> Result<Written, RenderError> {
    let start = Instant::now();
    let s = &scene.settings;
    let tiler = Tiler::new(scene, 0..s.spp, progress);
    let bands = tiler.bands(group);
    let threads = rayon::current_num_threads();
    // A thread's first allocation makes glibc reserve it an arena of
    // address space (64 MiB); let every thread take its own before
    // measuring what is left, so that under an address-space limit the
    // check sees what the render will have.
    rayon::broadcast(|_| std::hint::black_box(Vec::<u8>::with_capacity(1)));
    bands.need(threads).check()?;
    let too_large = || RenderError::Memory(bands.need(threads));
    let mut film = Film::try_band(s.width, s.height, bands.rows()).ok_or_else(too_large)?;
    let mut finished = Vec::new();
    finished
        .try_reserve_exact(bands.rows() as usize * s.width as usize)
        .map_err(|_| too_large())?;
    let mut rays = 0;
    for group in bands.groups() {
        let ((tiles, r), written) = rayon::join(
            || tiler.render(group.clone()),
            || rows.write_rows(&finished),
        );
        written?;
        finished.clear();
        film.merge_all(&tiles);
        rays += r;
        film.advance(bands.finished(&group), &mut finished)
            .map_err(|_| too_large())?;
    }
    rows.write_rows(&finished)?;
    Ok(Written {
        time: start.elapsed(),
        samples: tiler.total,
        rays,
        invalid_samples: film.invalid_samples,
    })
}

/// Renders the tiles of a frame's tile rows for one range of sample
/// indices, reporting progress as batches finish.
struct Tiler<'a> {
    scene: &'a RenderScene,
    reconstruction: Reconstruction,
    samples: Range<u32>,
    /// Camera paths of the whole pass.
    total: u64,
    /// Camera paths traced so far.
    done: AtomicU64,
    progress: &'a Progress<'a>,
}

impl<'a> Tiler<'a> {
    fn new(scene: &'a RenderScene, samples: Range<u32>, progress: &'a Progress<'a>) -> Self {
        let s = &scene.settings;
        Self {
            scene,
            reconstruction: Reconstruction::new(scene.filter.as_ref(), s.filter_sampling),
            total: s.width as u64 * s.height as u64 * samples.len() as u64,
            samples,
            done: AtomicU64::new(0),
            progress,
        }
    }

    /// The frame in groups of `group` tile rows.
    fn bands(&self, group: u32) -> Bands {
        let s = &self.scene.settings;
        Bands::new(s.width, s.height, TILE, group, self.reconstruction.reach())
    }

    /// Renders the whole frame, a group of tile rows at a time, with
    /// `render` (a method below) and hands each group's tiles to `merge` in
    /// tile order.
    fn whole<T>(
        &self,
        render: impl Fn(&Self, Range<u32>) -> (Vec<T>, u64),
        mut merge: impl FnMut(&[T]),
    ) -> Pass {
        let start = Instant::now();
        let mut rays = 0;
        let group = group_tile_rows(self.scene.settings.width) * WHOLE_GROUP_FACTOR;
        for group in self.bands(group).groups() {
            let (tiles, r) = render(self, group);
            merge(&tiles);
            rays += r;
        }
        Pass {
            time: start.elapsed(),
            samples: self.total,
            rays,
        }
    }

    /// Renders the tiles of tile rows `rows` on the pool's threads; returns
    /// their films in tile order (row by row, left to right) and the rays
    /// they traced.
    fn render(&self, rows: Range<u32>) -> (Vec<TileFilm>, u64) {
        let columns = self.scene.settings.width.div_ceil(TILE);
        let tiles: Vec<(u32, u32)> = rows
            .flat_map(|ty| (0..columns).map(move |tx| (tx * TILE, ty * TILE)))
            .collect();
        let results: Vec<(TileFilm, u64)> = tiles
            .par_iter()
            .map_init(Wavefront::default, |wave, &tile| {
                self.tile(wave, tile, None)
            })
            .collect();
        let rays = results.iter().map(|(_, r)| r).sum();
        (results.into_iter().map(|(tile, _)| tile).collect(), rays)
    }

    /// Renders the tiles of tile rows `rows` as [`Tiler::render`] does and
    /// records their first hits: each tile's film and output variables, in
    /// tile order, and the rays traced.
    fn render_aovs(&self, rows: Range<u32>) -> (Vec<(TileFilm, AovTile)>, u64) {
        let s = &self.scene.settings;
        let columns = s.width.div_ceil(TILE);
        let tiles: Vec<(u32, u32)> = rows
            .flat_map(|ty| (0..columns).map(move |tx| (tx * TILE, ty * TILE)))
            .collect();
        let results: Vec<(TileFilm, AovTile, u64)> = tiles
            .par_iter()
            .map_init(Wavefront::default, |wave, &(x0, y0)| {
                let (x1, y1) = ((x0 + TILE).min(s.width), (y0 + TILE).min(s.height));
                let size = (s.width, s.height);
                let reach = self.reconstruction.reach();
                let mut aovs = AovTile::new(x0, y0, x1, y1, size, reach);
                let (tile, rays) = self.tile(wave, (x0, y0), Some(&mut aovs));
                (tile, aovs, rays)
            })
            .collect();
        let rays = results.iter().map(|(_, _, r)| r).sum();
        let tiles = results.into_iter().map(|(t, a, _)| (t, a)).collect();
        (tiles, rays)
    }

    /// Renders the tile whose top left pixel is (`x0`, `y0`), adding its
    /// camera rays' first hits to `aovs` where given.
    fn tile(
        &self,
        wave: &mut Wavefront,
        (x0, y0): (u32, u32),
        mut aovs: Option<&mut AovTile>,
    ) -> (TileFilm, u64) {
        let (w, h) = (self.scene.settings.width, self.scene.settings.height);
        let (x1, y1) = ((x0 + TILE).min(w), (y0 + TILE).min(h));
        let pixels = (x1 - x0) * (y1 - y0);
        let chunk = (BATCH_PATHS / pixels).max(1);
        let mut tile = TileFilm::new(x0, y0, x1, y1, (w, h), self.reconstruction.reach());
        let rays_before = wave.rays;
        let mut first = self.samples.start;
        while first < self.samples.end {
            let count = chunk.min(self.samples.end - first);
            let batch = Batch {
                x0,
                y0,
                x1,
                y1,
                first_sample: first,
                samples: count,
            };
            match aovs.as_deref_mut() {
                Some(a) => {
                    wave.render_with_aovs(self.scene, batch, &self.reconstruction, &mut tile, a)
                }
                None => wave.render(self.scene, batch, &self.reconstruction, &mut tile),
            }
            first += count;
            if self.progress.is_active() {
                let n = pixels as u64 * count as u64;
                let d = self.done.fetch_add(n, Ordering::Relaxed) + n;
                self.progress.report(d, self.total);
            }
        }
        (tile, wave.rays - rays_before)
    }
}

#[cfg(test)]
pub(crate) mod tests {
    use super::*;
    use crate::extract::{Overrides, extract};
    use crate::film::Image;
    use crate::film::encode::write_with;
    use std::path::Path;

    /// The Cornell box at `width`×`height` pixels and `spp`.
    pub(crate) fn cornell_scene(width: u32, height: u32, spp: u32) -> RenderScene {
        // `expect` in this test code is the assertion: the committed scene
        // loads and extracts.
        let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("../scenes/cornell-box.yaml");
        let scene = crate::scene::load(&path).expect("scene loads");
        let overrides = Overrides {
            spp: Some(spp),
            width: Some(width),
            height: Some(height),
            ..Overrides::default()
        };
        extract(&scene, &crate::builtin_registry(), &overrides).expect("scene extracts")
    }

    /// Runs `f` on a pool of `threads` threads.
    fn on_threads<T: Send>(threads: usize, f: impl FnOnce() -> T + Send) -> T {
        rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .expect("thread pool")
            .install(f)
    }

    /// Renders the Cornell box at `width`² pixels and `spp` on a pool of
    /// `threads` threads.
    fn cornell(width: u32, spp: u32, threads: usize) -> Image {
        let r = cornell_scene(width, width, spp);
        on_threads(threads, || render(&r, &Progress::none()).image)
    }

    /// Collects the rows it is given, counting the calls.
    #[derive(Default)]
    struct Collect {
        pixels: Vec<radiant_core::Rgb>,
        calls: usize,
    }

    impl RowSink for Collect {
        fn write_rows(
            &mut self,
            rows: &[radiant_core::Rgb],
        ) -> Result<(), crate::film::output::ImageError> {
            self.pixels.extend_from_slice(rows);
            self.calls += 1;
            Ok(())
        }
    }

    #[test]
    fn bands_give_the_whole_film_image_bit_for_bit() {
        // 53 rows are 4 tile rows, the last one short; the gaussian reaches
        // 2 pixels, so rows finish 2 rows above each group's end.
        let r = cornell_scene(40, 53, 4);
        let whole = on_threads(2, || render(&r, &Progress::none()));
        for group in [1, 2, 3, 4] {
            let mut rows = Collect::default();
            let written = on_threads(2, || {
                render_rows(&r, &mut rows, group, &Progress::none()).expect("fits")
            });
            assert!(
                rows.pixels == whole.image.pixels,
                "groups of {group} tile rows"
            );
            assert_eq!(rows.calls, 4usize.div_ceil(group as usize) + 1);
            assert_eq!(written.rays, whole.rays);
            assert_eq!(written.samples, whole.samples);
        }
        assert!(whole.image.mean() > 0.0);
    }

    #[test]
    fn banded_files_match_whole_image_files() {
        // `expect` in this test code is the assertion.
        let dir = tempfile::tempdir().expect("a temporary folder");
        let r = cornell_scene(37, 45, 2);
        let whole = on_threads(2, || render(&r, &Progress::none()).image);
        for name in ["a.exr", "a.png"] {
            let (streamed, reference) =
                (dir.path().join(name), dir.path().join(format!("w{name}")));
            crate::film::output::write(&reference, &whole).expect("written");
            on_threads(2, || {
                write_with(&streamed, 37, 45, |rows| {
                    render_rows(&r, rows, 1, &Progress::none())
                })
            })
            .expect("written");
            let bytes = |p: &Path| std::fs::read(p).expect("readable");
            assert!(bytes(&streamed) == bytes(&reference), "{name}");
        }
        let read = crate::film::output::read_exr(dir.path().join("a.exr")).expect("an EXR");
        assert!(read == whole);
    }

    #[test]
    fn a_failed_render_leaves_no_file() {
        let dir = tempfile::tempdir().expect("a temporary folder");
        let out = dir.path().join("x.exr");
        let r = cornell_scene(16, 16, 1);
        let failed: Result<(), RenderError> = write_with(&out, 16, 16, |rows| {
            rows.write_rows(&[radiant_core::Rgb::ZERO; 16])?;
            Err(RenderError::Memory(FrameTooLarge::new(16, 16)))
        });
        assert!(matches!(failed, Err(RenderError::Memory(_))));
        let short: Result<(), RenderError> = write_with(&out, 16, 16, |rows| {
            Ok(rows.write_rows(&[radiant_core::Rgb::ZERO; 32])?)
        });
        assert!(short.is_err(), "two of 16 rows are not an image");
        assert_eq!(std::fs::read_dir(dir.path()).expect("listed").count(), 0);
        on_threads(1, || write(&r, &out, &Progress::none())).expect("written");
        assert!(out.exists());
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
