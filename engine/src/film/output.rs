//! Image files: PNG (tone-mapped sRGB, 8 or 16 bit), JPEG (tone-mapped
//! sRGB), EXR (linear float or half RGB) and Radiance HDR (linear RGBE),
//! written atomically: into a temporary file beside the target, then
//! renamed over it, so an interrupted write never leaves a broken file.
//! A whole [`Image`] is written here through the row encoders of
//! [`super::encode`], which banded renders feed row by row; [`read`]
//! reads any of them back as linear values (PNG and JPEG sRGB-decoded).

use super::Image;
use super::encode;
use std::path::Path;

/// Errors of reading and writing images.
#[derive(Debug, thiserror::Error)]
pub enum ImageError {
    /// The extension names no supported format.
    #[error("cannot write `{0}`: the file name must end in .png, .jpg, .jpeg, .exr or .hdr")]
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

/// The error of `path` failing as `e` says.
pub(super) fn io_error(path: &Path, e: impl std::fmt::Display) -> ImageError {
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
    let file = builder.tempfile_in(dir)?;
    // Remembered for `remove_unfinished_outputs`; a completed file is
    // renamed away, so its entry names nothing by then.
    if let Ok(mut pending) = UNFINISHED.lock() {
        pending.push(file.path().to_path_buf());
    }
    Ok(file)
}

/// The temporary files made by [`temp_file_beside`] in this process.
static UNFINISHED: std::sync::Mutex<Vec<std::path::PathBuf>> = std::sync::Mutex::new(Vec::new());

/// Removes the temporary files of outputs not yet complete, for an exit
/// that skips their destructors (the out-of-memory exit of the binary's
/// allocator). It allocates nothing (a path up to a few hundred bytes is
/// converted on the stack) and gives up rather than wait for the list.
pub fn remove_unfinished_outputs() {
    if let Ok(pending) = UNFINISHED.try_lock() {
        for path in pending.iter() {
            let _ = std::fs::remove_file(path);
        }
    }
}

/// Writes `image` to `path`, choosing the format by extension, with the
/// default encoding (clamped 8-bit sRGB, float EXR).
pub fn write(path: impl AsRef<Path>, image: &Image) -> Result<(), ImageError> {
    write_encoded(path, image, &super::encoding::Encoding::default())
}

/// Writes `image` to `path`, choosing the format by extension, its values
/// as `encoding` says.
pub fn write_encoded(
    path: impl AsRef<Path>,
    image: &Image,
    encoding: &super::encoding::Encoding,
) -> Result<(), ImageError> {
    encode::write_encoded(path.as_ref(), encoding, image.width, image.height, |rows| {
        rows.write_rows(&image.pixels)
    })
}

/// The first bytes of every OpenEXR file.
const EXR_MAGIC: [u8; 4] = [0x76, 0x2f, 0x31, 0x01];

/// Reads an image Radiant writes, whatever its extension says — EXR,
/// Radiance HDR, PNG (8 or 16 bit), JPEG — as linear RGB: EXR and HDR as
/// stored, PNG and JPEG sRGB-decoded (their tone curve, if any, is not
/// undone; alpha is dropped).
pub fn read(path: impl AsRef<Path>) -> Result<Image, ImageError> {
    use std::io::Read;
    let path = path.as_ref();
    let mut magic = [0u8; 4];
    let is_exr = std::fs::File::open(path)
        .and_then(|mut f| f.read_exact(&mut magic))
        .is_ok_and(|()| magic == EXR_MAGIC);
    if is_exr {
        return read_exr(path);
    }
    let texels = radiant_textures::load_image(path, false).map_err(|e| match e {
        radiant_textures::LoadError::Read { message, .. } => io_error(
            path,
            format!("{message} (Radiant reads EXR, Radiance HDR, PNG and JPEG images)"),
        ),
        other => io_error(path, other),
    })?;
    Ok(Image {
        width: texels.width,
        height: texels.height,
        pixels: texels.data,
    })
}

/// The image as PNG output shows it: clamped, sRGB-encoded, 8-bit RGB
/// triples, row-major.
pub fn to_srgb8(image: &Image) -> Vec<u8> {
    image.pixels.iter().flat_map(|p| srgb8(*p)).collect()
}

/// A pixel as PNG output shows it: clamped, sRGB-encoded, 8 bits per
/// channel.
pub fn srgb8(p: radiant_core::Rgb) -> [u8; 3] {
    p.to_array().map(|c| (srgb_encode(c) * 255.0 + 0.5) as u8)
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
