//! What a frame's film costs in memory, checked before it is taken: what a
//! frame needs (the whole film, or a band of it with the rows on their way
//! to the file) is compared with the memory available, and the film's
//! sums and finished pixels are reserved with `try_reserve`, so a frame too
//! large for the machine (or for a `ulimit`) is a [`FrameTooLarge`] error
//! that says what it needed and what would fit, never an allocation abort.

use radiant_core::Rgb;
use radiant_core::memory::{self, gib};
use std::fmt;

/// Bytes per pixel of the film's weighted sums (RGB and weight, exact
/// 128-bit fixed point: [`super::exact::Sums`]).
pub const SUM_BYTES: u64 = std::mem::size_of::<super::exact::Sums>() as u64;
/// Bytes per pixel of a tile: its exact sums and the `f32` sums of the
/// sample index being splatted.
pub const TILE_BYTES: u64 = SUM_BYTES + 16;
/// Bytes per pixel of the developed image (RGB, f32).
pub const IMAGE_BYTES: u64 = std::mem::size_of::<Rgb>() as u64;

/// A frame whose film could not be allocated, or would not fit in the
/// memory available.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
pub struct FrameTooLarge {
    /// Frame width in pixels.
    pub width: u32,
    /// Frame height in pixels.
    pub height: u32,
    /// Rows held at once where the frame is rendered in bands; `None`
    /// where the whole film is held.
    pub band: Option<u32>,
    /// What the frame needs, part by part: what for, and bytes.
    pub parts: Vec<(&'static str, u64)>,
    /// Memory available to the process when the allocation failed, where
    /// the system says (Linux: the smaller of `MemAvailable` and the
    /// address-space limit left).
    pub available: Option<u64>,
}

impl FrameTooLarge {
    /// The error for a whole `width`×`height` film, with the memory
    /// available now.
    pub fn new(width: u32, height: u32) -> Self {
        let pixels = width as u64 * height as u64;
        Self {
            width,
            height,
            band: None,
            parts: vec![
                ("the film's weighted sums", pixels * SUM_BYTES),
                ("the finished image", pixels * IMAGE_BYTES),
            ],
            available: memory::available(),
        }
    }

    /// The error for a `width`×`height` frame rendered in bands of `band`
    /// rows that need `parts`, with the memory available now.
    pub fn banded(width: u32, height: u32, band: u32, parts: Vec<(&'static str, u64)>) -> Self {
        Self {
            width,
            height,
            band: Some(band),
            parts,
            available: memory::available(),
        }
    }

    /// Bytes the frame needs: the sum of its parts.
    pub fn needed(&self) -> u64 {
        self.parts.iter().map(|(_, bytes)| bytes).sum()
    }

    /// `Ok` where the memory available is unknown or enough for what the
    /// frame needs, else this error: the check made before anything is
    /// taken (an allocation may still fail later, and is reported the
    /// same way).
    pub fn check(self) -> Result<(), Self> {
        match self.available {
            Some(available) if self.needed() > available => Err(self),
            _ => Ok(()),
        }
    }

    /// What would fit in `available` bytes: rows at this width for a whole
    /// film, the width for a banded one (its needs grow with the width).
    fn what_fits(&self, available: u64) -> String {
        match self.band {
            None => {
                // Every part is per pixel: rows scale the whole need.
                let rows = (available as u128 * self.height as u128 / self.needed().max(1) as u128)
                    .min(u64::MAX as u128);
                format!("enough for {rows} rows at this width")
            }
            Some(_) => {
                let width = (available as u128 * self.width as u128 / self.needed().max(1) as u128)
                    .min(u32::MAX as u128);
                format!("enough for a frame about {width} pixels wide")
            }
        }
    }
}

impl fmt::Display for FrameTooLarge {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "a {}×{} frame ", self.width, self.height)?;
        if let Some(band) = self.band {
            write!(f, "rendered in bands of {band} rows ")?;
        }
        let parts: Vec<String> = self
            .parts
            .iter()
            .map(|(what, bytes)| format!("{} for {what}", gib(*bytes)))
            .collect();
        write!(
            f,
            "needs {} of memory ({}) and it could not be allocated",
            gib(self.needed()),
            parts.join(", ")
        )?;
        if let Some(available) = self.available {
            write!(
                f,
                "; about {} is available, {}",
                gib(available),
                self.what_fits(available)
            )?;
        }
        match self.band {
            None => write!(
                f,
                ": render a smaller frame or on a machine with more memory"
            ),
            Some(_) => write!(
                f,
                ": render a narrower frame or on a machine with more memory"
            ),
        }
    }
}

/// A vector of `len` copies of `value`, or `None` where the memory cannot
/// be reserved.
pub fn try_filled<T: Clone>(len: usize, value: T) -> Option<Vec<T>> {
    let mut v = Vec::new();
    v.try_reserve_exact(len).ok()?;
    v.resize(len, value);
    Some(v)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_message_gives_the_need_and_what_fits() {
        let e = FrameTooLarge {
            available: Some(4 << 30),
            ..FrameTooLarge::new(32768, 32768)
        };
        // 64 bytes of exact sums and 12 of image per pixel.
        assert_eq!(SUM_BYTES, 64);
        assert_eq!(e.needed(), 32768 * 32768 * 76);
        let shown = e.to_string();
        assert!(
            shown.starts_with("a 32768×32768 frame needs 76.00 GiB"),
            "{shown}"
        );
        assert!(
            shown.contains("64.00 GiB for the film's weighted sums"),
            "{shown}"
        );
        // 4 GiB / (32768 × 76 bytes) = 1724.6 rows.
        assert!(
            shown.contains("enough for 1724 rows at this width"),
            "{shown}"
        );
        assert!(e.check().is_err());
    }

    #[test]
    fn a_band_says_what_width_would_fit() {
        let e = FrameTooLarge {
            available: Some(1 << 30),
            ..FrameTooLarge::banded(32768, 32768, 20, vec![("the band", 2 << 30)])
        };
        let shown = e.to_string();
        assert!(
            shown.starts_with("a 32768×32768 frame rendered in bands of 20 rows needs 2.00 GiB"),
            "{shown}"
        );
        assert!(shown.contains("a frame about 16384 pixels wide"), "{shown}");
        let fits = FrameTooLarge {
            available: None,
            ..e
        };
        assert!(fits.check().is_ok());
    }

    #[test]
    fn impossible_reservations_are_none() {
        assert!(try_filled(usize::MAX / 2, 0u64).is_none());
        assert_eq!(try_filled(3, 7u8), Some(vec![7, 7, 7]));
    }
}
