//! Backends render an extracted frame. [`cpu`] runs the wavefront path
//! tracer on every core through rayon; `gpu` (with the default-on `gpu`
//! cargo feature) runs it as a wgpu compute kernel assembled from the
//! frame's modules. [`Backend`] is the seam the command line renders
//! through, and [`choose`] picks one as `--backend cpu|gpu|auto` asks
//! ([`gpu_options`] holds what `--gpu-…` flags ask of the GPU, with or
//! without the feature); [`progressive`] renders through it in passes
//! (`--time`, `--checkpoint`, `--resume`).

pub mod cpu;
#[cfg(feature = "gpu")]
pub mod gpu;
pub mod gpu_options;
pub mod progressive;

pub use gpu_options::{BvhLayout, GpuKernel, GpuOptions};

use crate::extract::RenderScene;
use crate::film::memory::FrameTooLarge;
use crate::film::output::ImageError;
use crate::film::{Film, Image};
use std::ops::Range;
use std::path::Path;
use std::sync::atomic::AtomicBool;
use std::time::Duration;
use thiserror::Error;

/// Receives progress as tiles finish.
pub struct Progress<'a> {
    callback: Option<&'a (dyn Fn(u64, u64) + Sync)>,
}

impl<'a> Progress<'a> {
    /// No progress reporting.
    pub fn none() -> Self {
        Self { callback: None }
    }

    /// Calls `f(done, total)` (in samples) as work finishes.
    pub fn new(f: &'a (dyn Fn(u64, u64) + Sync)) -> Self {
        Self { callback: Some(f) }
    }

    /// Whether anyone listens.
    pub fn is_active(&self) -> bool {
        self.callback.is_some()
    }

    /// Reports `done` of `total` samples.
    pub fn report(&self, done: u64, total: u64) {
        if let Some(f) = self.callback {
            f(done, total);
        }
    }
}

/// Asks a render to stop early (Ctrl-C), and what to keep of it then.
#[derive(Debug, Clone, Copy)]
pub struct Interrupt<'a> {
    /// Raised to stop.
    pub flag: &'a AtomicBool,
    /// Whether an interrupted frame's file is written with what it holds
    /// (else none is: a frame of a sequence appears only when finished).
    pub keep: bool,
}

impl Interrupt<'static> {
    /// Never raised.
    pub const NEVER: Self = Self {
        flag: &NEVER_RAISED,
        keep: false,
    };
}

/// The flag of [`Interrupt::NEVER`].
static NEVER_RAISED: AtomicBool = AtomicBool::new(false);

/// A finished render.
pub struct Rendered {
    /// The developed image.
    pub image: Image,
    /// Wall time of the rendering (extract and BVH excluded).
    pub time: Duration,
    /// Camera paths traced (pixels × spp).
    pub samples: u64,
    /// Rays traced (camera, continuation and shadow rays).
    pub rays: u64,
    /// Samples that were NaN or infinite and recorded as zero.
    pub invalid_samples: u64,
}

/// A finished render written to a file: [`Rendered`] less the image.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Written {
    /// Wall time of the rendering (extract and BVH excluded).
    pub time: Duration,
    /// Camera paths traced (pixels × spp).
    pub samples: u64,
    /// Rays traced (camera, continuation and shadow rays).
    pub rays: u64,
    /// Samples that were NaN or infinite and recorded as zero.
    pub invalid_samples: u64,
}

impl From<&Rendered> for Written {
    fn from(r: &Rendered) -> Self {
        Self {
            time: r.time,
            samples: r.samples,
            rays: r.rays,
            invalid_samples: r.invalid_samples,
        }
    }
}

/// Why a backend could not render a frame.
#[derive(Debug, Error)]
pub enum RenderError {
    /// The film does not fit in memory.
    #[error(transparent)]
    Memory(#[from] FrameTooLarge),
    /// A backend that needs the whole film in memory cannot have it.
    #[error(
        "{backend} needs the whole film in memory, and {error}; the CPU backend \
         (`--backend cpu`) holds only a band of rows"
    )]
    WholeFilm {
        /// The backend, as [`Backend::describe`] says.
        backend: String,
        /// What the whole film needed.
        error: FrameTooLarge,
    },
    /// The image file could not be written.
    #[error(transparent)]
    Output(#[from] ImageError),
    /// The GPU failed or cannot render the scene.
    #[cfg(feature = "gpu")]
    #[error(transparent)]
    Gpu(#[from] gpu::GpuError),
    /// The GPU was asked for, and this build has no GPU backend.
    #[error(
        "this build of radiant has no GPU backend: it was built without the `gpu` cargo \
         feature (on by default). Build it with the feature (`cargo build --release --features \
         gpu`; a crate that depends on radiant with `default-features = false` adds \
         `features = [\"gpu\"]`), or render with `--backend cpu` (or `auto`)"
    )]
    GpuNotBuilt,
    /// The render was asked in passes, and the integrator cannot render
    /// that way.
    #[error("{0}")]
    NoPasses(String),
    /// The render was interrupted with nothing to keep: before its first
    /// band of rows was finished, or as a frame of a sequence.
    #[error("interrupted before the frame was finished: nothing written")]
    Interrupted,
}

