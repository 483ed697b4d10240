//! Resumable renders: where a progressive render (`--time`, `--checkpoint`,
//! Ctrl-C) keeps its state, and how `--resume` takes it back. The state is
//! a [`partial`] file whose header has no partition and whose samples are
//! `0..n` of the render's `spp`: the exact sums of the first `n` samples
//! of every pixel, with the scene's digest, size, frame, seed and depth.
//! An EXR output is that file itself (its `R`, `G`, `B` are the image); any
//! other output gets it beside it as `NAME.resume.exr` ([`state_path`]).
//! Samplers draw sample `i` of a pixel from (seed, pixel, `i`), so
//! rendering samples `n..` onto those sums gives the uninterrupted
//! render's image, bit for bit.

use super::partial::{self, Header, PartialError};
use crate::film::Film;
use crate::film::memory::FrameTooLarge;
use std::path::{Path, PathBuf};

/// Why a render cannot resume from a file.
#[derive(Debug, thiserror::Error)]
pub enum ResumeError {
    /// The file is not an EXR (a PNG, say), which holds no state.
    #[error(
        "cannot resume from `{path}`: only EXR files hold a render's state{}",
        sidecar.as_ref().map_or(String::new(), |s| format!("; this render's state is in `{}`", s.display()))
    )]
    NotExr {
        /// The file.
        path: PathBuf,
        /// The state file beside it, where there is one.
        sidecar: Option<PathBuf>,
    },
    /// The file is an image without state, or cannot be read.
    #[error(
        "cannot resume from `{path}`: {why}; --resume takes the EXR that a render with --time, --checkpoint or an interrupted one wrote (`NAME.resume.exr` beside a PNG)"
    )]
    NoState {
        /// The file.
        path: PathBuf,
        /// What is wrong with it.
        why: String,
    },
    /// The file is a sample partition for `radiant merge`.
    #[error(
        "cannot resume from `{path}`: it is sample partition {partition} of a frame; `radiant merge` adds partitions up"
    )]
    Partition {
        /// The file.
        path: PathBuf,
        /// Its partition.
        partition: String,
    },
    /// The file is a render of something else.
    #[error(
        "cannot resume from `{path}`: it renders a different {what} ({file} there, {render} here)"
    )]
    Different {
        /// The file.
        path: PathBuf,
        /// What differs.
        what: &'static str,
        /// Its value in the file.
        file: String,
        /// Its value in this render.
        render: String,
    },
    /// The file holds more samples than the render asks for.
    #[error(
        "cannot resume from `{path}`: it holds {samples} samples per pixel, more than the {spp} asked for; raise --spp"
    )]
    TooManySamples {
        /// The file.
        path: PathBuf,
        /// Samples per pixel it holds.
        samples: u32,
        /// Samples per pixel asked for.
        spp: u32,
    },
    /// The film does not fit in memory.
    #[error(transparent)]
    Memory(#[from] FrameTooLarge),
}

/// The file that holds the resumable state of a render written to
/// `output`: `output` itself where it is an EXR, else `output` with
/// `.resume.exr` appended (`frame.png` → `frame.png.resume.exr`).
pub fn state_path(output: &Path) -> PathBuf {
    if is_exr(output) {
        output.to_path_buf()
    } else {
        frame_state_path(output)
    }
}

/// The file that holds the state of an interrupted frame of a sequence
/// written to `output`: always `output` with `.resume.exr` appended, since
/// the frame's own file must not exist until the frame is finished
/// (`--skip-existing` leaves the frames whose file exists).
pub fn frame_state_path(output: &Path) -> PathBuf {
    let mut name = output.as_os_str().to_os_string();
    name.push(".resume.exr");
    PathBuf::from(name)
}

/// Whether `path` names an EXR file.
fn is_exr(path: &Path) -> bool {
    path.extension()
        .is_some_and(|e| e.eq_ignore_ascii_case("exr"))
}

