//! `radiant render --time`, `--checkpoint` and `--resume`: a frame rendered
//! in passes into a whole film (`radiant::backend::progressive`), its state
//! written atomically as it goes and when it stops
//! (`radiant::farm::resume`: an EXR output holds it, a PNG gets
//! `NAME.png.resume.exr` beside it), Ctrl-C stopping it after the pass in
//! progress with the image so far written (exit status 130; a second
//! Ctrl-C quits at once, writing nothing more).
//!
//! A plain render goes through the same passes where its whole film fits
//! in [`PLAIN_FILM_BYTES`], so that Ctrl-C keeps its samples too; it
//! writes only the image when it ends, and the state only when it is
//! interrupted. The film's sums are exact, so its image is the one the
//! banded render (which larger frames keep) makes, bit for bit.
//!
//! In a sequence (`--frames A..B`), Ctrl-C stops the frame in progress
//! after its pass and writes only its state, beside its file
//! (`frame_0002.png.resume.exr`, `frame_0002.exr.resume.exr`): the frame's
//! own file appears only when it is finished, so the finished frames stay,
//! `--skip-existing` renders the interrupted one again, and `--frames 2
//! --resume frame_0002.png.resume.exr` finishes it from its samples.

use super::RenderArgs;
use clap::Args;
use radiant::backend::progressive::{self, Controls, Limits, Outcome, Stop};
use radiant::backend::{Backend, Interrupt, Progress, RenderError, Written};
use radiant::extract::RenderScene;
use radiant::farm::partial::{self, Header};
use radiant::farm::resume::{self, state_path};
use radiant::film::Film;
use radiant::film::memory::SUM_BYTES;
use std::path::{Path, PathBuf};
use std::sync::Arc;
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::Duration;

/// The largest film (its exact sums) a plain render keeps whole so that
/// Ctrl-C can write its samples so far (and a state to resume): 16
/// Mpixels; larger frames render in bands
/// ([`radiant::backend::cpu::write_until`]), holding little memory, and
/// Ctrl-C keeps their finished rows (`banded.rs`).
const PLAIN_FILM_BYTES: u64 = 1 << 30;

/// Exit status of a render stopped by Ctrl-C (128 + SIGINT, as shells
/// report it), after the image so far is written.
pub(super) const INTERRUPTED: u8 = 130;

/// Options of progressive renders.
#[derive(Args, Default)]
pub struct ProgressiveArgs {
    /// Render whole passes until this much time is up (per frame), at most
    /// the scene's spp (raise it with --spp): `30s`, `5m`, `1h`, `1.5s`,
    /// `250ms`. Says how many samples per pixel it got.
    #[arg(long, value_parser = parse_duration, conflicts_with = "partition")]
    time: Option<Duration>,
    /// Write the image so far (and the render's state, for --resume) this
    /// often, atomically: `10s`, `2m`.
    #[arg(long, value_parser = parse_duration, conflicts_with = "partition")]
    checkpoint: Option<Duration>,
    /// Continue the render whose state this EXR holds (the output of a
    /// --time, --checkpoint or interrupted render, or `NAME.png.resume.exr`
    /// beside a PNG) up to the scene's spp: the same image, bit for bit, as
    /// one uninterrupted render of that many samples.
    #[arg(long, value_name = "EXR", conflicts_with = "partition")]
    resume: Option<PathBuf>,
    /// The largest film, in pixels, that a plain render keeps whole
    /// (default 16 Mpixels, [`PLAIN_FILM_BYTES`]); larger frames render in
    /// bands. For tests of banded renders on small frames.
    #[arg(long, hide = true, value_name = "PIXELS")]
    whole_film_pixels: Option<u64>,
}

impl ProgressiveArgs {
    /// Whether the render is progressive.
    pub(super) fn is_set(&self) -> bool {
        self.time.is_some() || self.checkpoint.is_some() || self.resume.is_some()
    }
}