/// Something that renders frames: the CPU path tracer or the GPU one.
pub trait Backend: Send {
    /// What renders (for messages): `cpu (16 threads)`, an adapter's name.
    fn describe(&self) -> String;

    /// Renders all samples of `scene` and develops the image.
    fn render(
        &mut self,
        scene: &RenderScene,
        progress: &Progress<'_>,
    ) -> Result<Rendered, RenderError>;

    /// Renders the sample indices `samples` of every pixel and adds them
    /// to `film` (one sample partition of a frame, or a progressive pass).
    fn render_samples(
        &mut self,
        scene: &RenderScene,
        film: &mut Film,
        samples: Range<u32>,
        progress: &Progress<'_>,
    ) -> Result<cpu::Pass, RenderError>;

    /// Renders all samples of `scene` and writes the image to `path`
    /// (atomically: no file on failure). This default renders the whole
    /// film, after checking that it fits in memory, and then writes it;
    /// the CPU backend writes rows as they finish from a band of film.
    fn write(
        &mut self,
        scene: &RenderScene,
        path: &Path,
        progress: &Progress<'_>,
    ) -> Result<Written, RenderError> {
        let s = &scene.settings;
        FrameTooLarge::new(s.width, s.height)
            .check()
            .map_err(|error| RenderError::WholeFilm {
                backend: self.describe(),
                error,
            })?;
        let rendered = self.render(scene, progress)?;
        crate::film::output::write_encoded(path, &rendered.image, &s.output)?;
        Ok(Written::from(&rendered))
    }

    /// [`Backend::write`], stopping early where `interrupt` is raised, if
    /// the backend can for `scene` ([`Backend::stops_early`]); this
    /// default renders everything.
    fn write_until(
        &mut self,
        scene: &RenderScene,
        path: &Path,
        progress: &Progress<'_>,
        interrupt: Interrupt<'_>,
    ) -> Result<Written, RenderError> {
        let _ = interrupt;
        self.write(scene, path, progress)
    }

    /// Whether [`Backend::write_until`] stops early for `scene` (else
    /// Ctrl-C is better left to quit at once). This default says no.
    fn stops_early(&self, scene: &RenderScene) -> bool {
        let _ = scene;
        false
    }

    /// What the last render counted beyond [`Rendered`], as a line for
    /// the user (the GPU's rays by kind and traversal work), if anything.
    fn counts(&self) -> Option<String> {
        None
    }
}

/// The CPU backend on the current rayon pool.
#[derive(Debug, Clone, Copy, Default)]
pub struct CpuBackend;

impl Backend for CpuBackend {
    fn describe(&self) -> String {
        format!("cpu ({} threads)", rayon::current_num_threads())
    }

    fn render(
        &mut self,
        scene: &RenderScene,
        progress: &Progress<'_>,
    ) -> Result<Rendered, RenderError> {
        Ok(cpu::try_render(scene, progress)?)
    }

    fn render_samples(
        &mut self,
        scene: &RenderScene,
        film: &mut Film,
        samples: Range<u32>,
        progress: &Progress<'_>,
    ) -> Result<cpu::Pass, RenderError> {
        cpu::passes(scene)?;
        Ok(cpu::render_samples(scene, film, samples, progress))
    }

    fn write(
        &mut self,
        scene: &RenderScene,
        path: &Path,
        progress: &Progress<'_>,
    ) -> Result<Written, RenderError> {
        cpu::write(scene, path, progress)
    }

    fn write_until(
        &mut self,
        scene: &RenderScene,
        path: &Path,
        progress: &Progress<'_>,
        interrupt: Interrupt<'_>,
    ) -> Result<Written, RenderError> {
        cpu::write_until(scene, path, progress, interrupt)
    }

    fn stops_early(&self, scene: &RenderScene) -> bool {
        cpu::passes(scene).is_ok()
    }
}

#[cfg(feature = "gpu")]
impl Backend for gpu::GpuBackend {
    fn describe(&self) -> String {
        format!("gpu: {}, {}", self.adapter(), self.kernel())
    }

    fn render(
        &mut self,
        scene: &RenderScene,
        progress: &Progress<'_>,
    ) -> Result<Rendered, RenderError> {
        Ok(gpu::GpuBackend::render(self, scene, progress)?)
    }

    fn render_samples(
        &mut self,
        scene: &RenderScene,
        film: &mut Film,
        samples: Range<u32>,
        progress: &Progress<'_>,
    ) -> Result<cpu::Pass, RenderError> {
        Ok(gpu::GpuBackend::render_samples(
            self, scene, film, samples, progress,
        )?)
    }

