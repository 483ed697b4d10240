//! Where a render task's films lie in the frame: the task's pixels grown
//! by the filter's reach and clipped to the image, and which of them a
//! sample's filter footprint covers. The beauty's [`super::TileFilm`] and
//! the first-hit planes' [`super::aov::AovTile`] share it.

use glam::Vec2;

/// A tile's rectangle of frame pixels, row-major in the tile's buffers.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) struct TileBounds {
    /// The first column.
    pub x0: i32,
    /// The first row.
    pub y0: i32,
    /// Columns.
    pub width: i32,
    /// Rows.
    pub height: i32,
    /// The frame's width.
    pub image_width: i32,
    /// The frame's height.
    pub image_height: i32,
}

impl TileBounds {
    /// The pixels [x0, x1) × [y0, y1) of a `size` image, grown by `reach`
    /// pixels and clipped to the image.
    pub fn new(x0: u32, y0: u32, x1: u32, y1: u32, size: (u32, u32), reach: f32) -> Self {
        let border = reach.ceil() as i32;
        let (w, h) = (size.0 as i32, size.1 as i32);
        let bx0 = (x0 as i32 - border).max(0);
        let by0 = (y0 as i32 - border).max(0);
        let bx1 = (x1 as i32 + border).min(w);
        let by1 = (y1 as i32 + border).min(h);
        Self {
            x0: bx0,
            y0: by0,
            width: bx1 - bx0,
            height: by1 - by0,
            image_width: w,
            image_height: h,
        }
    }

    /// Pixels covered.
    pub fn len(&self) -> usize {
        (self.width * self.height) as usize
    }

    /// The index of frame pixel (`x`, `y`) in the tile's buffers.
    #[inline]
    pub fn index(&self, x: i32, y: i32) -> usize {
        ((y - self.y0) * self.width + x - self.x0) as usize
    }

    /// The frame pixels whose centres lie within `radius` of raster
    /// position `pos` along each axis, clipped to the image: columns
    /// `x0..=x1` and rows `y0..=y1` as (x0, x1, y0, y1); empty ranges where
    /// none do.
    #[inline]
    pub fn footprint(&self, pos: Vec2, radius: f32) -> (i32, i32, i32, i32) {
        // One rounding instruction each on x86-64-v2 (the build's target).
        let (lo, hi) = ((pos - 0.5 - radius).ceil(), (pos - 0.5 + radius).floor());
        (
            (lo.x as i32).max(0),
            (hi.x as i32).min(self.image_width - 1),
            (lo.y as i32).max(0),
            (hi.y as i32).min(self.image_height - 1),
        )
    }
}