/// Parses `30s`, `5m`, `1h`, `250ms` or a number of seconds.
pub fn parse_duration(text: &str) -> Result<Duration, String> {
    let t = text.trim();
    let split = t.find(|c: char| c.is_ascii_alphabetic()).unwrap_or(t.len());
    let (number, unit) = t.split_at(split);
    let scale = match unit {
        "ms" => 1e-3,
        "" | "s" => 1.0,
        "m" | "min" => 60.0,
        "h" => 3600.0,
        _ => {
            return Err(format!(
                "`{text}` has the unit `{unit}`; expected a time such as 30s, 250ms, 5m or 1h"
            ));
        }
    };
    let value: f64 = number
        .trim()
        .parse()
        .map_err(|_| format!("`{text}` is not a time; expected one such as 30s, 5m or 1h"))?;
    Duration::try_from_secs_f64(value * scale)
        .ok()
        .filter(|d| !d.is_zero())
        .ok_or_else(|| format!("`{text}` is not a positive time"))
}

/// Has the first Ctrl-C raise `flag`, and a second one exit at once with
/// [`INTERRUPTED`].
fn handle_interrupts(flag: &Arc<AtomicBool>) -> miette::Result<()> {
    use signal_hook::consts::SIGINT;
    let install = || -> std::io::Result<()> {
        signal_hook::flag::register_conditional_shutdown(
            SIGINT,
            i32::from(INTERRUPTED),
            Arc::clone(flag),
        )?;
        signal_hook::flag::register(SIGINT, Arc::clone(flag))?;
        Ok(())
    };
    install().map_err(|e| miette::miette!("cannot handle Ctrl-C: {e}"))
}