    fn counts(&self) -> Option<String> {
        let s = self.last_stats();
        let rays = (s.camera_rays + s.bounce_rays + s.shadow_rays).max(1) as f64;
        let mut line = format!(
            "rays: {} camera, {} bounce, {} shadow",
            s.camera_rays, s.bounce_rays, s.shadow_rays
        );
        if s.nodes > 0 {
            line += &format!(
                "; per ray {:.1} nodes visited, {:.1} primitives tested",
                s.nodes as f64 / rays,
                s.prims as f64 / rays
            );
        }
        let stages = s.stages.millis();
        if !stages.is_empty() {
            let times: Vec<String> = stages
                .iter()
                .map(|(name, ms)| format!("{name} {ms:.1} ms"))
                .collect();
            line += &format!("\nstages ({}): {}", self.kernel(), times.join(", "));
        }
        Some(line)
    }
}

/// Which backend renders (`--backend`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
#[cfg_attr(feature = "cli", derive(clap::ValueEnum))]
pub enum BackendKind {
    /// The CPU path tracer.
    Cpu,
    /// The GPU path tracer; fails where no adapter is found or the scene
    /// uses a module without GPU code.
    Gpu,
    /// The GPU where a hardware adapter is found and the scene has GPU
    /// code for all its modules, else the CPU (saying why on stderr).
    #[default]
    Auto,
}

/// The backend `kind` asks for (a GPU opened with `options`), for frames
/// like `scene`; `note` receives what `auto` chose and why. Without the
/// `gpu` feature, `gpu` is [`RenderError::GpuNotBuilt`] and `auto` the CPU.
pub fn choose(
    kind: BackendKind,
    options: &GpuOptions,
    scene: &RenderScene,
    note: &mut dyn FnMut(String),
) -> Result<Box<dyn Backend>, RenderError> {
    match kind {
        BackendKind::Cpu => Ok(Box::new(CpuBackend)),
        #[cfg(feature = "gpu")]
        BackendKind::Gpu => {
            gpu::Plan::check(scene)?;
            Ok(Box::new(gpu::GpuBackend::new(options)?))
        }
        #[cfg(not(feature = "gpu"))]
        BackendKind::Gpu => {
            let _ = (options, scene);
            Err(RenderError::GpuNotBuilt)
        }
        #[cfg(feature = "gpu")]
        BackendKind::Auto => Ok(auto(options, scene, note)),
        #[cfg(not(feature = "gpu"))]
        BackendKind::Auto => {
            note(
                "backend: cpu (this build has no GPU backend: the `gpu` cargo feature is off)"
                    .into(),
            );
            Ok(Box::new(CpuBackend))
        }
    }
}

/// `--backend auto`: the GPU where a hardware adapter is found and the
/// scene has GPU code for all its modules, else the CPU, saying which
/// through `note`.
#[cfg(feature = "gpu")]
fn auto(
    options: &GpuOptions,
    scene: &RenderScene,
    note: &mut dyn FnMut(String),
) -> Box<dyn Backend> {
    if let Err(e) = gpu::Plan::check(scene) {
        note(format!("backend: cpu ({e})"));
        return Box::new(CpuBackend);
    }
    match gpu::GpuBackend::new(options) {
        Ok(g) if !g.is_software() => {
            note(format!("backend: gpu, adapter {}", g.adapter()));
            Box::new(g)
        }
        Ok(g) => {
            note(format!(
                "backend: cpu (the only GPU adapter, {}, is a software one; `--backend gpu` uses it anyway)",
                g.adapter()
            ));
            Box::new(CpuBackend)
        }
        Err(e) => {
            note(format!("backend: cpu ({e})"));
            Box::new(CpuBackend)
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_missing_gpu_feature_says_how_to_enable_it() {
        let message = RenderError::GpuNotBuilt.to_string();
        for needed in [
            "`gpu` cargo feature",
            "--features gpu",
            "features = [\"gpu\"]",
            "--backend cpu",
        ] {
            assert!(message.contains(needed), "{needed} in {message}");
        }
        assert!(!message.contains("  "), "a run of spaces in {message}");
    }

    /// Without the feature, `gpu` is refused with that message and `auto`
    /// renders on the CPU, saying why.
    #[cfg(not(feature = "gpu"))]
    #[test]
    fn without_the_gpu_feature_gpu_is_refused_and_auto_is_the_cpu() {
        let scene = cpu::tests::cornell_scene(8, 8, 1);
        let options = GpuOptions::default();
        let refused = choose(BackendKind::Gpu, &options, &scene, &mut |_| {});
        assert!(matches!(refused, Err(RenderError::GpuNotBuilt)));
        let mut notes = Vec::new();
        let auto = choose(BackendKind::Auto, &options, &scene, &mut |n| notes.push(n));
        assert!(auto.is_ok_and(|b| b.describe().starts_with("cpu")));
        assert!(
            notes.iter().any(|n| n.contains("`gpu` cargo feature")),
            "{notes:?}"
        );
    }
}
