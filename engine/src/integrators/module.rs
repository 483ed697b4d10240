//! Integrators as a module kind: `integrator: {type: …}` names a
//! light-transport algorithm registered in the [`Registry`] like a camera
//! or a shader, so an outside crate can add one with the same
//! `registry.register::<dyn Integrator>(info, build)` call.
//!
//! # Design
//!
//! The trait needs the engine's render data ([`RenderScene`]), so it lives
//! here rather than in `radiant-core`; the core registry holds its table
//! as an *extension table* ([`Registry::extension`]), so the one
//! `Registry` value that `radiant::cli::run(registry)` takes carries
//! integrators too, and `radiant modules` lists them with the others.
//!
//! As in pbrt-v4, an integrator belongs to a *family*, and each family has
//! a driver in the backend that owns the threads, the film and the
//! progress; the integrator says which family it is ([`Integrator::family`]):
//!
//! * [`Family::Tiles`] — image-tile integrators (`path`, and `bdpt`): the
//!   CPU driver (`backend/cpu.rs`) cuts the frame into 16×16 tiles, gives
//!   each rayon thread one [`TileWorker`] (the integrator's per-thread
//!   scratch, made once per thread by [`TileIntegrator::worker`]) and calls
//!   [`TileWorker::render`] with [`Batch`]es: a pixel rectangle and a range
//!   of sample indices. The worker adds each camera sample to the tile's
//!   [`TileFilm`] (filtered, Σ w·L / Σ w) — sample index by sample index,
//!   ending every block of [`BLOCK`](crate::film::exact::BLOCK) indices, as
//!   `path` does, so the exact sums do not depend on how batches were cut —
//!   and, where the integrator [`splats`](TileIntegrator::splats), adds
//!   contributions that land anywhere in the image (light paths reaching
//!   the camera) to the frame's [`SplatFilm`]. The driver adds the splat
//!   film to the developed image scaled by 1 / (samples per pixel), as
//!   pbrt-v4's `AddSplat` does: a light path per camera sample. Where it
//!   is asked for, the worker reports every camera sample's value by its
//!   pixel ([`TileOutput::samples`]): adaptive sampling decides from them.
//!   Tiles are rendered in any order on any thread; a worker's output
//!   must depend only on the scene, the seed, the pixel and the sample
//!   index (draw every random number from `scene.sampler` by
//!   [`SampleId`](radiant_core::SampleId)), so images do not depend on the
//!   thread count.
//! * [`Family::Chains`] — Markov-chain integrators (`pssmlt`, `erpt`): the
//!   driver hands [`ChainIntegrator::render`] the scene, the budget (the
//!   scene's samples per pixel, read as mutations per pixel) and a
//!   whole-image [`SplatFilm`]; the integrator runs its chains on the
//!   rayon pool and returns the scale its splats are developed with
//!   ([`ChainPass::scale`]: its normalization over the mutations).
//!
//! The splat film is exact: every tap is converted to 128-bit fixed point
//! ([`Sums`](crate::film::exact::Sums)) and added under its row's lock,
//! so the image does not depend on the order threads splat in.
//!
//! What the families do not support yet: renders in passes (`--time`,
//! `--checkpoint`, `--resume`, `--partition`) need a plain tile integrator
//! (no splats) without adaptive sampling; and the GPU backend renders
//! `path` alone ([`Integrator::gpu`]). Both are refused with a message.
//!
//! `max_depth`, `rr_depth` and `light_selection` are read by the scene
//! loader for every integrator (they are [`RenderSettings`] fields, so
//! `--max-depth` overrides them and resume files record them); an
//! integrator's builder parses the rest of its keys itself (for `path`,
//! none).
//!
//! [`RenderSettings`]: crate::settings::RenderSettings

pub use super::path::Batch;
use super::path::Wavefront;
use super::splat::SplatFilm;
use super::strategies::StrategyFilms;
use crate::backend::Progress;
use crate::extract::RenderScene;
use crate::film::aov::AovTile;
use crate::film::{Reconstruction, TileFilm};
use radiant_core::registry::{ModuleType, Table};
use radiant_core::{BuildContext, ModuleInfo, ModuleKind, ParamError, Params, Registry, Rgb};
use serde::Deserialize;