/// Reads the state at `path` for a render that `render` describes (its
/// `samples` are ignored): the film of the samples done and the file's
/// header, or why the file does not continue that render.
pub fn load(path: &Path, render: &Header) -> Result<(Film, Header), ResumeError> {
    if !is_exr(path) {
        let sidecar = state_path(path);
        return Err(ResumeError::NotExr {
            path: path.to_path_buf(),
            sidecar: sidecar.exists().then_some(sidecar),
        });
    }
    let no_state = |e: PartialError| ResumeError::NoState {
        path: path.to_path_buf(),
        why: match e {
            PartialError::NotPartial { missing, .. } => missing,
            e => e.to_string(),
        },
    };
    let header = partial::read_header(path).map_err(no_state)?;
    if let Some(p) = header.partition {
        return Err(ResumeError::Partition {
            path: path.to_path_buf(),
            partition: p.to_string(),
        });
    }
    // The samples per pixel may grow; everything else must agree.
    for ((what, file, file_shown), (_, here, here_shown)) in
        header.identity().into_iter().zip(render.identity())
    {
        if what != "samples per pixel" && file != here {
            return Err(ResumeError::Different {
                path: path.to_path_buf(),
                what,
                file: file_shown,
                render: here_shown,
            });
        }
    }
    if header.samples.end > render.spp {
        return Err(ResumeError::TooManySamples {
            path: path.to_path_buf(),
            samples: header.samples.end,
            spp: render.spp,
        });
    }
    let state = partial::read(path).map_err(no_state)?;
    let mut film = Film::try_new(header.width, header.height)?;
    film.add_sums(&state.sums, header.invalid_samples);
    Ok((film, header))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::farm::partial::tests::header;

    /// The state of a 3×2 render after `samples` of its 16 samples.
    fn state(samples: u32) -> Header {
        Header {
            partition: None,
            samples: 0..samples,
            ..header(1)
        }
    }

    #[test]
    fn state_files_sit_beside_non_exr_outputs() {
        assert_eq!(state_path(Path::new("a/f.exr")), Path::new("a/f.exr"));
        assert_eq!(state_path(Path::new("a/f.EXR")), Path::new("a/f.EXR"));
        assert_eq!(
            state_path(Path::new("a/f.png")),
            Path::new("a/f.png.resume.exr")
        );
    }

    #[test]
    fn a_state_loads_back_and_wrong_inputs_name_the_file() {
        let dir = tempfile::tempdir().expect("temporary folder");
        let path = dir.path().join("f.exr");
        let mut film = Film::new(3, 2);
        let layer: Vec<f32> = (0..24).map(|i| (i as f32 * 0.3).cos() + 1.5).collect();
        film.add_layers(&layer, 2);
        partial::write(&path, &state(5), &film).expect("writes");
        let (loaded, h) = load(&path, &state(0)).expect("resumes");
        assert_eq!(h, state(5));
        assert_eq!(loaded.sums(), film.sums());
        assert_eq!(loaded.invalid_samples, 2);
        // More samples per pixel may be asked for; fewer than it holds not.
        let more = Header {
            spp: 32,
            ..state(0)
        };
        assert!(load(&path, &more).is_ok());
        let fewer = Header { spp: 4, ..state(0) };
        let e = load(&path, &fewer).expect_err("too many").to_string();
        assert!(
            e.contains("holds 5 samples per pixel, more than the 4"),
            "{e}"
        );
        assert!(e.contains("f.exr"), "{e}");
        // Another scene, size or seed.
        type Change = fn(&mut Header);
        let cases: [(&str, Change); 3] = [
            ("scene", |h| h.scene_digest ^= 1),
            ("size", |h| h.width = 4),
            ("seed", |h| h.seed += 1),
        ];
        for (what, change) in cases {
            let mut other = state(0);
            change(&mut other);
            let e = load(&path, &other).expect_err(what).to_string();
            assert!(
                e.starts_with(&format!(
                    "cannot resume from `{}`: it renders a different {what}",
                    path.display()
                )),
                "{e}"
            );
        }
        // A partition, a plain EXR, a PNG, a missing file.
        partial::write(&path, &header(2), &film).expect("writes");
        let e = load(&path, &state(0)).expect_err("partition").to_string();
        assert!(e.contains("it is sample partition 2/4 of a frame"), "{e}");
        crate::film::output::write(&path, &film.develop()).expect("writes");
        let e = load(&path, &state(0)).expect_err("plain").to_string();
        assert!(e.contains("has no `radiant."), "{e}");
        let png = dir.path().join("f.png");
        let e = load(&png, &state(0)).expect_err("png").to_string();
        assert_eq!(
            e,
            format!(
                "cannot resume from `{}`: only EXR files hold a render's state",
                png.display()
            )
        );
        partial::write(&state_path(&png), &state(5), &film).expect("writes");
        let e = load(&png, &state(0)).expect_err("png").to_string();
        assert!(e.ends_with("f.png.resume.exr`"), "{e}");
        let e = load(&dir.path().join("gone.exr"), &state(0)).expect_err("missing");
        assert!(e.to_string().contains("gone.exr"), "{e}");
    }
}
