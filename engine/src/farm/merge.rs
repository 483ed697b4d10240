//! `radiant merge`: adds the partial films of a frame's sample partitions
//! ([`partial`](super::partial) files) into the frame. The files must be
//! parts of one render (same scene, size, frame, samples per pixel, seed
//! and depth) whose sample ranges cover the frame's samples exactly once;
//! they are added in the order of their samples. The sums are exact
//! ([`Sums`](crate::film::exact::Sums)), so the merged frame is the one
//! render of all the samples would have made, bit for bit.

use super::partial::{self, Header, PartialError};
use crate::film::Film;
use crate::film::memory::FrameTooLarge;
use std::ops::Range;
use std::path::PathBuf;

/// Why partial files do not merge into a frame.
#[derive(Debug, thiserror::Error)]
pub enum MergeError {
    /// Nothing to merge.
    #[error("no partial files to merge")]
    Empty,
    /// Two files belong to different renders.
    #[error(
        "`{a}` and `{b}` are not partitions of the same frame: their {what} differ ({a_value} and {b_value})"
    )]
    Different {
        /// The first file.
        a: PathBuf,
        /// The file that differs from it.
        b: PathBuf,
        /// What differs.
        what: &'static str,
        /// Its value in `a`.
        a_value: String,
        /// Its value in `b`.
        b_value: String,
    },
    /// Two files render some of the same samples.
    #[error("`{a}` (samples {}..{}) and `{b}` (samples {}..{}) overlap: each sample of the frame must come from one file", a_samples.start, a_samples.end, b_samples.start, b_samples.end)]
    Overlap {
        /// One file.
        a: PathBuf,
        /// Its samples.
        a_samples: Range<u32>,
        /// A file whose samples overlap them.
        b: PathBuf,
        /// Its samples.
        b_samples: Range<u32>,
    },
    /// No file renders some of the frame's samples.
    #[error("samples {}..{} of the frame's {spp} are in none of the files ({context}): render the missing partitions and merge again", missing.start, missing.end)]
    Gap {
        /// The samples no file has.
        missing: Range<u32>,
        /// The frame's samples per pixel.
        spp: u32,
        /// Which files lie around the gap.
        context: String,
    },
    /// A file is a progressive render's state, not a partition.
    #[error(
        "`{path}` is a progressive render's state (samples 0..{samples} of {spp}), not a sample partition: continue it with `radiant render --resume {path}`"
    )]
    Progressive {
        /// The file.
        path: PathBuf,
        /// Samples it holds.
        samples: u32,
        /// The samples per pixel it renders at most.
        spp: u32,
    },
    /// A file could not be read, or is not a partition.
    #[error(transparent)]
    Partial(#[from] PartialError),
    /// The merged film does not fit in memory.
    #[error(transparent)]
    Memory(#[from] FrameTooLarge),
}

/// Adds the partial files `files` into their frame's film; returns it
/// with the header of the file with the first samples. Headers are checked
/// first; then the files are read and added one at a time, in the order of
/// their samples.
pub fn merge(files: &[PathBuf]) -> Result<(Film, Header), MergeError> {
    let headers = files
        .iter()
        .map(|path| Ok((path.clone(), partial::read_header(path)?)))
        .collect::<Result<Vec<_>, MergeError>>()?;
    let order = order(&headers)?;
    let (_, first) = &headers[order[0]];
    let mut film = Film::try_new(first.width, first.height)?;
    for &i in &order {
        let part = partial::read(&headers[i].0)?;
        film.add_sums(&part.sums, part.header.invalid_samples);
    }
    Ok((film, first.clone()))
}

/// The order in which `parts` add up to one frame (by their samples), or
/// why they do not.
pub fn order(parts: &[(PathBuf, Header)]) -> Result<Vec<usize>, MergeError> {
    let Some((first_path, first)) = parts.first() else {
        return Err(MergeError::Empty);
    };
    if let Some((path, header)) = parts.iter().find(|(_, h)| h.partition.is_none()) {
        return Err(MergeError::Progressive {
            path: path.clone(),
            samples: header.samples.end,
            spp: header.spp,
        });
    }
    let identity = first.identity();
    for (path, header) in &parts[1..] {
        for ((what, a, a_shown), (_, b, b_shown)) in identity.iter().zip(header.identity()) {
            if *a != b {
                return Err(MergeError::Different {
                    a: first_path.clone(),
                    b: path.clone(),
                    what,
                    a_value: a_shown.clone(),
                    b_value: b_shown,
                });
            }
        }
    }
    let mut order: Vec<usize> = (0..parts.len()).collect();
    order.sort_by_key(|&i| (parts[i].1.samples.start, parts[i].1.samples.end));
    check_coverage(parts, &order)?;
    Ok(order)
}

/// Checks that `parts`, taken in `order` (by their samples), cover the
/// frame's samples once.
fn check_coverage(parts: &[(PathBuf, Header)], order: &[usize]) -> Result<(), MergeError> {
    let spp = parts[0].1.spp;
    let name = |p: &PathBuf| format!("`{}`", p.display());
    let mut next = 0;
    let mut previous: Option<&(PathBuf, Header)> = None;
    for part in order.iter().map(|&i| &parts[i]) {
        let samples = &part.1.samples;
        if let Some(prev) = previous.filter(|_| samples.start < next) {
            return Err(MergeError::Overlap {
                a: prev.0.clone(),
                a_samples: prev.1.samples.clone(),
                b: part.0.clone(),
                b_samples: samples.clone(),
            });
        }
        if samples.start > next {
            let context = match previous {
                Some(prev) => format!("between {} and {}", name(&prev.0), name(&part.0)),
                None => format!("before {}", name(&part.0)),
            };
            return Err(MergeError::Gap {
                missing: next..samples.start,
                spp,
                context,
            });
        }
        next = samples.end;
        previous = Some(part);
    }
    if next < spp {
        return Err(MergeError::Gap {
            missing: next..spp,
            spp,
            context: format!("after {}", name(&parts[order[order.len() - 1]].0)),
        });
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::farm::partial::tests::header;
    use crate::farm::partition::Partition;

    /// Partition `index`/4 of a 3×2 film of 16 spp, as if read from
    /// `p{index}.exr`.
    fn part(index: u32) -> (PathBuf, Header) {
        (PathBuf::from(format!("p{index}.exr")), header(index))
    }

    /// The error of ordering `parts`, as text.
    fn refusal(parts: &[(PathBuf, Header)]) -> String {
        order(parts).expect_err("refused").to_string()
    }

    #[test]
    fn files_add_up_in_sample_order_whatever_their_order() {
        let dir = tempfile::tempdir().expect("temporary folder");
        let mut files = Vec::new();
        let mut expected = Film::new(3, 2);
        for index in 1..=4 {
            let mut film = Film::new(3, 2);
            let layer: Vec<f32> = (0..24).map(|i| (i * index) as f32 / 7.0).collect();
            film.add_layers(&layer, 2);
            expected.add_layers(&layer, 2);
            let path = dir.path().join(format!("p{index}.exr"));
            partial::write(&path, &header(index), &film).expect("writes");
            files.push(path);
        }
        files.reverse();
        let (film, first) = merge(&files).expect("a whole frame");
        assert_eq!(first, header(1));
        assert_eq!(film.sums(), expected.sums());
        assert_eq!(film.invalid_samples, 8);
        // A file cut short is named.
        let bytes = std::fs::read(&files[0]).expect("reads");
        std::fs::write(&files[0], &bytes[..bytes.len() - 100]).expect("writes");
        let e = merge(&files).expect_err("truncated").to_string();
        assert!(e.contains("p4.exr"), "{e}");
    }

    #[test]
    fn gaps_and_overlaps_name_the_files() {
        let gap = refusal(&[part(1), part(2), part(4)]);
        assert!(gap.starts_with("samples 8..12 of the frame's 16 are in none of the files (between `p2.exr` and `p4.exr`)"), "{gap}");
        let end = refusal(&[part(3), part(1), part(2)]);
        assert!(
            end.contains(
                "samples 12..16 of the frame's 16 are in none of the files (after `p3.exr`)"
            ),
            "{end}"
        );
        let start = refusal(&[part(2), part(3), part(4)]);
        assert!(
            start.contains(
                "samples 0..4 of the frame's 16 are in none of the files (before `p2.exr`)"
            ),
            "{start}"
        );
        let twice = refusal(&[part(1), part(2), part(2), part(3), part(4)]);
        assert!(
            twice.contains("`p2.exr` (samples 4..8) and `p2.exr` (samples 4..8) overlap"),
            "{twice}"
        );
        // A half of the frame overlapping a quarter.
        let (path, mut half) = part(1);
        half.partition = Some(Partition::new(1, 2).expect("valid"));
        half.samples = 0..8;
        let e = refusal(&[(path, half), part(2), part(3), part(4)]);
        assert!(
            e.contains("`p1.exr` (samples 0..8) and `p2.exr` (samples 4..8) overlap"),
            "{e}"
        );
        // Halves and quarters that fit together merge.
        let (path, mut half) = part(1);
        half.samples = 0..8;
        assert_eq!(
            order(&[part(4), (path, half), part(3)]).expect("whole"),
            [1, 2, 0]
        );
    }

    #[test]
    fn parts_of_other_renders_are_refused() {
        type Change = fn(&mut Header);
        let cases: [(&str, Change); 6] = [
            ("scene", |h| h.scene_digest ^= 1),
            ("size", |h| h.width = 4),
            ("frame", |h| h.frame += 1),
            ("samples per pixel", |h| h.spp = 32),
            ("seed", |h| h.seed += 1),
            ("max_depth", |h| h.max_depth = 5),
        ];
        for (what, change) in cases {
            let (path, mut other) = part(2);
            change(&mut other);
            let e = refusal(&[part(1), (path, other)]);
            let start = format!(
                "`p1.exr` and `p2.exr` are not partitions of the same frame: their {what} differ"
            );
            assert!(e.starts_with(&start), "{e}");
        }
        let (path, mut moved) = part(2);
        moved.scene = "/elsewhere/x.yaml".into();
        assert!(
            order(&[part(1), (path, moved), part(3), part(4)]).is_ok(),
            "same content"
        );
        assert!(matches!(order(&[]), Err(MergeError::Empty)));
        let (path, mut state) = part(1);
        state.partition = None;
        state.samples = 0..5;
        let e = refusal(&[part(2), (path, state)]);
        assert!(
            e.starts_with("`p1.exr` is a progressive render's state (samples 0..5 of 16), not a sample partition: continue it with `radiant render --resume p1.exr`"),
            "{e}"
        );
    }
}
