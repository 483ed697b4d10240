//! The settings a sweep tries and how one setting is measured.
//!
//! A setting is the scene as written with one thing changed ([`Change`]).
//! Each is extracted (BVH included), then rendered progressively as two
//! seed halves (1, 2, 4, … samples per pixel each) until its share of the
//! budget would run out; after every pass the combined image is measured
//! against the reference. Adding an axis means a [`Axis`] variant, its
//! values in [`settings`], and how it changes the scene in [`Change`].

use super::AccuracyError;
use super::metrics::{BiasSplit, Metrics, bias_split, metrics};
use super::reference::Reference;
use super::twin::{TwinImages, TwinRender};
use crate::accel::BuildQuality;
use crate::extract::{Overrides, RenderScene, extract};
use crate::film::denoise::Denoiser;
use crate::integrators::Integrator;
use crate::integrators::adaptive::{Adaptive, ErrorGoal};
use crate::scene::{FilterSampling, LightSelection, Scene, default_module};
use crate::world::{EmitterSpec, LightSpec};
use radiant_core::{Filter, Registry, Sampler};
use std::fmt;
use std::sync::OnceLock;
use std::time::{Duration, Instant};

/// One thing a sweep varies.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum Axis {
    /// Samples per pixel: the scene as written, measured as samples accumulate.
    Spp,
    /// Longest path (2, 3, 5, 8, unlimited): bias against time.
    MaxDepth,
    /// Depth where Russian roulette starts (1, 2, 5, 10): variance against time.
    RrDepth,
    /// Every registered pixel filter, with its default parameters.
    Filter,
    /// How samples reach pixels through the filter (splat, importance).
    FilterSampling,
    /// Every registered sampler, with its default parameters.
    Sampler,
    /// Light selection of next-event estimation (power, uniform, spatial).
    LightSelection,
    /// BVH build quality (fast, medium, high): build time against trace time.
    Bvh,
    /// The backend: the scene on the GPU (where a hardware adapter is
    /// present) against the CPU baseline.
    Backend,
    /// Open Image Denoise on each half (off, on; where the library
    /// loads): what denoising buys at each time, and where it biases.
    Denoise,
    /// Every registered integrator, with its default parameters (and the
    /// scene's `max_depth`, `rr_depth`, `light_selection`).
    Integrator,
    /// Adaptive sampling (on with the default rule, or off where the scene
    /// turns it on): what stopping converged pixels saves.
    Adaptive,
}

impl Axis {
    /// Every axis, in report order.
    pub const ALL: [Axis; 12] = [
        Axis::Spp,
        Axis::MaxDepth,
        Axis::RrDepth,
        Axis::Filter,
        Axis::FilterSampling,
        Axis::Sampler,
        Axis::LightSelection,
        Axis::Bvh,
        Axis::Backend,
        Axis::Denoise,
        Axis::Integrator,
        Axis::Adaptive,
    ];

    /// The name used on the command line and in the CSV.
    pub fn name(self) -> &'static str {
        match self {
            Axis::Spp => "spp",
            Axis::MaxDepth => "max_depth",
            Axis::RrDepth => "rr_depth",
            Axis::Filter => "filter",
            Axis::FilterSampling => "filter_sampling",
            Axis::Sampler => "sampler",
            Axis::LightSelection => "light_selection",
            Axis::Bvh => "bvh",
            Axis::Backend => "backend",
            Axis::Denoise => "denoise",
            Axis::Integrator => "integrator",
            Axis::Adaptive => "adaptive",
        }
    }

    /// The axis called `name`.
    pub fn from_name(name: &str) -> Option<Axis> {
        Axis::ALL.into_iter().find(|a| a.name() == name)
    }
}

