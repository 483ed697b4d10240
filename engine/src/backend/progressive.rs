//! Progressive renders: a frame rendered in passes (a pass is some samples
//! of every pixel, [`Backend::render_samples`]) into one whole [`Film`],
//! until its samples are done, its time is up (`--time`) or it is
//! interrupted (Ctrl-C), with the film handed to a checkpoint writer every
//! so often (`--checkpoint`). The film's sums are exact
//! ([`crate::film::exact`]), so how the samples are cut into passes — or
//! into runs, where a render resumes from a checkpoint — does not change
//! the image: it is the one uninterrupted render of the same sample count
//! makes, bit for bit.
//!
//! Passes are sized from the time the samples so far took: about
//! [`PASS_TIME`] each by default (so an interruption waits at most about
//! that long for the pass in progress), the first one a single block of
//! samples, and under a time limit no more than fit in the time left, so a
//! timed render ends within about one pass of its limit, not after it.
//! Passes hold whole blocks of samples ([`BLOCK`]), so that the film's
//! exact sums do not depend on where passes (or runs) start.

use super::cpu::Pass;
use super::{Backend, Progress, RenderError};
use crate::extract::RenderScene;
use crate::film::Film;
use crate::film::exact::BLOCK;
use std::ops::Range;
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::{Duration, Instant};

/// The wall time a pass aims at, by default.
pub const PASS_TIME: Duration = Duration::from_secs(1);

/// When a progressive render stops and checkpoints.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Limits {
    /// Samples per pixel at most (the frame's `spp`).
    pub spp: u32,
    /// Wall time at most, if limited: passes start only where they are
    /// expected to end within it.
    pub time: Option<Duration>,
    /// How often the film is handed to the checkpoint writer, if at all.
    pub checkpoint: Option<Duration>,
    /// The wall time a pass aims at ([`PASS_TIME`]).
    pub pass_time: Duration,
}

/// What steers a progressive render while it runs.
pub struct Controls<'a> {
    /// When it stops and checkpoints.
    pub limits: Limits,
    /// Raised (by a Ctrl-C handler) to stop after the pass in progress.
    pub interrupt: &'a AtomicBool,
    /// Receives the samples of the frame done, of `limits.spp`.
    pub progress: &'a Progress<'a>,
}

/// Why a progressive render stopped.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Stop {
    /// All `spp` samples are rendered.
    Done,
    /// The time limit left no room for another pass.
    TimeUp,
    /// The interrupt flag was raised (Ctrl-C).
    Interrupted,
}

/// What a progressive render did.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Outcome {
    /// Samples per pixel the film holds (those it was given included).
    pub samples: u32,
    /// Why it stopped.
    pub stop: Stop,
    /// Wall time of this run's passes.
    pub time: Duration,
    /// Passes rendered in this run.
    pub passes: u32,
    /// The longest of them.
    pub longest_pass: Duration,
    /// Rays traced in this run.
    pub rays: u64,
    /// Checkpoints written in this run.
    pub checkpoints: u32,
}

/// Samples per pixel of the next pass: `done` (a multiple of [`BLOCK`])
/// of `limits.spp` are rendered, `per_sample` is the wall time one sample
/// per pixel has taken so far (`None` before the first pass) and `elapsed`
/// the time since the render started. Whole blocks, or all the samples
/// left; 0: stop.
pub fn next_pass(
    done: u32,
    limits: &Limits,
    per_sample: Option<Duration>,
    elapsed: Duration,
) -> u32 {
    let left = u64::from(limits.spp.saturating_sub(done));
    let block = u64::from(BLOCK);
    // `n` samples in whole blocks, or all of those left where they fit.
    let blocks = |n: u64| if n >= left { left } else { n / block * block };
    let Some(per_sample) = per_sample.filter(|t| !t.is_zero()) else {
        return blocks(block) as u32;
    };
    let fit = |time: Duration| (time.as_secs_f64() / per_sample.as_secs_f64()) as u64;
    let mut samples = blocks(fit(limits.pass_time).max(block));
    if let Some(limit) = limits.time {
        samples = samples.min(blocks(fit(limit.saturating_sub(elapsed))));
    }
    samples as u32
}

