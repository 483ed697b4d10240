//! The CPU backend: the drivers of the integrator families
//! ([`crate::integrators::module`]). For a tile integrator the frame is cut
//! into tiles, each tile's samples are rendered as batches by the
//! integrator's worker on a rayon thread, and tile films are merged in
//! tile order (so results do not depend on the thread count); splatting
//! tile integrators also get a whole-image [`SplatFilm`], and under
//! adaptive sampling each tile runs its own rounds
//! ([`crate::integrators::adaptive`]). A Markov-chain integrator renders
//! the whole frame into a [`SplatFilm`] itself.
//! Tiles are rendered a group of tile rows at a time. [`render_rows`]
//! holds only the band of film rows a group reaches
//! ([`film::band`](crate::film::band)) and hands finished rows to a row
//! encoder while the next group renders, so a frame written with
//! [`write`] needs memory in proportion to its width, not its area.

use super::{Interrupt, RenderError};
pub use super::{Progress, Rendered, Written};
use crate::extract::RenderScene;
use crate::film::aov::{AovFilm, AovImage, AovTile};
use crate::film::band::Bands;
use crate::film::encode::{BLOCK_ROWS, RowSink, write_encoded};
use crate::film::memory::FrameTooLarge;
use crate::film::{Film, Image, Reconstruction, TileFilm};
use crate::integrators::adaptive::{self, ErrorGoal, TileRect};
use crate::integrators::budget::{self, Pilot};
use crate::integrators::module::batches;
use crate::integrators::strategies::{self, StrategiesError, StrategyFilms, StrategyImages};
use crate::integrators::{
    Batch, ChainContext, Family, SplatFilm, TileContext, TileIntegrator, TileOutput, TileWorker,
};
use radiant_core::Rgb;
use rayon::prelude::*;
use std::ops::Range;
use std::path::Path;
use std::sync::atomic::{AtomicBool, AtomicU64, Ordering};
use std::time::{Duration, Instant};

/// Tile edge in pixels.
const TILE: u32 = 16;
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
    let tiles = match scene.integrator.family() {
        Family::Tiles(tiles) => tiles,
        Family::Chains(chains) => {
            let splats = SplatFilm::new(s.width, s.height, scene.filter.as_ref())?;
            let start = Instant::now();
            let pass = chains.render(&ChainContext {
                scene,
                spp: s.spp,
                splats: &splats,
                progress,
            });
            let mut image = black_image(s.width, s.height)?;
            splats.add_to(&mut image, pass.scale);
            return Ok(Rendered {
                image,
                time: start.elapsed(),
                samples: pass.samples,
                rays: pass.rays,
                invalid_samples: splats.invalid_samples(),
            });
        }
    };
    Ok(render_tiles(scene, tiles, progress, false, None)?.0)
}

/// Renders `scene` as [`try_render`] does (the same image) and also
/// counts the image samples each pixel took (row-major): what adaptive
/// sampling spent where (`--spp-map`). A Markov-chain integrator has no
/// samples per pixel: `None` for it.
pub fn try_render_counted(
    scene: &RenderScene,
    progress: &Progress<'_>,
) -> Result<(Rendered, Option<Vec<u32>>), FrameTooLarge> {
    match scene.integrator.family() {
        Family::Tiles(tiles) => render_tiles(scene, tiles, progress, true, None),
        Family::Chains(_) => Ok((try_render(scene, progress)?, None)),
    }
}

/// Renders `scene` as [`try_render`] does (the same image) and also its
/// per-strategy images ([`crate::integrators::strategies`]), by name; or
/// says, before anything renders, why its frame cannot be split by
/// strategy or does not fit in memory.
pub fn try_render_strategies(
    scene: &RenderScene,
    progress: &Progress<'_>,
) -> Result<(Rendered, StrategyImages), StrategiesError> {
    let (tiles, names) = strategies::tile_strategies(scene)?;
    let films = StrategyFilms::new(names, scene)?;
    let (rendered, _) = render_tiles(scene, tiles, progress, false, Some(&films))?;
    let s = &scene.settings;
    let images = films.develop(s.width, s.height, rendered.samples)?;
    Ok((rendered, images))
}

