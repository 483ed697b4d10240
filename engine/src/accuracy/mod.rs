//! The accuracy/time report (`radiant accuracy`): for one scene, how much
//! error each setting leaves after a given time, and how much time a given
//! error costs — measured, not guessed.
//!
//! Data flow: [`reference`](mod@reference) reads or renders the reference image →
//! [`sweep`] lists the settings (the scene as written with one thing
//! changed) and renders each progressively in two seed halves
//! ([`twin`]), measuring after every pass with [`metrics`] → [`report`]
//! fits slopes, finds the Pareto front and the best setting per time
//! budget, and writes the CSV and Markdown summary → [`plot`] draws the
//! error-against-time PNG.
//!
//! ```no_run
//! use radiant::accuracy::{Config, run, write};
//! let registry = radiant::builtin_registry();
//! let mut scene = radiant::scene::load("scenes/cornell-box.yaml")?;
//! let config = Config::new(std::time::Duration::from_secs(30));
//! let report = run(&mut scene, &registry, &config, None, &|line| eprintln!("{line}"))?;
//! write(&report, "accuracy-out".as_ref())?;
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```

pub mod metrics;
pub mod plot;
pub mod reference;
pub mod report;
pub mod sweep;
pub mod twin;

pub use reference::Reference;
pub use sweep::{Axis, Curve, Setting};

use crate::backend::Backend;
use crate::extract::Overrides;
use crate::scene::{Scene, SceneError};
use radiant_core::Registry;
use std::path::{Path, PathBuf};
use std::sync::{Mutex, OnceLock};
use std::time::{Duration, Instant};

/// Errors of the accuracy report.
#[derive(Debug, thiserror::Error)]
pub enum AccuracyError {
    /// The scene (or a setting applied to it) is invalid.
    #[error(transparent)]
    Scene(#[from] SceneError),
    /// The reference image could not be read, or an image not written.
    #[error(transparent)]
    Image(#[from] crate::film::output::ImageError),
    /// The reference has another size than the film.
    #[error(
        "the reference is {}x{} pixels but the film is {}x{}; render the reference at the scene's size or pass --width/--height to match it",
        reference.0, reference.1, film.0, film.1
    )]
    ReferenceSize {
        /// Reference width and height.
        reference: (u32, u32),
        /// Film width and height.
        film: (u32, u32),
    },
    /// A film does not fit in memory (the report keeps whole films: it
    /// compares them with the reference).
    #[error("the accuracy report needs whole films in memory, and {0}")]
    WholeFilm(Box<crate::film::memory::FrameTooLarge>),
    /// The GPU failed, or cannot render the scene.
    #[error(transparent)]
    Gpu(#[from] crate::backend::RenderError),
    /// The `backend` axis was asked for without a GPU to measure.
    #[error("the backend axis needs a hardware GPU: {0}")]
    NoGpu(String),
    /// An output file could not be written.
    #[error("cannot write `{path}`: {message}")]
    Write {
        /// The file.
        path: PathBuf,
        /// What went wrong.
        message: String,
    },
}

/// What to sweep and within which limits.
#[derive(Debug, Clone, PartialEq)]
pub struct Config {
    /// Wall-time bound of the whole run: the reference render (when none
    /// is given) and then the sweep, whose settings share what is left.
    pub budget: Duration,
    /// The part of the budget for rendering the reference when none is
    /// given (the sweep gets at least the rest; a reference time beyond
    /// the budget leaves the sweep nothing but each setting's first pass).
    pub reference_time: Duration,
    /// Largest samples per pixel of a setting (both halves together); the
    /// reference may use 16 times as many.
    pub max_spp: u32,
    /// The axes to sweep (the scene as written is always measured).
    pub axes: Vec<Axis>,
    /// Overrides applied to every setting and the reference (resolution).
    pub overrides: Overrides,
    /// Seed of the first setting's halves.
    pub seed: u64,
}

impl Config {
    /// Every axis within `budget`, a quarter of it for the reference.
    pub fn new(budget: Duration) -> Self {
        Self {
            budget,
            reference_time: budget / REFERENCE_SHARE,
            max_spp: 1 << 16,
            axes: Axis::ALL.to_vec(),
            overrides: Overrides::default(),
            seed: 0,
        }
    }
}

/// The reference's share of the budget by default: 1/4.
pub const REFERENCE_SHARE: u32 = 4;

/// The measured sweep.
#[derive(Debug, Clone)]
pub struct Report {
    /// The scene file.
    pub scene: PathBuf,
    /// The reference.
    pub reference: Reference,
    /// One curve per setting, the scene as written first.
    pub curves: Vec<Curve>,
    /// Why axes were skipped.
    pub notes: Vec<String>,
    /// The budget.
    pub budget: Duration,
    /// Wall time of the sweep (reference excluded).
    pub sweep_time: Duration,
    /// Wall time of the whole run (reference render included).
    pub total_time: Duration,
}

/// Measures every setting of `config.axes` on `scene` against `reference`
/// (or a reference rendered first when `None`), all within
/// `config.budget`; `log` receives a line per finished step.
pub fn run(
    scene: &mut Scene,
    registry: &Registry,
    config: &Config,
    reference: Option<Reference>,
    log: &dyn Fn(&str),
) -> Result<Report, AccuracyError> {
    let started = Instant::now();
    let reference = match reference {
        Some(r) => r,
        None => {
            let r = Reference::render(
                scene,
                registry,
                &config.overrides,
                config.reference_time,
                config.max_spp.saturating_mul(16),
            )?;
            log(&format!(
                "reference: {} spp in {:.1} s, relative standard error {:.3} %",
                r.spp.unwrap_or(0),
                r.time.unwrap_or_default().as_secs_f64(),
                100.0 * r.relative_error().unwrap_or(0.0)
            ));
            r
        }
    };
    let (settings, mut notes) = sweep::settings(scene, registry, &config.axes);
    let start = Instant::now();
    let mut curves = Vec::with_capacity(settings.len());
    for (i, setting) in settings.iter().enumerate() {
        // Spread what is left of the budget over the settings still to run,
        // so that one that ends early leaves its time to the others.
        let left = config.budget.saturating_sub(started.elapsed());
        let share = left / (settings.len() - i) as u32;
        let limits = sweep::RunLimits {
            share,
            max_spp: config.max_spp,
            seed: config.seed.wrapping_add(2 * i as u64),
        };
        let curve = match sweep::measure(
            scene,
            registry,
            &config.overrides,
            setting,
            &reference,
            limits,
        ) {
            Ok(curve) => curve,
            // Another integrator may refuse a scene that the scene's own
            // renders (bdpt and participating media): a note, not the end
            // of the report.
            Err(AccuracyError::Scene(e)) if setting.axis == Axis::Integrator => {
                let note = format!("{}: not measured: {e}", setting.label());
                log(&note);
                notes.push(note);
                continue;
            }
            Err(e) => return Err(e),
        };
        if let Some(m) = curve.last() {
            log(&format!(
                "{}: {} spp in {:.2} s, RMSE {:.4e}{}",
                setting.label(),
                m.spp,
                m.time,
                m.metrics.rmse,
                if curve.is_biased() { " (biased)" } else { "" }
            ));
        }
        curves.push(curve);
    }
    Ok(Report {
        scene: scene.file.clone(),
        reference,
        curves,
        notes,
        budget: config.budget,
        sweep_time: start.elapsed(),
        total_time: started.elapsed(),
    })
}

/// The hardware GPU the `backend` axis measures on, opened once per
/// process; why there is none otherwise (none found, only a software one,
/// whose speed says nothing, or a build without the `gpu` feature).
pub(crate) fn shared_gpu() -> Result<&'static Mutex<Box<dyn Backend>>, String> {
    static GPU: OnceLock<Result<Mutex<Box<dyn Backend>>, String>> = OnceLock::new();
    GPU.get_or_init(open_gpu).as_ref().map_err(Clone::clone)
}

/// Opens the GPU of [`shared_gpu`].
#[cfg(feature = "gpu")]
fn open_gpu() -> Result<Mutex<Box<dyn Backend>>, String> {
    use crate::backend::gpu::GpuBackend;
    match GpuBackend::new(&Default::default()) {
        Ok(g) if !g.is_software() => Ok(Mutex::new(Box::new(g))),
        Ok(g) => Err(format!(
            "the only adapter, {}, is a software one",
            g.adapter()
        )),
        Err(e) => Err(e.to_string()),
    }
}

/// [`shared_gpu`] without the GPU backend.
#[cfg(not(feature = "gpu"))]
fn open_gpu() -> Result<Mutex<Box<dyn Backend>>, String> {
    Err(crate::backend::RenderError::GpuNotBuilt.to_string())
}

/// The files [`write()`] makes in its folder.
pub const CSV_FILE: &str = "accuracy.csv";
/// See [`CSV_FILE`].
pub const PLOT_FILE: &str = "accuracy.png";
/// See [`CSV_FILE`].
pub const SUMMARY_FILE: &str = "accuracy.md";
/// See [`CSV_FILE`]; written only when the reference was rendered here.
pub const REFERENCE_FILE: &str = "reference.exr";

fn write_atomic(
    path: &Path,
    write: impl FnOnce(&Path) -> Result<(), String>,
) -> Result<(), AccuracyError> {
    let err = |message: String| AccuracyError::Write {
        path: path.to_path_buf(),
        message,
    };
    let suffix = path
        .extension()
        .map_or_else(String::new, |e| format!(".{}", e.to_string_lossy()));
    let tmp =
        crate::film::output::temp_file_beside(path, &suffix).map_err(|e| err(e.to_string()))?;
    write(tmp.path()).map_err(err)?;
    tmp.persist(path).map_err(|e| err(e.error.to_string()))?;
    Ok(())
}

/// Writes the CSV, the plot, the summary and (if rendered here) the
/// reference into the folder `out`, creating it if needed.
pub fn write(report: &Report, out: &Path) -> Result<(), AccuracyError> {
    std::fs::create_dir_all(out).map_err(|e| AccuracyError::Write {
        path: out.to_path_buf(),
        message: e.to_string(),
    })?;
    let text = |s: String| move |p: &Path| std::fs::write(p, s).map_err(|e| e.to_string());
    write_atomic(&out.join(CSV_FILE), text(report::csv(report)))?;
    write_atomic(&out.join(SUMMARY_FILE), text(report::summary(report)))?;
    write_atomic(&out.join(PLOT_FILE), |p| plot::draw(report, p))?;
    if report.reference.halves.is_some() {
        crate::film::output::write(out.join(REFERENCE_FILE), &report.reference.image)?;
    }
    Ok(())
}