/// Renders passes of `scene` on `backend` into `film`, which holds the
/// first `done` samples of every pixel (0 for a new render), until the
/// limits or the interrupt flag of `controls` stop it;
/// `checkpoint(film, samples)` is called after a pass whenever the
/// checkpoint interval has passed since the last one (or the start), and
/// not after the last pass. Progress reports count the samples of the
/// frame, `done` included. Errors are the backend's or the checkpoint
/// writer's.
pub fn render<E: From<RenderError>>(
    backend: &mut dyn Backend,
    scene: &RenderScene,
    film: &mut Film,
    done: u32,
    controls: &Controls<'_>,
    checkpoint: &mut dyn FnMut(&Film, u32) -> Result<(), E>,
) -> Result<Outcome, E> {
    let mut pass = |film: &mut Film, samples: Range<u32>, progress: &Progress<'_>| {
        backend.render_samples(scene, film, samples, progress)
    };
    render_passes(&mut pass, film, done, controls, checkpoint)
}

/// Renders a pass of samples into a film: the backend's passes, or the CPU
/// backend's with first-hit planes beside the film.
pub type PassFn<'a> =
    dyn FnMut(&mut Film, Range<u32>, &Progress<'_>) -> Result<Pass, RenderError> + 'a;

/// [`render`] with the passes rendered by `pass` (which adds the samples
/// of a range to the film, and to whatever else it keeps).
pub fn render_passes<E: From<RenderError>>(
    pass: &mut PassFn<'_>,
    film: &mut Film,
    done: u32,
    controls: &Controls<'_>,
    checkpoint: &mut dyn FnMut(&Film, u32) -> Result<(), E>,
) -> Result<Outcome, E> {
    let (limits, progress) = (&controls.limits, controls.progress);
    let start = Instant::now();
    let pixels = u64::from(film.width()) * u64::from(film.height());
    let total = pixels * u64::from(limits.spp);
    let mut outcome = Outcome {
        samples: done,
        stop: Stop::Done,
        time: Duration::ZERO,
        passes: 0,
        longest_pass: Duration::ZERO,
        rays: 0,
        checkpoints: 0,
    };
    let mut last_checkpoint = start;
    loop {
        if controls.interrupt.load(Ordering::Relaxed) {
            outcome.stop = Stop::Interrupted;
            break;
        }
        let rendered = outcome.samples - done;
        let per_sample = (rendered > 0).then(|| outcome.time / rendered);
        let count = next_pass(outcome.samples, limits, per_sample, start.elapsed());
        if count == 0 {
            if outcome.samples < limits.spp {
                outcome.stop = Stop::TimeUp;
            }
            break;
        }
        let before = pixels * u64::from(outcome.samples);
        let report = |d: u64, _: u64| progress.report(before + d, total);
        let pass_progress = if progress.is_active() {
            Progress::new(&report)
        } else {
            Progress::none()
        };
        let range = outcome.samples..outcome.samples + count;
        let pass = pass(film, range, &pass_progress)?;
        outcome.samples += count;
        outcome.passes += 1;
        outcome.time += pass.time;
        outcome.longest_pass = outcome.longest_pass.max(pass.time);
        outcome.rays += pass.rays;
        if let Some(every) = limits.checkpoint
            && last_checkpoint.elapsed() >= every
            && outcome.samples < limits.spp
        {
            checkpoint(film, outcome.samples)?;
            outcome.checkpoints += 1;
            last_checkpoint = Instant::now();
        }
    }
    Ok(outcome)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::backend::CpuBackend;
    use crate::backend::cpu::tests::cornell_scene;

    fn limits(spp: u32, time: Option<u64>) -> Limits {
        Limits {
            spp,
            time: time.map(Duration::from_millis),
            checkpoint: None,
            pass_time: PASS_TIME,
        }
    }

    #[test]
    fn passes_aim_at_the_pass_time_and_fit_the_time_left() {
        let ms = Duration::from_millis;
        // The first pass is one block, or what is left, or none.
        assert_eq!(next_pass(0, &limits(64, None), None, ms(0)), 4);
        assert_eq!(next_pass(0, &limits(3, None), None, ms(0)), 3);
        assert_eq!(next_pass(64, &limits(64, None), None, ms(0)), 0);
        // 10 ms a sample: 100 samples a second, at most those left.
        assert_eq!(next_pass(4, &limits(1000, None), Some(ms(10)), ms(0)), 100);
        assert_eq!(next_pass(988, &limits(1000, None), Some(ms(10)), ms(0)), 12);
        assert_eq!(next_pass(1000, &limits(1000, None), Some(ms(10)), ms(0)), 0);
        // 7 ms a sample: 142 samples a second, in whole blocks: 140.
        assert_eq!(next_pass(4, &limits(1000, None), Some(ms(7)), ms(0)), 140);
        // A slow sample still makes a pass of one block.
        assert_eq!(next_pass(4, &limits(8, None), Some(ms(5000)), ms(0)), 4);
        assert_eq!(next_pass(4, &limits(6, None), Some(ms(5000)), ms(0)), 2);
        // Under a 3 s limit with 2.93 s gone, 7 samples of 10 ms fit: one
        // block; with 2.97 s gone not a block: stop, though samples are left.
        let timed = limits(1000, Some(3000));
        assert_eq!(next_pass(8, &timed, Some(ms(10)), ms(2930)), 4);
        assert_eq!(next_pass(8, &timed, Some(ms(10)), ms(2970)), 0);
        assert_eq!(next_pass(8, &timed, Some(ms(10)), ms(4000)), 0);
        // The last samples of a frame fit where a whole block would not.
        let end = limits(10, Some(3000));
        assert_eq!(next_pass(8, &end, Some(ms(10)), ms(2970)), 2);
    }

    /// Renders `scene`'s samples in the ranges `cuts` apart into one film
    /// on two threads.
    fn in_ranges(scene: &RenderScene, cuts: &[u32]) -> Film {
        let s = &scene.settings;
        let mut film = Film::new(s.width, s.height);
        rayon::ThreadPoolBuilder::new()
            .num_threads(2)
            .build()
            .expect("thread pool")
            .install(|| {
                for range in cuts.windows(2) {
                    CpuBackend
                        .render_samples(scene, &mut film, range[0]..range[1], &Progress::none())
                        .expect("renders");
                }
            });
        film
    }

    #[test]
    fn any_cut_of_the_samples_gives_the_same_sums() {
        // Block-aligned ranges; the batches of the 8-pixel-wide edge tiles
        // hold 8 samples, so blocks span batches and batches span blocks.
        // The gaussian filter splats across tiles.
        let scene = cornell_scene(24, 20, 23);
        let whole = in_ranges(&scene, &[0, 23]);
        for cuts in [&[0, 4, 8, 23][..], &[0, 12, 16, 20, 23], &[0, 20, 23]] {
            let cut = in_ranges(&scene, cuts);
            assert!(cut.sums() == whole.sums(), "{cuts:?}");
        }
        // Partitions rendered into films of their own and added up.
        let mut merged = Film::new(24, 20);
        for range in [[0, 4], [4, 12], [12, 23]] {
            merged.add_sums(in_ranges(&scene, &range).sums(), 0);
        }
        assert!(merged.sums() == whole.sums());
        assert!(whole.develop().mean() > 0.0);
    }

    #[test]
    fn interrupts_and_checkpoints_fall_between_passes() {
        let scene = cornell_scene(16, 16, 14);
        let mut film = Film::new(16, 16);
        let stop = AtomicBool::new(false);
        let controls = Controls {
            limits: Limits {
                spp: 14,
                time: None,
                checkpoint: Some(Duration::ZERO),
                // Passes of one block.
                pass_time: Duration::from_nanos(1),
            },
            interrupt: &stop,
            progress: &Progress::none(),
        };
        // A checkpoint after every pass but the last; each sees whole
        // passes, and stopping at the second one interrupts the render.
        let mut seen = Vec::new();
        let mut checkpoint = |f: &Film, samples: u32| -> Result<(), RenderError> {
            seen.push((samples, f.develop().mean()));
            if seen.len() == 2 {
                stop.store(true, Ordering::Relaxed);
            }
            Ok(())
        };
        let outcome = render(
            &mut CpuBackend,
            &scene,
            &mut film,
            0,
            &controls,
            &mut checkpoint,
        )
        .expect("renders");
        assert_eq!(outcome.stop, Stop::Interrupted);
        assert_eq!(outcome.checkpoints, 2);
        assert_eq!(outcome.passes, 2);
        assert_eq!(seen[0].0, 4, "the first pass is one block");
        assert_eq!(outcome.samples, seen[1].0);
        // Resumed from there, it ends where one render of 14 samples does.
        stop.store(false, Ordering::Relaxed);
        let outcome = render(
            &mut CpuBackend,
            &scene,
            &mut film,
            outcome.samples,
            &controls,
            &mut |_: &Film, _| Ok::<(), RenderError>(()),
        )
        .expect("renders");
        assert_eq!((outcome.stop, outcome.samples), (Stop::Done, 14));
        assert!(film.sums() == in_ranges(&scene, &[0, 14]).sums());
    }
}