/// Renders all samples of `scene` with the tile integrator `tiles` into a
/// whole film (and splat film), counting each pixel's samples where
/// `count` and splitting contributions by strategy into `strategies` where
/// given.
fn render_tiles(
    scene: &RenderScene,
    tiles: &dyn TileIntegrator,
    progress: &Progress<'_>,
    count: bool,
    strategies: Option<&StrategyFilms>,
) -> Result<(Rendered, Option<Vec<u32>>), FrameTooLarge> {
    let s = &scene.settings;
    let mut film = Film::try_new(s.width, s.height)?;
    let splats = frame_splats(scene, tiles)?;
    let mut tiler = Tiler::new(scene, tiles, splats.as_ref(), 0..s.spp, progress);
    tiler.strategies = strategies;
    if count {
        let counts = crate::film::memory::try_filled(s.width as usize * s.height as usize, 0u32)
            .ok_or_else(|| FrameTooLarge::new(s.width, s.height))?;
        tiler.counts = Some(std::sync::Mutex::new(counts));
    }
    let pass = tiler.whole(Tiler::render, |tiles| film.merge_all(tiles));
    let mut image = film.try_develop()?;
    let invalid_splats = add_splats(splats.as_ref(), &mut image, pass.samples);
    let counts = tiler
        .counts
        .take()
        .map(|c| c.into_inner().unwrap_or_else(|e| e.into_inner()));
    let rendered = Rendered {
        image,
        time: pass.time,
        samples: pass.samples,
        rays: pass.rays,
        invalid_samples: film.invalid_samples + invalid_splats,
    };
    Ok((rendered, counts))
}

/// A black image of `width × height`, or what the frame needed.
fn black_image(width: u32, height: u32) -> Result<Image, FrameTooLarge> {
    let pixels = crate::film::memory::try_filled(width as usize * height as usize, Rgb::ZERO)
        .ok_or_else(|| FrameTooLarge::new(width, height))?;
    Ok(Image {
        width,
        height,
        pixels,
    })
}

/// The whole-image splat film of a frame rendered by `tiles`, where it
/// splats.
fn frame_splats(
    scene: &RenderScene,
    tiles: &dyn TileIntegrator,
) -> Result<Option<SplatFilm>, FrameTooLarge> {
    let s = &scene.settings;
    tiles
        .splats()
        .then(|| SplatFilm::new(s.width, s.height, scene.filter.as_ref()))
        .transpose()
}

/// Adds `splats` to `image`, scaled by the pixels over the camera samples
/// `samples` (one light path per camera sample, so 1 / spp at a fixed
/// spp); returns the invalid splats.
fn add_splats(splats: Option<&SplatFilm>, image: &mut Image, samples: u64) -> u64 {
    let Some(splats) = splats else {
        return 0;
    };
    let pixels = image.width as f64 * image.height as f64;
    splats.add_to(image, pixels / samples.max(1) as f64);
    splats.invalid_samples()
}

/// The tile integrator of `scene` where it renders in passes of sample
/// ranges — a tile integrator that does not splat (under adaptive
/// sampling, passes render shares of each pixel's count, see
/// [`adaptive::pass_share`]) — or why it cannot: `--time`, `--checkpoint`, `--resume` and
/// `--partition` render in passes, and the banded writer needs the same.
pub fn passes(scene: &RenderScene) -> Result<&dyn TileIntegrator, RenderError> {
    let refuse = |why: &str| {
        Err(RenderError::NoPasses(format!(
            "{why}; `--time`, `--checkpoint`, `--resume`, `--partition` and `radiant merge` need \
             renders in passes of whole samples of every pixel"
        )))
    };
    let name = integrator_name(scene);
    match scene.integrator.family() {
        Family::Chains(_) => refuse(&format!(
            "the integrator `{name}` runs Markov chains over the whole image"
        )),
        Family::Tiles(t) if t.splats() => refuse(&format!(
            "the integrator `{name}` splats light paths over the whole image"
        )),
        Family::Tiles(t) => Ok(t),
    }
}