impl fmt::Display for Axis {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

/// How a setting differs from the scene as written.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum Change {
    /// No change: the scene as written.
    Baseline,
    /// `integrator.max_depth` (-1 = unlimited).
    MaxDepth(i32),
    /// `integrator.rr_depth`.
    RrDepth(u32),
    /// The pixel filter type (default parameters).
    Filter(String),
    /// `film.filter_sampling`.
    FilterSampling(FilterSampling),
    /// The sampler type (default parameters).
    Sampler(String),
    /// `integrator.light_selection`.
    LightSelection(LightSelection),
    /// BVH build quality.
    Bvh(BuildQuality),
    /// Rendered by the GPU backend.
    Gpu,
    /// Denoised (with `filter_sampling: importance`, as `--denoise`
    /// renders).
    Denoise,
    /// The integrator type (default parameters).
    Integrator(String),
    /// Adaptive sampling toward an error goal (default parameters), or
    /// off (`None`).
    Adaptive(Option<ErrorGoal>),
}

/// One setting of the sweep.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Setting {
    /// The axis it belongs to.
    pub axis: Axis,
    /// What it changes.
    pub change: Change,
}

impl Setting {
    /// The scene as written.
    pub fn baseline() -> Self {
        Self {
            axis: Axis::Spp,
            change: Change::Baseline,
        }
    }

    /// The value of the setting on its axis, e.g. `2` or `box`.
    pub fn value(&self) -> String {
        match &self.change {
            Change::Baseline => "scene".into(),
            Change::MaxDepth(d) => d.to_string(),
            Change::RrDepth(d) => d.to_string(),
            Change::Filter(t) | Change::Sampler(t) | Change::Integrator(t) => t.clone(),
            Change::FilterSampling(FilterSampling::Splat) => "splat".into(),
            Change::FilterSampling(FilterSampling::Importance) => "importance".into(),
            Change::LightSelection(LightSelection::Power) => "power".into(),
            Change::LightSelection(LightSelection::Uniform) => "uniform".into(),
            Change::LightSelection(LightSelection::Spatial) => "spatial".into(),
            Change::Bvh(q) => format!("{q:?}").to_lowercase(),
            Change::Gpu => "gpu".into(),
            Change::Denoise => "on".into(),
            Change::Adaptive(Some(ErrorGoal::Relative)) => "relative".into(),
            Change::Adaptive(Some(ErrorGoal::Mse)) => "mse".into(),
            Change::Adaptive(None) => "off".into(),
        }
    }

    /// A short label: `baseline` or `axis=value`.
    pub fn label(&self) -> String {
        match self.change {
            Change::Baseline => "baseline".into(),
            _ => format!("{}={}", self.axis, self.value()),
        }
    }

    /// Extracts `scene` with this setting applied over `base` overrides.
    pub fn extract(
        &self,
        scene: &mut Scene,
        registry: &Registry,
        base: &Overrides,
    ) -> Result<RenderScene, AccuracyError> {
        let mut overrides = *base;
        match &self.change {
            Change::MaxDepth(d) => overrides.max_depth = Some(*d),
            Change::RrDepth(d) => overrides.rr_depth = Some(*d),
            Change::FilterSampling(f) => overrides.filter_sampling = Some(*f),
            Change::LightSelection(l) => overrides.light_selection = Some(*l),
            Change::Bvh(q) => overrides.bvh = Some(*q),
            Change::Denoise => overrides.filter_sampling = Some(FilterSampling::Importance),
            _ => {}
        }
        let (filter, sampler) = (scene.filter.clone(), scene.sampler.clone());
        let (integrator, adaptive) = (scene.integrator.clone(), scene.settings.adaptive);
        match &self.change {
            Change::Filter(t) => scene.filter = default_module(t),
            Change::Sampler(t) => scene.sampler = default_module(t),
            Change::Integrator(t) => scene.integrator = default_module(t),
            Change::Adaptive(goal) => {
                scene.settings.adaptive = goal.map(|error| Adaptive {
                    error,
                    ..Adaptive::default()
                })
            }
            _ => {}
        }
        let render = extract(scene, registry, &overrides);
        scene.filter = filter;
        scene.sampler = sampler;
        scene.integrator = integrator;
        scene.settings.adaptive = adaptive;
        Ok(render?)
    }
}

