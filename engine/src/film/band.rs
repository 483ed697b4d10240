//! Rendering a frame in bands: the frame's tile rows are rendered a group
//! at a time, top to bottom, and the film holds only the rows that the
//! group being rendered can reach (its tile rows and the filter's border
//! above and below). Once a group is merged, every row above the next
//! group's reach is finished and goes on to the file ([`super::Film::advance`]),
//! so memory grows with the frame's width, not its area. [`Bands`] is that
//! geometry and what it costs in memory.

use super::encode;
use super::memory::{FrameTooLarge, IMAGE_BYTES, SUM_BYTES, TILE_BYTES};
use std::ops::Range;

/// How a frame is cut into groups of tile rows, and the rows of film that
/// a group needs.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Bands {
    width: u32,
    height: u32,
    /// Tile edge in pixels.
    tile: u32,
    /// Tile rows per group.
    group: u32,
    /// How far, in whole pixels, a sample reaches beyond its pixel.
    border: u32,
}

impl Bands {
    /// Groups of `group` tile rows (at least one) of `tile`-pixel tiles
    /// over a `width`×`height` frame whose samples reach `reach` pixels
    /// beyond their own (the filter's radius when splatting).
    pub fn new(width: u32, height: u32, tile: u32, group: u32, reach: f32) -> Self {
        Self {
            width,
            height,
            tile: tile.max(1),
            group: group.max(1),
            border: reach.max(0.0).ceil() as u32,
        }
    }

    /// Rows the film holds: a group's tile rows and the border on both
    /// sides, at most the frame's height.
    pub fn rows(&self) -> u32 {
        (self.tile * self.group + 2 * self.border).min(self.height)
    }

    /// The tile rows of each group, top to bottom.
    pub fn groups(&self) -> impl Iterator<Item = Range<u32>> + use<> {
        let (rows, group) = (self.height.div_ceil(self.tile), self.group);
        (0..rows)
            .step_by(group as usize)
            .map(move |first| first..(first + group).min(rows))
    }

    /// The rows finished once the tile rows up to `group.end` are merged:
    /// those no later tile reaches.
    pub fn finished(&self, group: &Range<u32>) -> u32 {
        let below = group.end * self.tile;
        if below >= self.height {
            self.height
        } else {
            below.saturating_sub(self.border)
        }
    }

    /// What a banded render of this frame needs in memory on `threads`
    /// threads, part by part, as the error it becomes where that is not
    /// available.
    pub fn need(&self, threads: usize) -> FrameTooLarge {
        let (w, rows) = (self.width as u64, self.rows() as u64);
        let tiles = self.width.div_ceil(self.tile) as u64 * self.group as u64;
        let tile_pixels = (self.tile as u64 + 2 * self.border as u64).pow(2);
        FrameTooLarge::banded(
            self.width,
            self.height,
            self.rows(),
            vec![
                ("the band's weighted sums", w * rows * SUM_BYTES),
                (
                    "finished rows on their way to the file",
                    w * rows * IMAGE_BYTES,
                ),
                ("the tiles in flight", tiles * tile_pixels * TILE_BYTES),
                (
                    "the encoder",
                    encode::buffer_bytes(self.width, self.rows(), threads),
                ),
            ],
        )
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn groups_cover_the_frame_and_rows_finish_past_the_reach() {
        // 50 rows: tile rows 0..4, in groups of 2 (the last one short).
        let bands = Bands::new(40, 50, 16, 2, 1.5);
        assert_eq!(bands.rows(), 36);
        let groups: Vec<_> = bands.groups().collect();
        assert_eq!(groups, vec![0..2, 2..4]);
        // The next group's tiles start at row 32 and reach 2 rows up.
        assert_eq!(bands.finished(&groups[0]), 30);
        assert_eq!(bands.finished(&groups[1]), 50);
        // Held rows 30..66 cover every row the second group reaches.
        assert!(30 + bands.rows() >= 4 * 16 + 2);
    }

    #[test]
    fn a_band_never_holds_more_than_the_frame() {
        let bands = Bands::new(8, 20, 16, 4, 2.0);
        assert_eq!(bands.rows(), 20);
        assert_eq!(bands.groups().count(), 1);
        assert!(bands.need(2).needed() > 0);
    }
}