/// Why a progressive frame failed.
#[derive(Debug, thiserror::Error)]
pub(super) enum FrameError {
    /// Rendering failed.
    #[error(transparent)]
    Render(#[from] RenderError),
    /// The state could not be written.
    #[error(transparent)]
    State(#[from] partial::PartialError),
    /// The image could not be written.
    #[error(transparent)]
    Image(#[from] radiant::film::output::ImageError),
    /// The render cannot resume from the file given.
    #[error(transparent)]
    Resume(#[from] resume::ResumeError),
}

/// One progressive frame: what renders it and where it goes.
pub(super) struct Frame<'a> {
    /// The frame's scene.
    pub scene: &'a RenderScene,
    /// Its header (scene, size, seed…; the samples are filled in).
    pub header: Header,
    /// The output image.
    pub path: &'a Path,
    /// Raised by Ctrl-C.
    pub interrupt: &'a AtomicBool,
    /// Whether the frame is one of a sequence's.
    pub sequence: bool,
}

/// Renders `frame` as `args` say (from its resumed state where asked) and
/// writes it; returns what it rendered in this run and how it stopped.
pub(super) fn render(
    backend: &mut dyn Backend,
    frame: &Frame<'_>,
    args: &ProgressiveArgs,
    progress: &Progress<'_>,
) -> Result<(Written, Outcome), FrameError> {
    // A plain render that ends keeps no state: its output is the image alone.
    let plain = !args.is_set();
    let s = &frame.scene.settings;
    let (mut film, done) = match &args.resume {
        Some(from) => {
            let (film, state) = resume::load(from, &frame.header)?;
            (film, state.samples.end)
        }
        None => (
            Film::try_new(s.width, s.height).map_err(RenderError::from)?,
            0,
        ),
    };
    let controls = Controls {
        limits: Limits {
            spp: s.spp,
            time: args.time,
            checkpoint: args.checkpoint,
            pass_time: progressive::PASS_TIME,
        },
        interrupt: frame.interrupt,
        progress,
    };
    let mut checkpoint = |film: &Film, samples: u32| write(frame, film, samples);
    let outcome = progressive::render(
        backend,
        frame.scene,
        &mut film,
        done,
        &controls,
        &mut checkpoint,
    )?;
    if plain && outcome.stop == Stop::Done {
        write_image(frame, &film)?;
    } else if frame.sequence && outcome.stop == Stop::Interrupted {
        if outcome.samples > 0 {
            let header = state_header(frame, &film, outcome.samples);
            partial::write(&resume::frame_state_path(frame.path), &header, &film)?;
        }
    } else if outcome.samples > 0 {
        write(frame, &film, outcome.samples)?;
    }
    let pixels = u64::from(s.width) * u64::from(s.height);
    let written = Written {
        time: outcome.time,
        samples: pixels * u64::from(outcome.samples - done),
        rays: outcome.rays,
        invalid_samples: film.invalid_samples,
    };
    Ok((written, outcome))
}

/// Writes the image of `film`'s first `samples` samples and the render's
/// state (one file for an EXR output), each atomically; the state first,
/// so an image on disk never holds more than its state.
fn write(frame: &Frame<'_>, film: &Film, samples: u32) -> Result<(), FrameError> {
    let header = state_header(frame, film, samples);
    let state = state_path(frame.path);
    partial::write(&state, &header, film)?;
    if state != frame.path {
        write_image(frame, film)?;
    }
    Ok(())
}

/// The state's header of `film`'s first `samples` samples of `frame`.
fn state_header(frame: &Frame<'_>, film: &Film, samples: u32) -> Header {
    Header {
        samples: 0..samples,
        invalid_samples: film.invalid_samples,
        ..frame.header.clone()
    }
}

/// Writes the image of `film`, encoded as the frame's settings say,
/// atomically.
fn write_image(frame: &Frame<'_>, film: &Film) -> Result<(), FrameError> {
    let image = film.try_develop().map_err(RenderError::from)?;
    radiant::film::output::write_encoded(frame.path, &image, &frame.scene.settings.output)?;
    Ok(())
}

/// What a progressive frame did, for the user; `sequence` is the frame's
/// number where it is one of a sequence's.
pub(super) fn describe(outcome: &Outcome, path: &Path, spp: u32, sequence: Option<i64>) -> String {
    let state = state_path(path);
    let passes = format!(
        "{} passes (longest {:.2} s)",
        outcome.passes,
        outcome.longest_pass.as_secs_f64()
    );
    match outcome.stop {
        Stop::Done => format!("{} of {spp} spp in {passes}", outcome.samples),
        Stop::TimeUp => format!(
            "time up: {} of {spp} spp in {passes}; continue with --resume {}",
            outcome.samples,
            state.display()
        ),
        Stop::Interrupted if outcome.samples == 0 => {
            "interrupted before the first pass ended: nothing written".to_string()
        }
        Stop::Interrupted if let Some(frame) = sequence => {
            let state = resume::frame_state_path(path);
            format!(
                "interrupted: frame {frame}'s {} of {spp} spp kept in {} (its image is written \
                 when it is finished); finish it with --frames {frame} --resume {}",
                outcome.samples,
                state.display(),
                state.display()
            )
        }
        Stop::Interrupted => format!(
            "interrupted: {} of {spp} spp written to {}; continue with --resume {}",
            outcome.samples,
            path.display(),
            state.display()
        ),
    }
}

/// A progressive render's session: the scene's bytes (for the state's
/// digest) and the Ctrl-C flag.
pub(super) struct Session {
    scene_bytes: Vec<u8>,
    interrupt: Arc<AtomicBool>,
    /// Whether `--time`, `--checkpoint` or `--resume` asked for it (else
    /// it is a plain render's, kept for Ctrl-C).
    asked: bool,
    /// Whether Ctrl-C is handled yet: from the start where passes were
    /// asked for; in a plain render from its first frame in passes or in
    /// bands on the CPU (until then Ctrl-C quits at once, as it does in a
    /// render that cannot stop early).
    handling: AtomicBool,
    /// Whether it renders several frames.
    sequence: bool,
    /// The largest film a plain render keeps whole, in bytes of sums.
    whole_film_bytes: u64,
}

/// The session of a progressive render where `args` ask for one, or of a
/// plain render (of one frame or a sequence), handling Ctrl-C from now on
/// where passes were asked for.
pub(super) fn start(args: &RenderArgs) -> miette::Result<Option<Session>> {
    let p = &args.progressive;
    if p.resume.is_some() && args.frames.is_some_and(|(a, b)| b > a) {
        miette::bail!(
            "--resume continues one frame, not frames {}..{}: resume each frame with its own file",
            args.frames.map_or(0, |f| f.0),
            args.frames.map_or(0, |f| f.1)
        );
    }
    let scene_bytes = std::fs::read(&args.scene)
        .map_err(|e| miette::miette!("cannot read the scene `{}`: {e}", args.scene.display()))?;
    let session = Session {
        scene_bytes,
        interrupt: Arc::new(AtomicBool::new(false)),
        asked: p.is_set(),
        handling: AtomicBool::new(false),
        sequence: args.frames.is_some_and(|(a, b)| b > a),
        whole_film_bytes: p
            .whole_film_pixels
            .map_or(PLAIN_FILM_BYTES, |pixels| pixels.saturating_mul(SUM_BYTES)),
    };
    if session.asked {
        session.handle_interrupts()?;
    }
    Ok(Some(session))
}

impl Session {
    /// Whether `--time`, `--checkpoint` or `--resume` asked for passes.
    pub(super) fn asked(&self) -> bool {
        self.asked
    }

    /// Handles Ctrl-C from now on (once).
    fn handle_interrupts(&self) -> miette::Result<()> {
        if !self.handling.swap(true, Ordering::Relaxed) {
            handle_interrupts(&self.interrupt)?;
        }
        Ok(())
    }

    /// Whether this session renders `scene`'s frame: always where passes
    /// were asked for; for a plain render, where it needs no first-hit
    /// planes (`passes`: AOVs, denoising, alpha keep their own path) and its
    /// whole film fits in memory and in [`PLAIN_FILM_BYTES`] (or
    /// `--whole-film-pixels`).
    pub(super) fn takes(&self, scene: &RenderScene, passes: bool) -> bool {
        use radiant::film::memory::FrameTooLarge;
        let s = &scene.settings;
        let bytes = u64::from(s.width) * u64::from(s.height) * SUM_BYTES;
        self.asked
            || (!passes
                && bytes <= self.whole_film_bytes
                && FrameTooLarge::new(s.width, s.height).check().is_ok()
                && radiant::backend::cpu::passes(scene).is_ok())
    }

    /// Renders `frame` of `args.scene` (its scene `scene`) to `path` on
    /// `backend`, saying how it went through `note`.
    pub(super) fn render(
        &self,
        args: &RenderArgs,
        backend: &mut dyn Backend,
        (scene, frame): (&RenderScene, i64),
        path: &Path,
        progress: &Progress<'_>,
        note: &dyn Fn(&str),
    ) -> miette::Result<Written> {
        self.handle_interrupts()?;
        let frame_state = Frame {
            scene,
            header: Header::new(
                &args.scene,
                &self.scene_bytes,
                frame,
                &scene.settings,
                None,
                0..0,
            ),
            path,
            interrupt: &self.interrupt,
            sequence: self.sequence,
        };
        let (written, outcome) = render(backend, &frame_state, &args.progressive, progress)
            .map_err(|e| miette::miette!("{e}"))?;
        if self.asked || outcome.stop != Stop::Done {
            let sequence = self.sequence.then_some(frame);
            note(&describe(&outcome, path, scene.settings.spp, sequence));
        }
        Ok(written)
    }

    /// Ctrl-C for a render with first-hit planes (`passes.rs`) or in
    /// bands (`banded.rs`), handled from now on: a frame of a sequence
    /// keeps nothing when interrupted.
    pub(super) fn interrupt(&self) -> miette::Result<Interrupt<'_>> {
        self.handle_interrupts()?;
        Ok(Interrupt {
            flag: &self.interrupt,
            keep: !self.sequence,
        })
    }

    /// Whether Ctrl-C stopped the render.
    pub(super) fn interrupted(&self) -> bool {
        self.interrupt.load(Ordering::Relaxed)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn durations_parse_with_units() {
        let ms = Duration::from_millis;
        assert_eq!(parse_duration("30s"), Ok(ms(30_000)));
        assert_eq!(parse_duration("1.5s"), Ok(ms(1500)));
        assert_eq!(parse_duration("250ms"), Ok(ms(250)));
        assert_eq!(parse_duration("2m"), Ok(ms(120_000)));
        assert_eq!(parse_duration("1h"), Ok(ms(3_600_000)));
        assert_eq!(parse_duration(" 10 "), Ok(ms(10_000)));
        for bad in ["", "s", "10x", "-3s", "0s", "1e400s", "ten"] {
            assert!(parse_duration(bad).is_err(), "{bad}");
        }
        assert!(
            parse_duration("10x")
                .expect_err("unit")
                .contains("the unit `x`")
        );
    }
}