/// The settings of `axes` for `scene`: always the baseline first, then per
/// axis the values that differ from the scene as written. The second list
/// says why an axis has no setting, where it has none.
pub fn settings(scene: &Scene, registry: &Registry, axes: &[Axis]) -> (Vec<Setting>, Vec<String>) {
    let mut list = vec![Setting::baseline()];
    let mut notes = Vec::new();
    let s = &scene.settings;
    // The GPU and the denoiser's planes need `path` rendered in passes.
    let plain =
        scene.integrator.type_name == crate::integrators::module::DEFAULT && s.adaptive.is_none();
    for &axis in axes {
        let changes: Vec<Change> = match axis {
            Axis::Spp => continue,
            Axis::MaxDepth => [2, 3, 5, 8, -1]
                .into_iter()
                .filter(|&d| d != s.max_depth)
                .map(Change::MaxDepth)
                .collect(),
            Axis::RrDepth => [1, 2, 5, 10]
                .into_iter()
                .filter(|&d| d != s.rr_depth)
                .map(Change::RrDepth)
                .collect(),
            Axis::Filter => registry
                .names::<dyn Filter>()
                .into_iter()
                .filter(|t| *t != scene.filter.type_name)
                .map(|t| Change::Filter(t.to_string()))
                .collect(),
            Axis::FilterSampling => [FilterSampling::Splat, FilterSampling::Importance]
                .into_iter()
                .filter(|f| *f != s.filter_sampling)
                .map(Change::FilterSampling)
                .collect(),
            Axis::Sampler => registry
                .names::<dyn Sampler>()
                .into_iter()
                .filter(|t| *t != scene.sampler.type_name)
                .map(|t| Change::Sampler(t.to_string()))
                .collect(),
            Axis::LightSelection => {
                let lights = scene.world.query::<&LightSpec>().iter().count()
                    + scene.world.query::<&EmitterSpec>().iter().count();
                if lights < 2 {
                    notes.push(format!(
                        "light_selection: the scene has {lights} light, so power, uniform and spatial selection are the same"
                    ));
                    continue;
                }
                [
                    LightSelection::Power,
                    LightSelection::Uniform,
                    LightSelection::Spatial,
                ]
                .into_iter()
                .filter(|l| *l != s.light_selection)
                .map(Change::LightSelection)
                .collect()
            }
            Axis::Bvh => [BuildQuality::Fast, BuildQuality::Medium]
                .into_iter()
                .map(Change::Bvh)
                .collect(),
            Axis::Backend | Axis::Denoise if !plain => {
                notes.push(format!(
                    "{axis}: not measured: the scene's integrator `{}`{} does not render in passes",
                    scene.integrator.type_name,
                    if s.adaptive.is_some() {
                        " with adaptive sampling"
                    } else {
                        ""
                    }
                ));
                continue;
            }
            Axis::Backend => match super::shared_gpu() {
                Ok(_) => vec![Change::Gpu],
                Err(why) => {
                    notes.push(format!("backend: the GPU is not measured: {why}"));
                    continue;
                }
            },
            Axis::Denoise => match shared_denoiser() {
                Ok(_) => vec![Change::Denoise],
                Err(why) => {
                    notes.push(format!("denoise: not measured: {why}"));
                    continue;
                }
            },
            Axis::Integrator => registry
                .names::<dyn Integrator>()
                .into_iter()
                .filter(|t| *t != scene.integrator.type_name)
                .map(|t| Change::Integrator(t.to_string()))
                .collect(),
            Axis::Adaptive => [None, Some(ErrorGoal::Relative), Some(ErrorGoal::Mse)]
                .into_iter()
                .filter(|goal| *goal != s.adaptive.map(|a| a.error))
                .map(Change::Adaptive)
                .collect(),
        };
        if changes.is_empty() {
            notes.push(format!("{axis}: only the scene's own value is registered"));
        }
        list.extend(changes.into_iter().map(|change| Setting { axis, change }));
    }
    (list, notes)
}

/// Open Image Denoise for the `denoise` axis, loaded once per process;
/// why it cannot be loaded otherwise.
fn shared_denoiser() -> Result<&'static Denoiser, String> {
    static DENOISER: OnceLock<Result<Denoiser, String>> = OnceLock::new();
    DENOISER
        .get_or_init(|| Denoiser::load().map_err(|e| e.to_string()))
        .as_ref()
        .map_err(Clone::clone)
}

