//! Two independent progressive renders of one setting, with two sampler
//! seeds, over one extracted scene: the halves whose difference measures
//! the noise (see [`metrics`](super::metrics)). On the `denoise` axis each
//! half also collects its first-hit planes and is denoised when developed.
//! An integrator that does not render in passes
//! ([`cpu::passes`](crate::backend::cpu::passes)), and adaptive sampling
//! (whose passes render shares of each pixel's count in a render of the
//! scene's spp, where a point of the curve is an adaptive render of that
//! point's spp), are measured by whole renders instead: each point renders
//! both halves afresh with all its samples, and its time is that render's.

use super::metrics::Halves;
use crate::backend::Backend;
use crate::backend::cpu::{self, Progress, render_samples, render_samples_with_aovs};
use crate::error::{SceneError, module_error};
use crate::extract::RenderScene;
use crate::film::aov::AovFilm;
use crate::film::denoise::{Denoiser, Guides};
use crate::film::{Film, Image};
use crate::scene::Scene;
use glam::UVec2;
use radiant_core::{BuildContext, Registry, Sampler, TextureTable};
use std::cell::Cell;
use std::collections::HashMap;
use std::sync::Mutex;
use std::time::{Duration, Instant};

/// Two progressive renders of one [`RenderScene`] with different seeds.
pub struct TwinRender {
    scene: RenderScene,
    /// The sampler of the half not being rendered (swapped in turn into
    /// `scene.sampler`).
    other: Box<dyn Sampler>,
    films: [Film; 2],
    spp: u32,
    time: Duration,
    /// The GPU that renders instead of the CPU (the `backend` axis).
    gpu: Option<&'static Mutex<Box<dyn Backend>>>,
    /// The first failure (the GPU's, or a whole render's memory);
    /// rendering stops there.
    error: Option<super::AccuracyError>,
    /// Whole renders' images and seeds, where the scene does not render in
    /// passes.
    whole: Option<Whole>,
    /// The seeds of the two halves.
    seeds: [u64; 2],
    /// The denoiser of the `denoise` axis, with each half's planes.
    denoise: Option<(&'static Denoiser, [AovFilm; 2])>,
    /// Time spent denoising so far (developing happens behind `&self`).
    denoise_time: Cell<Duration>,
}

/// The halves of whole renders: their latest images, seeds and invalid
/// samples.
struct Whole {
    images: [Image; 2],
    seeds: [u64; 2],
    invalid: u64,
}

/// Builds `scene`'s sampler for `seed` the way extract does (samplers use
/// only the resolution, seed and spp of the context).
fn build_sampler(
    scene: &Scene,
    registry: &Registry,
    render: &RenderScene,
    seed: u64,
) -> Result<Box<dyn Sampler>, SceneError> {
    let s = &render.settings;
    let mut textures = TextureTable::default();
    let named = HashMap::new();
    let mut ctx = BuildContext::standalone(&scene.dir, &mut textures, &named);
    ctx.resolution = UVec2::new(s.width, s.height);
    ctx.seed = seed;
    ctx.spp = s.spp;
    registry
        .build::<dyn Sampler>(&scene.sampler.type_name, &scene.sampler.params, &mut ctx)
        .map_err(|e| module_error(&scene.file, &scene.sampler, e))
}

impl TwinRender {
    /// Prepares the halves: the first uses `render`'s own sampler (built
    /// for `render.settings.seed`), the second one built for `second_seed`.
    pub fn new(
        scene: &Scene,
        registry: &Registry,
        render: RenderScene,
        second_seed: u64,
    ) -> Result<Self, super::AccuracyError> {
        let other = build_sampler(scene, registry, &render, second_seed)?;
        let first_seed = render.settings.seed;
        let (w, h) = (render.settings.width, render.settings.height);
        let whole = |e| super::AccuracyError::WholeFilm(Box::new(e));
        Ok(Self {
            scene: render,
            other,
            films: [
                Film::try_new(w, h).map_err(whole)?,
                Film::try_new(w, h).map_err(whole)?,
            ],
            spp: 0,
            time: Duration::ZERO,
            gpu: None,
            error: None,
            whole: None,
            seeds: [first_seed, second_seed],
            denoise: None,
            denoise_time: Cell::new(Duration::ZERO),
        })
    }