/// The scene's integrator type, for messages.
pub fn integrator_name(scene: &RenderScene) -> &str {
    scene
        .modules
        .iter()
        .find(|(kind, _)| *kind == radiant_core::ModuleKind::Integrator)
        .map_or("path", |(_, name)| name.as_str())
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
    let Family::Tiles(tiles) = scene.integrator.family() else {
        // A Markov-chain render has no camera rays of its own: its
        // output variables are those of the camera's first hits, rendered
        // with `path`'s camera rays alone.
        let rendered = try_render(scene, progress)?;
        let mut aovs = AovFilm::try_new(s.width, s.height)?;
        let path = crate::integrators::module::PathIntegrator;
        Tiler::new(scene, &path, None, 0..s.spp.min(4), &Progress::none()).whole(
            Tiler::render_aovs,
            |tiles| {
                for (_, aov) in tiles {
                    aovs.merge(aov);
                }
            },
        );
        return Ok((rendered, aovs.develop()));
    };
    let mut film = Film::try_new(s.width, s.height)?;
    let mut aovs = AovFilm::try_new(s.width, s.height)?;
    let splats = frame_splats(scene, tiles)?;
    let pass = Tiler::new(scene, tiles, splats.as_ref(), 0..s.spp, progress).whole(
        Tiler::render_aovs,
        |tiles| {
            for (tile, aov) in tiles {
                film.merge(tile);
                aovs.merge(aov);
            }
        },
    );
    let mut image = film.try_develop()?;
    let invalid_splats = add_splats(splats.as_ref(), &mut image, pass.samples);
    let rendered = Rendered {
        image,
        time: pass.time,
        samples: pass.samples,
        rays: pass.rays,
        invalid_samples: film.invalid_samples + invalid_splats,
    };
    Ok((rendered, aovs.develop()))
}

/// [`render_samples`] that also adds the camera rays' first hits to
/// `aovs` (whole films both): progressive rendering of the image and its
/// output variables.
///
/// # Panics
///
/// Where the scene does not render in passes ([`passes`]).
pub fn render_samples_with_aovs(
    scene: &RenderScene,
    film: &mut Film,
    aovs: &mut AovFilm,
    samples: Range<u32>,
    progress: &Progress<'_>,
) -> Pass {
    let tiles = passes(scene).unwrap_or_else(|e| panic!("{e}"));
    let decided = film_decisions(scene, tiles, film);
    let mut tiler = Tiler::new(scene, tiles, None, samples, progress);
    tiler.decided = decided.as_deref();
    let pass = tiler.whole(Tiler::render_aovs, |tiles| {
        for (tile, aov) in tiles {
            film.merge(tile);
            aovs.merge(aov);
        }
    });
    film.adaptive_counts = decided;
    pass
}

/// Under adaptive sampling, the image samples each pixel of the frame
/// takes, from `film` where an earlier pass decided them, else decided
/// now (all tiles, on the pool's threads); `None` without adaptive
/// sampling. The caller puts them back in the film after the pass.
fn film_decisions(
    scene: &RenderScene,
    tiles: &dyn TileIntegrator,
    film: &mut Film,
) -> Option<Vec<u32>> {
    let a = scene.settings.adaptive.as_ref()?;
    if let Some(counts) = film.adaptive_counts.take() {
        return Some(counts);
    }
    let s = &scene.settings;
    let none = Progress::none();
    Some(Tiler::new(scene, tiles, None, 0..s.spp, &none).frame_counts(a))
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
    write_until(scene, path, progress, Interrupt::NEVER)
}