/// One point of a setting's error curve.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Measurement {
    /// Samples per pixel of the combined image (both halves).
    pub spp: u32,
    /// Seconds from the start of extract (BVH build included) to the end of
    /// the last pass, metrics excluded.
    pub time: f64,
    /// Errors of the combined image.
    pub metrics: Metrics,
    /// Its bias/variance split.
    pub bias: BiasSplit,
}

/// A setting's measured error curve.
#[derive(Debug, Clone)]
pub struct Curve {
    /// The setting.
    pub setting: Setting,
    /// Extract time (module builds and BVH) in seconds.
    pub setup: f64,
    /// The measurements, by increasing spp.
    pub points: Vec<Measurement>,
    /// NaN or infinite samples (recorded as black).
    pub invalid_samples: u64,
}

/// Limits of one setting's run.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RunLimits {
    /// Wall time the setting may use, metrics included.
    pub share: Duration,
    /// Largest samples per pixel of the combined image.
    pub max_spp: u32,
    /// Seed of the first half (the second uses `seed + 1`).
    pub seed: u64,
}

/// Renders `setting` progressively and measures each pass against
/// `reference`, within `limits`. The first pass (one sample per pixel in
/// each half) always runs.
pub fn measure(
    scene: &mut Scene,
    registry: &Registry,
    base: &Overrides,
    setting: &Setting,
    reference: &Reference,
    limits: RunLimits,
) -> Result<Curve, AccuracyError> {
    let start = Instant::now();
    let max_half = (limits.max_spp / 2).max(1);
    let overrides = Overrides {
        seed: Some(limits.seed),
        spp: Some(max_half),
        ..*base
    };
    let extract_start = Instant::now();
    let render = setting.extract(scene, registry, &overrides)?;
    let setup = extract_start.elapsed().as_secs_f64();
    reference.check_size(render.settings.width, render.settings.height)?;
    let gpu = match setting.change {
        Change::Gpu => {
            #[cfg(feature = "gpu")]
            crate::backend::gpu::Plan::check(&render).map_err(crate::backend::RenderError::from)?;
            Some(super::shared_gpu().map_err(AccuracyError::NoGpu)?)
        }
        _ => None,
    };
    let denoiser = (setting.change == Change::Denoise).then(|| {
        shared_denoiser().expect("the denoise axis has settings only where the library loaded")
    });
    let mut twin = TwinRender::new(scene, registry, render, limits.seed + 1)?
        .on_gpu(gpu)
        .denoised_by(denoiser)?;
    twin.whole_renders_where_needed();
    let mut points = Vec::new();
    twin.run_doubling(max_half, start, limits.share, |twin| {
        let images = TwinImages::of(twin);
        let m = metrics(&images.combined, &reference.image).expect("the sizes were checked");
        points.push(Measurement {
            spp: 2 * twin.spp(),
            time: setup + twin.time().as_secs_f64(),
            metrics: m,
            bias: bias_split(images.halves(), &reference.image, reference.halves()),
        });
    });
    if let Some(e) = twin.take_error() {
        return Err(e);
    }
    Ok(Curve {
        setting: setting.clone(),
        setup,
        points,
        invalid_samples: twin.invalid_samples(),
    })
}

#[cfg(test)]
mod tests {
    // `unwrap` in this test code is the assertion: the inputs are the test's
    // own, so a failure is a bug, and the panic reports it with the error.
    use super::*;
    use radiant_core::{ModuleInfo, Params};

    fn scene(integrator: &str, lights: &str) -> Scene {
        let text = format!(
            "integrator: {integrator}\ncamera: {{type: perspective}}\n\
             film: {{filter: {{type: box}}}}\nlights:\n{lights}"
        );
        crate::scene::from_str(&text, "t.yaml".as_ref(), ".".as_ref()).unwrap()
    }