    /// The same renders, each half denoised by `denoiser` where it is
    /// given (its planes rendered along, on the CPU).
    pub fn denoised_by(
        self,
        denoiser: Option<&'static Denoiser>,
    ) -> Result<Self, super::AccuracyError> {
        let Some(denoiser) = denoiser else {
            return Ok(self);
        };
        let (w, h) = (self.scene.settings.width, self.scene.settings.height);
        let whole = |e| super::AccuracyError::WholeFilm(Box::new(e));
        let planes = [
            AovFilm::try_new(w, h).map_err(whole)?,
            AovFilm::try_new(w, h).map_err(whole)?,
        ];
        Ok(Self {
            denoise: Some((denoiser, planes)),
            ..self
        })
    }

    /// The same renders on `gpu` where it is given.
    pub fn on_gpu(self, gpu: Option<&'static Mutex<Box<dyn Backend>>>) -> Self {
        Self { gpu, ..self }
    }

    /// The failure, if rendering stopped on one.
    pub fn take_error(&mut self) -> Option<super::AccuracyError> {
        self.error.take()
    }

    /// Measures by whole renders where the scene does not render in
    /// passes (see the module documentation).
    pub fn whole_renders_where_needed(&mut self) {
        if cpu::passes(&self.scene).is_err() || self.scene.settings.adaptive.is_some() {
            let (w, h) = (self.scene.settings.width, self.scene.settings.height);
            let black = || Image {
                width: w,
                height: h,
                pixels: vec![radiant_core::Rgb::ZERO; w as usize * h as usize],
            };
            self.whole = Some(Whole {
                images: [black(), black()],
                seeds: self.seeds,
                invalid: 0,
            });
        }
    }

    /// Renders both halves afresh with `spp` samples per pixel each, as
    /// whole renders; returns the time this took.
    fn render_whole(&mut self, spp: u32) -> Duration {
        let Some(whole) = &mut self.whole else {
            return Duration::ZERO;
        };
        let mut took = Duration::ZERO;
        whole.invalid = 0;
        for half in 0..2 {
            self.scene.settings.spp = spp;
            self.scene.settings.seed = whole.seeds[half];
            match cpu::try_render(&self.scene, &Progress::none()) {
                Ok(r) => {
                    took += r.time;
                    whole.invalid += r.invalid_samples;
                    whole.images[half] = r.image;
                }
                Err(e) => {
                    self.error
                        .get_or_insert(super::AccuracyError::WholeFilm(Box::new(e)));
                }
            }
            std::mem::swap(&mut self.scene.sampler, &mut self.other);
        }
        took
    }

    /// Samples per pixel rendered so far in each half.
    pub fn spp(&self) -> u32 {
        self.spp
    }

    /// Render time so far (both halves), denoising included.
    pub fn time(&self) -> Duration {
        self.time + self.denoise_time.get()
    }

    /// Renders both halves on to `spp` samples per pixel each; returns the
    /// time this took.
    pub fn advance(&mut self, spp: u32) -> Duration {
        if self.whole.is_some() {
            // A whole render's time is its own, not added to the last.
            let took = self.render_whole(spp);
            self.spp = spp;
            self.time = took;
            return took;
        }
        let mut took = Duration::ZERO;
        if spp > self.spp && self.error.is_none() {
            for (half, film) in self.films.iter_mut().enumerate() {
                let range = self.spp..spp;
                let none = Progress::none();
                took += match (self.gpu, &mut self.denoise) {
                    (None, Some((_, planes))) => {
                        render_samples_with_aovs(&self.scene, film, &mut planes[half], range, &none)
                            .time
                    }
                    (None, None) => render_samples(&self.scene, film, range, &none).time,
                    (Some(gpu), _) => {
                        let mut gpu = gpu.lock().unwrap_or_else(|e| e.into_inner());
                        match gpu.render_samples(&self.scene, film, range, &none) {
                            Ok(pass) => pass.time,
                            Err(e) => {
                                self.error.get_or_insert(e.into());
                                Duration::ZERO
                            }
                        }
                    }
                };
                std::mem::swap(&mut self.scene.sampler, &mut self.other);
            }
            self.spp = spp;
        }
        self.time += took;
        took
    }

