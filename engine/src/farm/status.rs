//! `radiant farm status`: which frames of a sequence are done, missing or
//! partial. Files are written atomically, so a frame file is normally whole
//! or absent; a frame counts as partial where its file exists but does not
//! read as a whole image (copied in part, damaged), or where only some of
//! its sample partitions have been rendered.

use super::partition::Partition;
use super::slurm::part_path;
use crate::world::systems::sequence_path as frame_file;
use rayon::prelude::*;
use std::path::Path;

/// The state of one frame.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum FrameState {
    /// Its file is a whole image.
    Done,
    /// Neither its file nor any partition of it exists.
    Missing,
    /// Its file exists but is not a whole image (the reason), or some of
    /// its partitions are rendered and it is not merged yet.
    Partial(String),
}

/// The state of every frame in `first..=last` of the sequence `output`
/// (a name with a run of `#`), looking for `partitions` sample partitions
/// per frame where it is given.
pub fn frame_states(
    output: &Path,
    (first, last): (i64, i64),
    partitions: Option<u32>,
) -> Vec<(i64, FrameState)> {
    (first..=last)
        .into_par_iter()
        .map(|frame| (frame, frame_state(output, frame, partitions)))
        .collect()
}

fn frame_state(output: &Path, frame: i64, partitions: Option<u32>) -> FrameState {
    let path = frame_file(output, frame);
    if path.exists() {
        return match whole_image(&path) {
            Ok(()) => FrameState::Done,
            Err(reason) => FrameState::Partial(reason),
        };
    }
    let Some(count) = partitions else {
        return FrameState::Missing;
    };
    let rendered = (1..=count)
        .filter_map(|k| Partition::new(k, count).ok())
        .filter(|&p| part_path(output, frame, p).exists())
        .count();
    match rendered {
        0 => FrameState::Missing,
        n => FrameState::Partial(format!("{n} of {count} partitions rendered, not merged")),
    }
}

/// `Ok` if `path` decodes as a whole image, else why not.
fn whole_image(path: &Path) -> Result<(), String> {
    let is_exr = path
        .extension()
        .is_some_and(|e| e.eq_ignore_ascii_case("exr"));
    if is_exr {
        crate::film::output::read_exr(path)
            .map(drop)
            .map_err(|e| e.to_string())
    } else {
        image::open(path)
            .map(drop)
            .map_err(|e| format!("{}: {e}", path.display()))
    }
}

/// The frames in `frames` (ascending) as ranges: `1..4, 7, 9..12`.
pub fn ranges(frames: &[i64]) -> String {
    let mut parts: Vec<String> = Vec::new();
    let mut i = 0;
    while i < frames.len() {
        let mut j = i;
        while j + 1 < frames.len() && frames[j + 1] == frames[j] + 1 {
            j += 1;
        }
        parts.push(if i == j {
            frames[i].to_string()
        } else {
            format!("{}..{}", frames[i], frames[j])
        });
        i = j + 1;
    }
    parts.join(", ")
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::film::Image;

    #[test]
    fn frames_are_done_missing_or_partial() {
        let dir = tempfile::tempdir().expect("temporary folder");
        let output = dir.path().join("f_##.exr");
        let image = Image {
            width: 2,
            height: 2,
            pixels: vec![radiant_core::Rgb::ONE; 4],
        };
        for frame in [1, 2, 5] {
            crate::film::output::write(frame_file(&output, frame), &image).expect("writes");
        }
        // Frame 5 cut short, as a copy interrupted half-way leaves it.
        let five = frame_file(&output, 5);
        let bytes = std::fs::read(&five).expect("reads");
        std::fs::write(&five, &bytes[..bytes.len() / 2]).expect("writes");
        // Frame 4: one of two partitions.
        let part = part_path(&output, 4, Partition::new(2, 2).expect("valid"));
        std::fs::write(part, b"").expect("writes");
        let states = frame_states(&output, (1, 5), Some(2));
        assert_eq!(states[0], (1, FrameState::Done));
        assert_eq!(states[1], (2, FrameState::Done));
        assert_eq!(states[2], (3, FrameState::Missing));
        assert_eq!(
            states[3],
            (
                4,
                FrameState::Partial("1 of 2 partitions rendered, not merged".into())
            )
        );
        assert!(
            matches!(&states[4], (5, FrameState::Partial(why)) if why.contains("f_05.exr")),
            "{states:?}"
        );
        assert_eq!(
            frame_states(&output, (4, 4), None),
            [(4, FrameState::Missing)]
        );
    }

    #[test]
    fn frame_lists_read_as_ranges() {
        assert_eq!(ranges(&[1, 2, 3, 4, 7, 9, 10, 11, 12]), "1..4, 7, 9..12");
        assert_eq!(ranges(&[-1, 0]), "-1..0");
        assert_eq!(ranges(&[]), "");
    }
}
