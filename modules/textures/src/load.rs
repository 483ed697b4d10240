//! Reading image files into linear RGB texels.
//!
//! EXR files are read with the `exr` crate, PNG, JPEG and Radiance HDR with
//! `image`. Float formats (EXR, HDR) hold linear values and are used as
//! they are; integer formats (8- and 16-bit PNG, JPEG) are normalised to
//! [0, 1] and, unless the texture is `raw` data (normal, roughness or mask
//! maps), decoded from sRGB. Alpha is ignored; grey images fill all three
//! channels.

use crate::srgb::srgb_to_linear;
use radiant_core::Rgb;
use std::path::{Path, PathBuf};

/// Why an image could not be read.
#[derive(Debug, thiserror::Error)]
pub enum LoadError {
    /// The file could not be opened or decoded.
    #[error("cannot read image `{path}`: {message}")]
    Read {
        /// The file.
        path: PathBuf,
        /// What went wrong.
        message: String,
    },
    /// The file holds no pixels.
    #[error("image `{0}` has no pixels")]
    Empty(PathBuf),
    /// Some texels are NaN or infinite (float formats only).
    #[error(
        "image `{path}` has {count} NaN or infinite texels (the first at column {x}, row {y} \
         from the top); a texture must hold finite values"
    )]
    NonFinite {
        /// The file.
        path: PathBuf,
        /// How many texels are not finite.
        count: usize,
        /// Column of the first one.
        x: u32,
        /// Row of the first one, from the top.
        y: u32,
    },
}

/// Linear RGB texels, row-major, top row first.
#[derive(Debug, Clone, PartialEq)]
pub struct Texels {
    /// Width in texels.
    pub width: u32,
    /// Height in texels.
    pub height: u32,
    /// The texels.
    pub data: Vec<Rgb>,
}

/// Reads `path` into linear texels; `raw` skips the sRGB decoding of
/// integer formats.
pub fn load(path: &Path, raw: bool) -> Result<Texels, LoadError> {
    let is_exr = path
        .extension()
        .is_some_and(|e| e.eq_ignore_ascii_case("exr"));
    let texels = if is_exr {
        load_exr(path)?
    } else {
        load_image(path, raw)?
    };
    usable(texels, path)
}

/// Decodes a PNG or JPEG image held in memory (an image embedded in a
/// glTF file, say) as [`load`] reads a file; `origin` names it in errors.
pub fn load_bytes(bytes: &[u8], origin: &Path, raw: bool) -> Result<Texels, LoadError> {
    let reader = || {
        image::ImageReader::new(std::io::Cursor::new(bytes))
            .with_guessed_format()
            .map_err(|e| read_error(origin, e))
    };
    usable(decode(origin, raw, reader)?, origin)
}

/// `texels` if they hold pixels and all of them are finite.
fn usable(texels: Texels, path: &Path) -> Result<Texels, LoadError> {
    if texels.width == 0 || texels.height == 0 {
        return Err(LoadError::Empty(path.to_path_buf()));
    }
    if let Some(first) = texels.data.iter().position(|t| !t.is_finite()) {
        return Err(LoadError::NonFinite {
            path: path.to_path_buf(),
            count: texels.data.iter().filter(|t| !t.is_finite()).count(),
            x: first as u32 % texels.width,
            y: first as u32 / texels.width,
        });
    }
    Ok(texels)
}

fn read_error(path: &Path, e: impl std::fmt::Display) -> LoadError {
    LoadError::Read {
        path: path.to_path_buf(),
        message: e.to_string(),
    }
}

fn load_exr(path: &Path) -> Result<Texels, LoadError> {
    let (data, size) =
        radiant_core::exr_file::read_exr_rgb(path).map_err(|e| read_error(path, e))?;
    Ok(Texels {
        width: size.x,
        height: size.y,
        data,
    })
}

/// Bytes per texel that decoding an integer or float image takes at most:
/// the decoded RGBA floats, their RGB float copy and the texels.
const DECODE_BYTES: u64 = 16 + 12 + 12;

/// Reads a PNG, JPEG or Radiance HDR file (its format told by its
/// content) into linear texels; `raw` skips the sRGB decoding of integer
/// formats. [`load`] reads textures through it, and `radiant compare`
/// the images it is given.
pub fn load_image(path: &Path, raw: bool) -> Result<Texels, LoadError> {
    radiant_core::input_file::reject_special_file(path).map_err(|e| read_error(path, e))?;
    let reader = || {
        image::ImageReader::open(path)
            .map_err(|e| read_error(path, e))?
            .with_guessed_format()
            .map_err(|e| read_error(path, e))
    };
    decode(path, raw, reader)
}

/// The linear value of each 8-bit sRGB channel value: what
/// [`srgb_to_linear`] gives for the value as `image` converts it to a
/// float (`v / 255`).
fn srgb_8_bit() -> [f32; 256] {
    std::array::from_fn(|v| srgb_to_linear(v as f32 / 255.0))
}

/// Decodes the image that `reader` opens (twice: once for its size, which
/// is checked against the memory left, then for its pixels); `path` names
/// it in errors.
fn decode<R: std::io::BufRead + std::io::Seek>(
    path: &Path,
    raw: bool,
    reader: impl Fn() -> Result<image::ImageReader<R>, LoadError>,
) -> Result<Texels, LoadError> {
    let (width, height) = reader()?
        .into_dimensions()
        .map_err(|e| read_error(path, e))?;
    radiant_core::memory::check(width as u64 * height as u64 * DECODE_BYTES, || {
        format!("decoding its {width}×{height} pixels")
    })
    .map_err(|e| read_error(path, e))?;
    let decoded = reader()?.decode().map_err(|e| read_error(path, e))?;
    let is_float = matches!(
        decoded.color(),
        image::ColorType::Rgb32F | image::ColorType::Rgba32F
    );
    let eight_bit = matches!(
        decoded.color(),
        image::ColorType::L8
            | image::ColorType::La8
            | image::ColorType::Rgb8
            | image::ColorType::Rgba8
    );
    if eight_bit && !raw {
        // 256 values a channel: decoded once each, not once per texel.
        let table = srgb_8_bit();
        return Ok(texels(&decoded.to_rgb8(), |v| table[v as usize]));
    }
    let linear = is_float || raw;
    Ok(texels(&decoded.to_rgb32f(), |c| {
        if linear { c } else { srgb_to_linear(c) }
    }))
}

/// The texels of `rgb`, each channel through `channel`.
fn texels<P: image::Primitive>(
    rgb: &image::ImageBuffer<image::Rgb<P>, Vec<P>>,
    channel: impl Fn(P) -> f32,
) -> Texels
where
    image::Rgb<P>: image::Pixel<Subpixel = P>,
{
    Texels {
        width: rgb.width(),
        height: rgb.height(),
        data: rgb
            .pixels()
            .map(|p| Rgb::new(channel(p[0]), channel(p[1]), channel(p[2])))
            .collect(),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_8_bit_table_decodes_as_the_float_path_does() {
        // Every value as `image` turns it into a float, then decoded: the
        // table must give the same bits (an 8-bit texture then reads the
        // same texels as before the table).
        let bytes: Vec<u8> = (0..=255u8).flat_map(|v| [v, v, v]).collect();
        let image = image::RgbImage::from_raw(256, 1, bytes).expect("256 pixels");
        let floats = image::DynamicImage::ImageRgb8(image).to_rgb32f();
        let table = srgb_8_bit();
        for (v, p) in floats.pixels().enumerate() {
            assert_eq!(
                table[v].to_bits(),
                srgb_to_linear(p[0]).to_bits(),
                "value {v}"
            );
        }
    }
}