    /// Renders in passes that double the samples per pixel of each half
    /// (1, 2, 4, … up to `max_half`), calling `after_pass` after each. The
    /// cost of the next pass is predicted from the last one (per sample)
    /// plus `after_pass`'s time; a pass that would end later than `limit`
    /// after `start` is cut to the samples that fit, or not started if
    /// fewer than a quarter of the samples so far would fit. The first pass
    /// always runs.
    pub fn run_doubling(
        &mut self,
        max_half: u32,
        start: Instant,
        limit: Duration,
        mut after_pass: impl FnMut(&Self),
    ) {
        let max_half = max_half.max(1);
        let mut spp = 1;
        let mut done = 0;
        let whole = self.whole.is_some();
        loop {
            // Whole renders render all their samples again.
            let rendered = if whole { spp } else { spp - done };
            let per_sample = self.advance(spp).as_secs_f64() / rendered as f64;
            if self.error.is_some() {
                break;
            }
            let after_start = Instant::now();
            after_pass(self);
            let left = limit.as_secs_f64()
                - start.elapsed().as_secs_f64()
                - after_start.elapsed().as_secs_f64();
            let fit = if per_sample > 0.0 {
                (left / per_sample).floor().clamp(0.0, u32::MAX as f64) as u32
            } else {
                u32::MAX
            };
            let fit = if whole { fit.saturating_sub(spp) } else { fit };
            let more = spp.min(max_half - spp).min(fit);
            if more == 0 || more < spp / 4 {
                break;
            }
            done = spp;
            spp += more;
        }
    }

    /// The two halves developed (and denoised, on the `denoise` axis;
    /// a half the denoiser fails on stays as it is).
    pub fn images(&self) -> [Image; 2] {
        if let Some(whole) = &self.whole {
            return whole.images.clone();
        }
        let images = [self.films[0].develop(), self.films[1].develop()];
        let Some((denoiser, planes)) = &self.denoise else {
            return images;
        };
        let start = Instant::now();
        let guides = Guides::of(&self.scene);
        let [a, b] = images;
        let denoised = [(a, &planes[0]), (b, &planes[1])].map(|(image, planes)| {
            denoiser
                .denoise(&image, &planes.develop(), guides)
                .unwrap_or(image)
        });
        self.denoise_time
            .set(self.denoise_time.get() + start.elapsed());
        denoised
    }

    /// Samples that were NaN or infinite (recorded as black), both halves.
    pub fn invalid_samples(&self) -> u64 {
        self.films.iter().map(|f| f.invalid_samples).sum::<u64>()
            + self.whole.as_ref().map_or(0, |w| w.invalid)
    }
}

/// Developed halves kept together with their combined image.
#[derive(Debug, Clone)]
pub struct TwinImages {
    /// The two halves.
    pub halves: [Image; 2],
    /// Their average.
    pub combined: Image,
}

impl TwinImages {
    /// Develops `twin`'s films.
    pub fn of(twin: &TwinRender) -> Self {
        let halves = twin.images();
        let combined = Halves {
            a: &halves[0],
            b: &halves[1],
        }
        .combined();
        Self { halves, combined }
    }

    /// The halves, for the metrics.
    pub fn halves(&self) -> Halves<'_> {
        Halves {
            a: &self.halves[0],
            b: &self.halves[1],
        }
    }
}
