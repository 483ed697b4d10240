//! Reading OpenEXR images as linear RGB: the first layer with RGB(A)
//! channels, any channel type, pixels row-major from the top row. The
//! engine reads references and `compare` inputs through it, the lights
//! their environment maps and the textures their image files.
//!
//! The header is read and its sizes checked before any pixel memory is
//! reserved (against a fixed bound and the memory available), so a corrupt
//! or hostile header, or an image too large for the machine, is an error,
//! not an attempt to allocate hundreds of gigabytes.

use crate::Rgb;
use glam::UVec2;
use std::path::Path;

/// The most pixels an image may have (16384 × 16384; 3 GiB as RGB floats).
pub const MAX_EXR_PIXELS: usize = 1 << 28;

/// Why an EXR file could not be read.
#[derive(Debug, thiserror::Error)]
pub enum ExrError {
    /// The path is not a regular file (a folder, a FIFO, a device).
    #[error("{0}")]
    NotRegular(String),
    /// The pixels would not fit in the memory available.
    #[error(transparent)]
    Memory(#[from] crate::memory::OutOfMemory),
    /// The `exr` crate could not read the file.
    #[error("{0}")]
    Read(#[from] exr::error::Error),
    /// A layer is larger than [`MAX_EXR_PIXELS`] (or its size overflows).
    #[error(
        "a layer is {width}×{height} pixels, more than the {MAX_EXR_PIXELS} an image may have \
         (is the header damaged?)"
    )]
    TooLarge {
        /// Layer width in pixels.
        width: usize,
        /// Layer height in pixels.
        height: usize,
    },
}

/// The pixels and size of the EXR image at `path`.
pub fn read_exr_rgb(path: &Path) -> Result<(Vec<Rgb>, UVec2), ExrError> {
    use exr::prelude::read_first_rgba_layer_from_file;
    crate::input_file::reject_special_file(path).map_err(ExrError::NotRegular)?;
    let meta = exr::meta::MetaData::read_from_file(path, false)?;
    for header in &meta.headers {
        let (width, height) = (header.layer_size.width(), header.layer_size.height());
        if width.checked_mul(height).is_none_or(|n| n > MAX_EXR_PIXELS) {
            return Err(ExrError::TooLarge { width, height });
        }
    }
    if let Some(header) = meta.headers.first() {
        let (width, height) = (header.layer_size.width(), header.layer_size.height());
        // The pixels as RGB floats, and a copy that a texture or
        // environment map makes of them.
        let needed = (width * height) as u64 * 2 * std::mem::size_of::<Rgb>() as u64;
        crate::memory::check(needed, || format!("the {width}×{height} image"))?;
    }
    let image = read_first_rgba_layer_from_file(
        path,
        |resolution, _| {
            let (w, h) = (resolution.width(), resolution.height());
            (vec![Rgb::ZERO; w * h], w)
        },
        |(pixels, w): &mut (Vec<Rgb>, usize), pos, (r, g, b, _a): (f32, f32, f32, f32)| {
            pixels[pos.y() * *w + pos.x()] = Rgb::new(r, g, b);
        },
    )?;
    let size = image.layer_data.size;
    let (pixels, _) = image.layer_data.channel_data.pixels;
    // Both sides are at most 2^28 (their product is), so they fit in u32.
    Ok((
        pixels,
        UVec2::new(size.width() as u32, size.height() as u32),
    ))
}

#[cfg(test)]
mod tests {
    // `unwrap` in this test code is the assertion: the inputs are the test's
    // own, so a failure is a bug, and the panic reports it with the error.
    use super::*;
    use exr::prelude::*;

    fn write_test_image(path: &Path, width: usize, height: usize) {
        write_rgb_file(path, width, height, |x, y| {
            (x as f32, y as f32, (x + y) as f32 * 0.5)
        })
        .unwrap();
    }

    #[test]
    fn reads_pixels_row_major_from_the_top() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("a.exr");
        write_test_image(&path, 3, 2);
        let (pixels, size) = read_exr_rgb(&path).unwrap();
        assert_eq!(size, UVec2::new(3, 2));
        // Row 1, column 2 of a 3-wide image.
        assert_eq!(pixels[5], Rgb::new(2.0, 1.0, 1.5));
    }

    #[test]
    fn a_header_claiming_a_huge_image_is_an_error_before_allocating() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("bomb.exr");
        write_test_image(&path, 4, 4);
        // Move the data window's xMin (an i32 after the attribute's name,
        // type and size) far to the left: a 4 KB file that claims billions
        // of pixels.
        let mut bytes = std::fs::read(&path).unwrap();
        let name = b"dataWindow\0box2i\0";
        let at = bytes.windows(name.len()).position(|w| w == name).unwrap() + name.len() + 4;
        bytes[at..at + 4].copy_from_slice(&(-419_430_400i32).to_le_bytes());
        std::fs::write(&path, bytes).unwrap();
        let error = read_exr_rgb(&path).unwrap_err();
        assert!(matches!(error, ExrError::TooLarge { .. }), "{error}");
        assert!(error.to_string().contains("more than"), "{error}");
    }

    #[test]
    fn garbage_is_an_error() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("g.exr");
        std::fs::write(&path, b"not an exr file at all").unwrap();
        assert!(matches!(read_exr_rgb(&path), Err(ExrError::Read(_))));
    }
}