/// [`write`], stopping early where `interrupt` is raised (Ctrl-C): the
/// tiles in flight finish, the group they belong to is dropped, and the
/// file gets the rows of the groups merged so far and black below them, as
/// [`render_rows`] says (nothing where `interrupt.keep` is false, or no
/// group was merged: [`RenderError::Interrupted`]). A scene that does not
/// render in bands (splats) renders whole and does not stop ([`passes`]
/// says which).
pub fn write_until(
    scene: &RenderScene,
    path: &Path,
    progress: &Progress<'_>,
    interrupt: Interrupt<'_>,
) -> Result<Written, RenderError> {
    let s = &scene.settings;
    if passes(scene).is_err() {
        // Splats and adaptive decisions reach the whole image: render it
        // whole, then write it.
        FrameTooLarge::new(s.width, s.height).check()?;
        let rendered = try_render(scene, progress)?;
        crate::film::output::write_encoded(path, &rendered.image, &s.output)?;
        return Ok(Written::from(&rendered));
    }
    let group = band_tile_rows(scene);
    write_encoded(path, &s.output, s.width, s.height, |rows| {
        render_rows(scene, rows, group, progress, interrupt)
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
///
/// # Panics
///
/// Where the scene does not render in passes ([`passes`]).
pub fn render_samples(
    scene: &RenderScene,
    film: &mut Film,
    samples: Range<u32>,
    progress: &Progress<'_>,
) -> Pass {
    let tiles = passes(scene).unwrap_or_else(|e| panic!("{e}"));
    let decided = film_decisions(scene, tiles, film);
    let mut tiler = Tiler::new(scene, tiles, None, samples, progress);
    tiler.decided = decided.as_deref();
    let pass = tiler.whole(Tiler::render, |tiles| film.merge_all(tiles));
    film.adaptive_counts = decided;
    pass
}

/// Renders every sample of `scene` in groups of `group` tile rows and
/// hands the developed rows, top to bottom, to `rows`, holding only the
/// film rows a group reaches: the image of [`render`], bit for bit, since
/// tiles are rendered and merged exactly as there. Each group's finished
/// rows are encoded while the next group renders. Fails before any sample
/// is traced where the band does not fit in memory.
///
/// Where `interrupt` is raised, tiles not yet started are skipped and
/// their group dropped; the rows of the groups merged before it are
/// handed on, each with all its own samples (the last few lack only the
/// next group's splats, and are normalised by the weights they have),
/// and the rest of the image is black. [`Written::samples`] counts the
/// samples of the merged rows. Where no group was merged, or
/// `interrupt.keep` is false, it fails with [`RenderError::Interrupted`]
/// instead.
pub fn render_rows(
    scene: &RenderScene,
    rows: &mut dyn RowSink,
    group: u32,
    progress: &Progress<'_>,
    interrupt: Interrupt<'_>,
) -> Result<Written, RenderError> {
    let start = Instant::now();
    let s = &scene.settings;
    let tiles = passes(scene)?;
    let mut tiler = Tiler::new(scene, tiles, None, 0..s.spp, progress);
    tiler.stop = Some(interrupt.flag);
    let bands = tiler.bands(group);
    let threads = rayon::current_num_threads();
    // A thread's first allocation makes glibc reserve it an arena of
    // address space (64 MiB); let every thread take its own before
    // measuring what is left, so that under an address-space limit the
    // check sees what the render will have.
    rayon::broadcast(|_| std::hint::black_box(Vec::<u8>::with_capacity(1)));
    let need = || {
        let mut need = bands.need(threads);
        if tiler.allocates() {
            let pixels = u64::from(s.width) * u64::from(s.height);
            need.parts.push((
                "adaptive sampling's per-pixel decisions (error: mse)",
                pixels * budget::DECISION_BYTES,
            ));
        }
        need
    };
    need().check()?;
    let too_large = || RenderError::Memory(need());
    tiler.allocate_frame();
    let mut film = Film::try_band(s.width, s.height, bands.rows()).ok_or_else(too_large)?;
    let mut finished = Vec::new();
    finished
        .try_reserve_exact(bands.rows() as usize * s.width as usize)
        .map_err(|_| too_large())?;
    let (mut rays, mut merged) = (0, 0);
    for group in bands.groups() {
        let ((tiles, r), written) = rayon::join(
            || tiler.render(group.clone()),
            || rows.write_rows(&finished),
        );
        written?;
        finished.clear();
        if tiler.cut.load(Ordering::Relaxed) {
            break;
        }
        film.merge_all(&tiles);
        rays += r;
        merged = (group.end * TILE).min(s.height);
        film.advance(bands.finished(&group), &mut finished)
            .map_err(|_| too_large())?;
    }
    if merged < s.height {
        if merged == 0 || !interrupt.keep {
            return Err(RenderError::Interrupted);
        }
        film.advance(merged, &mut finished)
            .map_err(|_| too_large())?;
        rows.write_rows(&finished)?;
        finished.clear();
        finished.resize(s.width as usize * BLOCK_ROWS as usize, Rgb::ZERO);
        for y in (merged..s.height).step_by(BLOCK_ROWS as usize) {
            let black = (s.height - y).min(BLOCK_ROWS) as usize * s.width as usize;
            rows.write_rows(&finished[..black])?;
        }
    } else {
        rows.write_rows(&finished)?;
    }
    Ok(Written {
        time: start.elapsed(),
        samples: tiler.total / u64::from(s.height) * u64::from(merged),
        rays,
        invalid_samples: film.invalid_samples,
    })
}

/// Renders the tiles of a frame's tile rows for one range of sample
/// indices, reporting progress as batches finish.
struct Tiler<'a> {
    scene: &'a RenderScene,
    integrator: &'a dyn TileIntegrator,
    /// The frame's splat film, where the integrator splats.
    splats: Option<&'a SplatFilm>,
    /// The per-strategy films, where the render asks for them.
    strategies: Option<&'a StrategyFilms>,
    /// Where adaptive sampling's decision samples splat (dropped): made
    /// once per frame, for a splatting integrator under adaptive sampling.
    decision_sink: Option<SplatFilm>,
    reconstruction: Reconstruction,
    samples: Range<u32>,
    /// Camera paths of the whole pass.
    total: u64,
    /// Camera paths of the pass done so far (for progress).
    done: AtomicU64,
    /// Image samples traced (adaptive sampling stops pixels early).
    traced: AtomicU64,
    /// Where asked for, each pixel's image samples (row-major, the whole
    /// frame): `--spp-map`.
    counts: Option<std::sync::Mutex<Vec<u32>>>,
    /// Under adaptive sampling in passes, the image samples each pixel
    /// takes in the whole render (row-major), decided by the first pass;
    /// `None` where each tile decides its own (a whole render).
    decided: Option<&'a [u32]>,
    /// Under adaptive sampling toward the least MSE, the image samples each
    /// pixel takes (row-major, the whole frame), decided when the render
    /// starts ([`Tiler::allocate_frame`]) where `decided` is `None`.
    allocated: std::sync::OnceLock<Vec<u32>>,
    progress: &'a Progress<'a>,
    /// Raised to stop (a banded write's Ctrl-C): tiles not yet started
    /// are skipped, and `cut` says that one was.
    stop: Option<&'a AtomicBool>,
    /// Whether a tile was skipped.
    cut: AtomicBool,
}

impl<'a> Tiler<'a> {
    fn new(
        scene: &'a RenderScene,
        integrator: &'a dyn TileIntegrator,
        splats: Option<&'a SplatFilm>,
        samples: Range<u32>,
        progress: &'a Progress<'a>,
    ) -> Self {
        let s = &scene.settings;
        Self {
            scene,
            integrator,
            splats,
            strategies: None,
            decision_sink: splats
                .filter(|_| s.adaptive.is_some())
                .map(|_| SplatFilm::sink(scene.filter.as_ref())),
            reconstruction: Reconstruction::new(scene.filter.as_ref(), s.filter_sampling),
            total: s.width as u64 * s.height as u64 * samples.len() as u64,
            samples,
            done: AtomicU64::new(0),
            traced: AtomicU64::new(0),
            counts: None,
            decided: None,
            allocated: std::sync::OnceLock::new(),
            progress,
            stop: None,
            cut: AtomicBool::new(false),
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
        self.allocate_frame();
        let mut rays = 0;
        let group = group_tile_rows(self.scene.settings.width) * WHOLE_GROUP_FACTOR;
        for group in self.bands(group).groups() {
            let (tiles, r) = render(self, group);
            merge(&tiles);
            rays += r;
        }
        Pass {
            time: start.elapsed(),
            samples: self.traced.load(Ordering::Relaxed),
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
            .map_init(
                || self.integrator.worker(),
                |worker, &tile| self.tile(worker.as_mut(), tile, None),
            )
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
            .map_init(
                || self.integrator.worker(),
                |worker, &(x0, y0)| {
                    let (x1, y1) = ((x0 + TILE).min(s.width), (y0 + TILE).min(s.height));
                    let size = (s.width, s.height);
                    let reach = self.reconstruction.reach();
                    let mut aovs = AovTile::new(x0, y0, x1, y1, size, reach);
                    let (tile, rays) = self.tile(worker.as_mut(), (x0, y0), Some(&mut aovs));
                    (tile, aovs, rays)
                },
            )
            .collect();
        let rays = results.iter().map(|(_, _, r)| r).sum();
        let tiles = results.into_iter().map(|(t, a, _)| (t, a)).collect();
        (tiles, rays)
    }

    /// Renders the tile whose top left pixel is (`x0`, `y0`), adding its
    /// camera rays' first hits to `aovs` where given.
    fn tile(
        &self,
        worker: &mut dyn TileWorker,
        (x0, y0): (u32, u32),
        mut aovs: Option<&mut AovTile>,
    ) -> (TileFilm, u64) {
        let (w, h) = (self.scene.settings.width, self.scene.settings.height);
        let (x1, y1) = ((x0 + TILE).min(w), (y0 + TILE).min(h));
        let pixels = (x1 - x0) * (y1 - y0);
        let mut tile = TileFilm::new(x0, y0, x1, y1, (w, h), self.reconstruction.reach());
        if self.stop.is_some_and(|stop| stop.load(Ordering::Relaxed)) {
            self.cut.store(true, Ordering::Relaxed);
            return (tile, 0);
        }
        let rays_before = worker.rays();
        let ctx = self.context();
        let rect = TileRect {
            x0,
            y0,
            x1,
            y1,
            width: w,
        };
        if let Some(a) = &self.scene.settings.adaptive {
            // Decisions first (their samples never reach the image), then
            // this pass's share of each pixel's image samples, weighted by
            // 1 / its count.
            let frame = self
                .decided
                .or_else(|| self.allocated.get().map(Vec::as_slice));
            let counts = match frame {
                Some(frame) => tile_counts(frame, rect),
                None => self.decide(worker, a, rect),
            };
            let spp = self.scene.settings.spp;
            let share = |c| adaptive::pass_share(&self.samples, spp, c);
            adaptive::render_image(&counts, rect, share, |batch, count| {
                tile.set_scale(1.0 / count as f32);
                let out = TileOutput {
                    film: &mut tile,
                    aovs: aovs.as_deref_mut(),
                    samples: None,
                };
                worker.render(&ctx, batch, out);
            });
            tile.set_scale(1.0);
            let traced = counts.iter().map(|&c| share(c).len() as u64).sum();
            self.finish_tile(rect, &counts, traced);
            return (tile, worker.rays() - rays_before);
        }
        for batch in batches((x0, y0, x1, y1), self.samples.clone()) {
            let out = TileOutput {
                film: &mut tile,
                aovs: aovs.as_deref_mut(),
                samples: None,
            };
            worker.render(&ctx, batch, out);
            if self.progress.is_active() {
                let n = pixels as u64 * batch.samples as u64;
                let d = self.done.fetch_add(n, Ordering::Relaxed) + n;
                self.progress.report(d, self.total);
            }
        }
        let traced = u64::from(pixels) * self.samples.len() as u64;
        self.traced.fetch_add(traced, Ordering::Relaxed);
        if self.counts.is_some() {
            self.record_counts(rect, &vec![self.samples.len() as u32; pixels as usize]);
        }
        (tile, worker.rays() - rays_before)
    }

    /// The rectangle of the tile whose top left pixel is (`x0`, `y0`).
    fn rect(&self, (x0, y0): (u32, u32)) -> TileRect {
        let (w, h) = (self.scene.settings.width, self.scene.settings.height);
        TileRect {
            x0,
            y0,
            x1: (x0 + TILE).min(w),
            y1: (y0 + TILE).min(h),
            width: w,
        }
    }

    /// Under adaptive sampling, the image samples each pixel of the frame
    /// takes (row-major): every tile decided on the pool's threads, and
    /// under `error: mse` the frame's budget split by the pilot σs.
    fn frame_counts(&self, a: &adaptive::Adaptive) -> Vec<u32> {
        let s = &self.scene.settings;
        match a.error {
            ErrorGoal::Relative => self.per_pixel(|w, t| self.decide(w, a, t), 0),
            ErrorGoal::Mse => {
                let pilot = self.per_pixel(|w, t| self.pilot(w, t), Pilot::default());
                let footprint = budget::Footprint::new(&self.reconstruction);
                let sigma = footprint.effective_sigma(&pilot, s.width as usize);
                budget::allocate(&sigma, s.spp, budget::limits(a, s.spp))
            }
        }
    }

    /// Under adaptive sampling toward the least MSE, decides the whole
    /// frame's counts into `allocated` (once; before rendering, within the
    /// render's time), unless a pass before decided them.
    fn allocate_frame(&self) {
        if let Some(a) = self
            .scene
            .settings
            .adaptive
            .as_ref()
            .filter(|_| self.allocates())
        {
            self.allocated.get_or_init(|| self.frame_counts(a));
        }
    }

    /// Whether the render decides the whole frame's counts when it starts
    /// ([`Tiler::allocate_frame`]): adaptive sampling toward the least MSE,
    /// not decided by a pass before.
    fn allocates(&self) -> bool {
        self.decided.is_none()
            && self
                .scene
                .settings
                .adaptive
                .is_some_and(|a| a.error == ErrorGoal::Mse)
    }

    /// `value(worker, tile)` of every tile (row-major in the tile), on the
    /// pool's threads, placed in a row-major frame (`empty` where none).
    fn per_pixel<T: Copy + Send>(
        &self,
        value: impl Fn(&mut dyn TileWorker, TileRect) -> Vec<T> + Sync,
        empty: T,
    ) -> Vec<T> {
        let s = &self.scene.settings;
        let columns = s.width.div_ceil(TILE);
        let rects: Vec<TileRect> = (0..s.height.div_ceil(TILE))
            .flat_map(|ty| (0..columns).map(move |tx| self.rect((tx * TILE, ty * TILE))))
            .collect();
        let values: Vec<Vec<T>> = rects
            .par_iter()
            .map_init(|| self.integrator.worker(), |w, &t| value(w.as_mut(), t))
            .collect();
        let mut frame = vec![empty; s.width as usize * s.height as usize];
        for (t, tile) in rects.iter().zip(values) {
            let tw = (t.x1 - t.x0) as usize;
            for (row, y) in tile.chunks(tw.max(1)).zip(t.y0..) {
                let start = (y * t.width + t.x0) as usize;
                frame[start..start + row.len()].copy_from_slice(row);
            }
        }
        frame
    }

    /// Renders adaptive sampling's pilot round of tile `t` (decision
    /// samples into a scratch film): each pixel's mean and σ.
    fn pilot(&self, worker: &mut dyn TileWorker, t: TileRect) -> Vec<Pilot> {
        self.decision_round(worker, t, |render| {
            budget::pilot(self.scene.settings.spp, t, render)
        })
    }

    /// Makes adaptive sampling's decisions for tile `t` (decision samples
    /// into a scratch film): the image samples each of its pixels takes.
    fn decide(&self, worker: &mut dyn TileWorker, a: &adaptive::Adaptive, t: TileRect) -> Vec<u32> {
        let spp = self.scene.settings.spp;
        self.decision_round(worker, t, |render| adaptive::decide(a, spp, t, render))
    }

    /// Runs `decide` on tile `t`, handing it a renderer of decision
    /// samples: they go to a scratch film (and splats to the decision
    /// sink), never to the image, and each sample's value is reported by
    /// pixel.
    fn decision_round<T>(
        &self,
        worker: &mut dyn TileWorker,
        t: TileRect,
        decide: impl FnOnce(&mut dyn FnMut(Batch, &mut dyn FnMut(u32, Rgb))) -> T,
    ) -> T {
        let s = &self.scene.settings;
        let reach = self.reconstruction.reach();
        let mut scratch = TileFilm::new(t.x0, t.y0, t.x1, t.y1, (s.width, s.height), reach);
        // Decision samples never reach the image, nor its strategies'.
        let ctx = TileContext {
            splats: self.decision_sink.as_ref(),
            strategies: None,
            ..self.context()
        };
        decide(&mut |batch, add| {
            let out = TileOutput {
                film: &mut scratch,
                aovs: None,
                samples: Some(add),
            };
            worker.render(&ctx, batch, out);
        })
    }

    /// Ends an adaptive tile: counts its `traced` samples, records its
    /// pixels' `counts` where asked, and reports its share of the pass
    /// (pixels × spp, whatever the pixels took) as done.
    fn finish_tile(&self, rect: TileRect, counts: &[u32], traced: u64) {
        self.traced.fetch_add(traced, Ordering::Relaxed);
        self.record_counts(rect, counts);
        if self.progress.is_active() {
            let n = counts.len() as u64 * self.samples.len() as u64;
            let d = self.done.fetch_add(n, Ordering::Relaxed) + n;
            self.progress.report(d, self.total);
        }
    }

    /// Writes a tile's per-pixel sample `counts` into the frame's, where
    /// they are recorded.
    fn record_counts(&self, t: TileRect, counts: &[u32]) {
        let Some(frame) = &self.counts else {
            return;
        };
        let mut frame = frame.lock().unwrap_or_else(|e| e.into_inner());
        let tw = (t.x1 - t.x0) as usize;
        for (row, y) in counts.chunks(tw.max(1)).zip(t.y0..) {
            let start = (y * t.width + t.x0) as usize;
            frame[start..start + row.len()].copy_from_slice(row);
        }
    }

    /// What every batch of the frame shares.
    fn context(&self) -> TileContext<'_> {
        TileContext {
            scene: self.scene,
            reconstruction: &self.reconstruction,
            splats: self.splats,
            strategies: self.strategies,
        }
    }
}

/// The counts of tile `t`'s pixels (row-major in the tile) in `frame`'s
/// (row-major in the frame).
fn tile_counts(frame: &[u32], t: TileRect) -> Vec<u32> {
    (t.y0..t.y1)
        .flat_map(|y| {
            let start = (y * t.width + t.x0) as usize;
            frame[start..start + (t.x1 - t.x0) as usize].iter().copied()
        })
        .collect()
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
                render_rows(&r, &mut rows, group, &Progress::none(), Interrupt::NEVER)
                    .expect("fits")
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
                    render_rows(&r, rows, 1, &Progress::none(), Interrupt::NEVER)
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
    fn path_through_the_integrator_module_is_the_wavefront_driven_directly() {
        // The driver before integrators were modules: 16-pixel tiles,
        // batches of about 1024 paths through `Wavefront::render`, tiles
        // merged in order. The module's driver must give the same bits.
        use crate::integrators::Batch;
        use crate::integrators::path::Wavefront;
        let (w, h, spp) = (40, 37, 12);
        let r = cornell_scene(w, h, spp);
        let module = on_threads(2, || render(&r, &Progress::none()).image);
        let recon = Reconstruction::new(r.filter.as_ref(), r.settings.filter_sampling);
        let mut film = Film::new(w, h);
        let mut wave = Wavefront::default();
        for y0 in (0..h).step_by(16) {
            for x0 in (0..w).step_by(16) {
                let (x1, y1) = ((x0 + 16).min(w), (y0 + 16).min(h));
                let mut tile = TileFilm::new(x0, y0, x1, y1, (w, h), recon.reach());
                let chunk = (1024 / ((x1 - x0) * (y1 - y0))).max(1);
                let mut first = 0;
                while first < spp {
                    let samples = chunk.min(spp - first);
                    let batch = Batch {
                        x0,
                        y0,
                        x1,
                        y1,
                        first_sample: first,
                        samples,
                    };
                    wave.render(&r, batch, &recon, &mut tile);
                    first += samples;
                }
                film.merge(&tile);
            }
        }
        assert!(film.develop().pixels == module.pixels);
        assert!(module.mean() > 0.0);
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