/// A light-transport algorithm: a module of kind `integrator`.
pub trait Integrator: Send + Sync {
    /// Which driver renders it, with the integrator as that family's trait.
    fn family(&self) -> Family<'_>;

    /// Whether the GPU backend has a kernel for it (`path` alone). Others
    /// are refused by `--backend gpu`, and `auto` takes the CPU.
    fn gpu(&self) -> bool {
        false
    }

    /// Why it cannot render `scene` (a module without a side it needs, a
    /// feature it does not handle), asked once the frame is extracted: the
    /// message becomes an error at the scene's `integrator:`. `Ok` by
    /// default.
    fn check(&self, _scene: &RenderScene) -> Result<(), String> {
        Ok(())
    }
}

/// The driver families (see the module documentation).
pub enum Family<'a> {
    /// Rendered tile by tile, sample index by sample index.
    Tiles(&'a dyn TileIntegrator),
    /// Rendered as Markov chains over the whole image.
    Chains(&'a dyn ChainIntegrator),
}

/// An integrator of the image-tile family.
pub trait TileIntegrator: Send + Sync {
    /// Whether it adds contributions outside the pixel being sampled (light
    /// paths that reach the camera): then the driver holds a whole-image
    /// [`SplatFilm`] and passes it in [`TileContext::splats`].
    fn splats(&self) -> bool {
        false
    }

    /// A worker for one thread: the integrator's scratch, reused for every
    /// batch that thread renders (so nothing is allocated per ray).
    fn worker(&self) -> Box<dyn TileWorker + '_>;

    /// The names of its sampling strategies in `scene`, one image each
    /// where a render asks for per-strategy images
    /// ([`super::strategies`]; `bdpt`: `s{s}_t{t}`); empty (the default)
    /// where it splits its image by none.
    fn strategies(&self, _scene: &RenderScene) -> Vec<String> {
        Vec::new()
    }
}

/// What every batch of a frame shares.
pub struct TileContext<'a> {
    /// The frame.
    pub scene: &'a RenderScene,
    /// How camera samples reach pixels through the pixel filter.
    pub reconstruction: &'a Reconstruction,
    /// The whole-image splat target, where the integrator
    /// [`splats`](TileIntegrator::splats).
    pub splats: Option<&'a SplatFilm>,
    /// One film per [strategy](TileIntegrator::strategies), where the
    /// render asks for per-strategy images: every contribution, weighted,
    /// also goes to its strategy's film.
    pub strategies: Option<&'a StrategyFilms>,
}

/// Where one batch's results go.
pub struct TileOutput<'a> {
    /// The tile's film: every camera sample, filtered.
    pub film: &'a mut TileFilm,
    /// The tile's output variables (the camera rays' first hits), where
    /// the render records them.
    pub aovs: Option<&'a mut AovTile>,
    /// Where asked for (adaptive sampling), each camera sample's value by
    /// its pixel (`y × width + x`), splats not included.
    pub samples: Option<&'a mut dyn FnMut(u32, Rgb)>,
}

/// One thread's state of a tile integrator.
pub trait TileWorker: Send {
    /// Renders `batch`: adds its camera samples to `out.film` (and its
    /// first hits to `out.aovs`, its values to `out.samples`, where given)
    /// and its splats to `ctx.splats`.
    fn render(&mut self, ctx: &TileContext<'_>, batch: Batch, out: TileOutput<'_>);

    /// Rays traced by this worker so far (camera, continuation, shadow).
    fn rays(&self) -> u64;
}

/// An integrator of the Markov-chain family.
pub trait ChainIntegrator: Send + Sync {
    /// Renders the frame into `ctx.splats` on the current rayon pool.
    fn render(&self, ctx: &ChainContext<'_>) -> ChainPass;
}

/// What a Markov-chain integrator renders with.
pub struct ChainContext<'a> {
    /// The frame.
    pub scene: &'a RenderScene,
    /// The budget: mutations per pixel (the scene's `spp`), so that
    /// `--spp` trades time for noise as with the other integrators.
    pub spp: u32,
    /// The whole-image film the chains splat into.
    pub splats: &'a SplatFilm,
    /// Progress, in mutations of the whole budget (`spp × pixels`).
    pub progress: &'a Progress<'a>,
}

