//! Image files: PNG (tone-mapped sRGB, 8 bit) and EXR (linear float RGB),
//! written atomically: into a temporary file beside the target, then
//! renamed over it, so an interrupted write never leaves a broken file.

use super::Image;
use std::io::{BufWriter, Write};
use std::path::Path;

/// Errors of reading and writing images.
#[derive(Debug, thiserror::Error)]
pub enum ImageError {
    /// The extension names no supported format.
    #[error("cannot write `{0}`: the file name must end in .png or .exr")]
    UnknownFormat(String),
    /// Reading or writing failed.
    #[error("{path}: {message}")]
    Io {
        /// The file.
        path: String,
        /// What went wrong.
        message: String,
    },
}

fn io_error(path: &Path, e: impl std::fmt::Display) -> ImageError {
    ImageError::Io {
        path: path.display().to_string(),
        message: e.to_string(),
    }
}

/// The sRGB transfer function of a linear value, clamped to [0, 1].
pub fn srgb_encode(linear: f32) -> f32 {
    let c = if linear.is_nan() {
        0.0
    } else {
        linear.clamp(0.0, 1.0)
    };
    if c <= 0.003_130_8 {
        12.92 * c
    } else {
        1.055 * c.powf(1.0 / 2.4) - 0.055
    }
}

/// A hidden temporary file in the folder of `path` (ending in `suffix`),
/// to be renamed onto `path` once complete, so that an interrupted write
/// never leaves a broken file. It is created with the permissions a plain
/// `File::create` would give (0o666 less the umask), not tempfile's private
/// 0o600, so the renamed result is as readable as any other output.
pub fn temp_file_beside(path: &Path, suffix: &str) -> std::io::Result<tempfile::NamedTempFile> {
    let dir = match path.parent() {
        Some(d) if !d.as_os_str().is_empty() => d,
        _ => Path::new("."),
    };
    let mut builder = tempfile::Builder::new();
    builder.prefix(".radiant-").suffix(suffix);
    #[cfg(unix)]
    {
        use std::os::unix::fs::PermissionsExt;
        builder.permissions(std::fs::Permissions::from_mode(0o666));
    }
    builder.tempfile_in(dir)
}

/// Writes `image` to `path`, choosing the format by extension.
pub fn write(path: impl AsRef<Path>, image: &Image) -> Result<(), ImageError> {
    let path = path.as_ref();
    let ext = path
        .extension()
        .and_then(|e| e.to_str())
        .map(str::to_ascii_lowercase);
    let format = match ext.as_deref() {
        Some("png") => Format::Png,
        Some("exr") => Format::Exr,
        _ => return Err(ImageError::UnknownFormat(path.display().to_string())),
    };
    let mut tmp = temp_file_beside(path, ".tmp").map_err(|e| io_error(path, e))?;
    match format {
        Format::Png => write_png(tmp.as_file_mut(), image),
        Format::Exr => write_exr(tmp.as_file_mut(), image),
    }
    .map_err(|e| io_error(path, e))?;
    tmp.as_file().sync_all().map_err(|e| io_error(path, e))?;
    tmp.persist(path).map_err(|e| io_error(path, e.error))?;
    Ok(())
}

enum Format {
    Png,
    Exr,
}

/// The image as PNG output shows it: clamped, sRGB-encoded, 8-bit RGB
/// triples, row-major.
pub fn to_srgb8(image: &Image) -> Vec<u8> {
    image
        .pixels
        .iter()
        .flat_map(|p| p.to_array())
        .map(|c| (srgb_encode(c) * 255.0 + 0.5) as u8)
        .collect()
}

fn write_png(file: &mut std::fs::File, image: &Image) -> Result<(), String> {
    let bytes = to_srgb8(image);
    let buffer = image::RgbImage::from_raw(image.width, image.height, bytes)
        .ok_or("image size does not match its pixels")?;
    let mut w = BufWriter::new(file);
    buffer
        .write_to(&mut w, image::ImageFormat::Png)
        .map_err(|e| e.to_string())?;
    w.flush().map_err(|e| e.to_string())
}

fn write_exr(file: &mut std::fs::File, image: &Image) -> Result<(), String> {
    use exr::prelude::{Encoding, Layer, LayerAttributes, SpecificChannels, Vec2, WritableImage};
    let width = image.width as usize;
    let channels = SpecificChannels::rgb(|pos: Vec2<usize>| {
        let p = image.pixels[pos.y() * width + pos.x()];
        (p.x, p.y, p.z)
    });
    let layer = Layer::new(
        (image.width as usize, image.height as usize),
        LayerAttributes::named("rgb"),
        Encoding::SMALL_LOSSLESS,
        channels,
    );
    let w = BufWriter::new(file);
    exr::image::Image::from_layer(layer)
        .write()
        .to_buffered(w)
        .map_err(|e| e.to_string())
}

/// Reads the RGB channels of an EXR file as linear floats.
pub fn read_exr(path: impl AsRef<Path>) -> Result<Image, ImageError> {
    let path = path.as_ref();
    let (pixels, size) =
        radiant_core::exr_file::read_exr_rgb(path).map_err(|e| io_error(path, e))?;
    Ok(Image {
        width: size.x,
        height: size.y,
        pixels,
    })
}

#[cfg(test)]
mod tests {
    // `unwrap` in this test code is the assertion: the inputs are the test's
    // own, so a failure is a bug, and the panic reports it with the error.
    use super::*;
    use radiant_core::Rgb;

    #[cfg(unix)]
    #[test]
    fn outputs_get_the_permissions_of_a_plain_file() {
        use std::os::unix::fs::PermissionsExt;
        let dir = tempfile::tempdir().unwrap();
        let plain = dir.path().join("plain");
        std::fs::File::create(&plain).unwrap();
        let out = dir.path().join("out.png");
        let image = Image {
            width: 1,
            height: 1,
            pixels: vec![Rgb::splat(0.5)],
        };
        write(&out, &image).unwrap();
        let mode = |p: &Path| std::fs::metadata(p).unwrap().permissions().mode() & 0o777;
        assert_eq!(mode(&out), mode(&plain));
    }

    fn sample_image() -> Image {
        Image {
            width: 3,
            height: 2,
            pixels: (0..6)
                .map(|i| Rgb::new(i as f32 * 0.5, 0.25, 7.0))
                .collect(),
        }
    }

    #[test]
    fn exr_round_trips_exactly() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("x.exr");
        write(&path, &sample_image()).unwrap();
        assert_eq!(read_exr(&path).unwrap(), sample_image());
        // No temporary file is left beside it.
        assert_eq!(std::fs::read_dir(dir.path()).unwrap().count(), 1);
    }

    #[test]
    fn png_is_srgb_encoded() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("x.png");
        write(&path, &sample_image()).unwrap();
        let png = image::open(&path).unwrap().to_rgb8();
        assert_eq!(png.get_pixel(1, 0).0, [188, 137, 255]);
        assert!((srgb_encode(0.5) - 0.735_356_7).abs() < 1e-6);
    }

    #[test]
    fn unknown_extension_and_missing_folder_are_errors() {
        assert!(matches!(
            write("x.bmp", &sample_image()),
            Err(ImageError::UnknownFormat(_))
        ));
        assert!(write("/nonexistent/dir/x.png", &sample_image()).is_err());
    }
}