    struct Constant;
    impl Sampler for Constant {
        fn fill_1d(&self, _: &[radiant_core::SampleId], _: u32, out: &mut [f32]) {
            out.fill(0.5);
        }
        fn fill_2d(&self, _: &[radiant_core::SampleId], _: u32, out: &mut [glam::Vec2]) {
            out.fill(glam::Vec2::splat(0.5));
        }
    }

    #[test]
    fn axis_names_round_trip() {
        for a in Axis::ALL {
            assert_eq!(Axis::from_name(a.name()), Some(a));
        }
        assert_eq!(Axis::from_name("depth"), None);
    }

    const POINT: &str = "  - {type: point, position: [0, 0, 1], intensity: 1}\n";

    #[test]
    fn settings_leave_out_the_scenes_own_values_and_follow_the_registry() {
        let mut registry = crate::builtin_registry();
        let one = scene("{type: path, max_depth: 5, rr_depth: 2}", POINT);
        let (list, notes) = settings(&one, &registry, &Axis::ALL);
        // The integrator axis holds every registered integrator but the
        // scene's, and the adaptive axis turns adaptive sampling on with
        // each error goal.
        let integrators: Vec<String> = list
            .iter()
            .filter(|s| s.axis == Axis::Integrator)
            .map(Setting::value)
            .collect();
        let others: Vec<&str> = registry
            .names::<dyn Integrator>()
            .into_iter()
            .filter(|t| *t != "path")
            .collect();
        assert_eq!(integrators, others);
        let adaptive: Vec<String> = list
            .iter()
            .filter(|s| s.axis == Axis::Adaptive)
            .map(Setting::label)
            .collect();
        assert_eq!(adaptive, ["adaptive=relative", "adaptive=mse"]);
        let mut labels: Vec<String> = list
            .iter()
            .filter(|s| !matches!(s.axis, Axis::Integrator | Axis::Adaptive))
            .map(Setting::label)
            .collect();
        // The denoise axis is there where the library loads, else a note.
        let denoise = labels.last().is_some_and(|l| l == "denoise=on");
        assert_eq!(denoise, shared_denoiser().is_ok());
        assert_eq!(!denoise, notes.iter().any(|n| n.starts_with("denoise")));
        labels.truncate(labels.len() - usize::from(denoise));
        assert_eq!(
            labels,
            [
                "baseline",
                "max_depth=2",
                "max_depth=3",
                "max_depth=8",
                "max_depth=-1",
                "rr_depth=1",
                "rr_depth=5",
                "rr_depth=10",
                "filter=blackman_harris",
                "filter=gaussian",
                "filter=lanczos",
                "filter=mitchell",
                "filter=tent",
                "filter_sampling=importance",
                "sampler=halton",
                "sampler=independent",
                "sampler=stratified",
                "bvh=fast",
                "bvh=medium"
            ]
        );
        assert!(notes.iter().any(|n| n.starts_with("light_selection")));

        // A sampler registered later joins the sweep; two lights allow
        // light selection.
        registry.register::<dyn Sampler>(
            ModuleInfo {
                type_name: "constant",
                summary: "",
                params: &[],
            },
            |_: &Params, _| Ok(Box::new(Constant) as Box<dyn Sampler>),
        );
        let two = scene("{type: path}", &POINT.repeat(2));
        let (list, notes) = settings(&two, &registry, &[Axis::Sampler, Axis::LightSelection]);
        let labels: Vec<String> = list.iter().map(Setting::label).collect();
        assert_eq!(
            labels,
            [
                "baseline",
                "sampler=constant",
                "sampler=halton",
                "sampler=independent",
                "sampler=stratified",
                "light_selection=power",
                "light_selection=uniform"
            ]
        );
        assert!(notes.is_empty());
        // Each setting extracts with its change applied.
        let mut two = two;
        for s in &list {
            let r = s
                .extract(&mut two, &registry, &Overrides::default())
                .unwrap();
            let expected = match s.change {
                Change::LightSelection(l) => l,
                _ => LightSelection::Spatial,
            };
            assert_eq!(r.settings.light_selection, expected);
        }
        assert_eq!(two.sampler.type_name, "sobol", "the scene is restored");
    }
}