/// What a Markov-chain render did.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ChainPass {
    /// The factor the splat film's sums are developed with (the image is
    /// Σ splats × scale): the chains' normalization over their mutations.
    pub scale: f64,
    /// Paths (mutations and bootstrap samples) evaluated.
    pub samples: u64,
    /// Rays traced.
    pub rays: u64,
}

/// Paths per batch, about: a 16×16 tile's pixels × 4 samples.
pub const BATCH_PATHS: u32 = 1024;

/// The batches of about [`BATCH_PATHS`] paths that render the sample
/// indices `samples` of the pixels [x0, x1) × [y0, y1): whole sample
/// ranges of every pixel, in sample order.
pub fn batches(
    (x0, y0, x1, y1): (u32, u32, u32, u32),
    samples: std::ops::Range<u32>,
) -> impl Iterator<Item = Batch> {
    let chunk = (BATCH_PATHS / ((x1 - x0) * (y1 - y0)).max(1)).max(1);
    let end = samples.end;
    samples.step_by(chunk as usize).map(move |first| Batch {
        x0,
        y0,
        x1,
        y1,
        first_sample: first,
        samples: chunk.min(end - first),
    })
}

/// The extension table of `integrator` modules: before anything
/// registered, an empty one.
static NO_INTEGRATORS: Table<dyn Integrator> = Table::new();

impl ModuleType for dyn Integrator {
    const KIND: ModuleKind = ModuleKind::Integrator;

    fn table(registry: &Registry) -> &Table<Self> {
        registry.extension::<Self>().unwrap_or(&NO_INTEGRATORS)
    }

    fn table_mut(registry: &mut Registry) -> &mut Table<Self> {
        registry.extension_mut::<Self>()
    }
}

/// The integrator the scene file gives when it names none.
pub const DEFAULT: &str = "path";

/// The unidirectional path tracer ([`super::path`]) as a tile integrator.
#[derive(Debug, Clone, Copy, Default)]
pub struct PathIntegrator;

impl Integrator for PathIntegrator {
    fn family(&self) -> Family<'_> {
        Family::Tiles(self)
    }

    fn gpu(&self) -> bool {
        true
    }
}

impl TileIntegrator for PathIntegrator {
    fn worker(&self) -> Box<dyn TileWorker + '_> {
        Box::<Wavefront>::default()
    }
}

impl TileWorker for Wavefront {
    fn render(&mut self, ctx: &TileContext<'_>, batch: Batch, out: TileOutput<'_>) {
        match out.aovs {
            Some(a) => self.render_with_aovs(ctx.scene, batch, ctx.reconstruction, out.film, a),
            None => Wavefront::render(self, ctx.scene, batch, ctx.reconstruction, out.film),
        }
        if let Some(add) = out.samples {
            for (pixel, value) in self.samples() {
                add(pixel, value);
            }
        }
    }

    fn rays(&self) -> u64 {
        self.rays
    }
}

/// `path`'s own keys: none (`max_depth`, `rr_depth` and `light_selection`
/// are the loader's, see the module documentation).
#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct PathParams {}

/// Registers the built-in integrators.
pub fn register(registry: &mut Registry) {
    registry.register::<dyn Integrator>(
        ModuleInfo {
            type_name: "path",
            summary: "Unidirectional path tracer: next-event estimation at every vertex, \
                      power-heuristic MIS, Russian roulette (Mitsuba 3's `path`). Runs on CPU and GPU.",
            params: &[],
        },
        |params: &Params, _: &mut BuildContext<'_>| -> Result<Box<dyn Integrator>, ParamError> {
            let PathParams {} = params.parse()?;
            Ok(Box::new(PathIntegrator))
        },
    );
}
