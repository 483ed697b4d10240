//! Images with an alpha channel: the developed image and its coverage
//! (the share of each pixel's filtered camera rays that hit a surface,
//! [`super::aov::AovImage::alpha`]) written as RGBA — PNG with straight
//! alpha (the colour divided by the coverage, then tone-mapped and
//! sRGB-encoded like any PNG), EXR with premultiplied alpha (the radiance
//! as rendered and `A`, OpenEXR's convention). Other formats have no alpha
//! channel. Written whole, atomically, like every output.

use super::Image;
use super::encode::Format;
use super::encoding::{BitDepth, Encoding, ExrSamples};
use super::output::{ImageError, io_error, srgb_encode, temp_file_beside};
use exr::prelude::{WritableImage, f16};
use radiant_core::Rgb;
use std::io::{BufWriter, Write};
use std::path::Path;

/// Writes `image` with the coverage `alpha` (one value a pixel) to `path`,
/// a PNG or EXR file.
///
/// # Panics
///
/// If `alpha` does not have one value per pixel of `image`.
pub fn write(
    path: &Path,
    image: &Image,
    alpha: &[f32],
    encoding: &Encoding,
) -> Result<(), ImageError> {
    assert_eq!(alpha.len(), image.pixels.len(), "one alpha per pixel");
    let format = Format::of(path)?;
    let mut tmp = temp_file_beside(path, ".tmp").map_err(|e| io_error(path, e))?;
    {
        let out = BufWriter::new(tmp.as_file_mut());
        match format {
            Format::Png => png(out, image, alpha, encoding),
            Format::Exr => exr(out, image, alpha, encoding.exr),
            Format::Jpeg | Format::Hdr => Err(format!(
                "{format:?} has no alpha channel; write .png or .exr for an image with alpha"
            )),
        }
        .map_err(|e| io_error(path, e))?;
    }
    tmp.as_file().sync_all().map_err(|e| io_error(path, e))?;
    tmp.persist(path).map_err(|e| io_error(path, e.error))?;
    Ok(())
}

/// The colour of a pixel of coverage `a` without it (straight alpha).
fn unpremultiply(p: Rgb, a: f32) -> Rgb {
    if a > 0.0 { p / a } else { p }
}

/// RGBA PNG, 8 or 16 bit: straight alpha, the colour tone-mapped.
fn png(out: impl Write, image: &Image, alpha: &[f32], encoding: &Encoding) -> Result<(), String> {
    let mut encoder = png::Encoder::new(out, image.width, image.height);
    encoder.set_color(png::ColorType::Rgba);
    let t = &encoding.tonemap;
    let mut bytes = Vec::new();
    let pixels = image.pixels.iter().zip(alpha);
    match encoding.bit_depth {
        BitDepth::Eight => {
            encoder.set_depth(png::BitDepth::Eight);
            for (p, &a) in pixels {
                let c = t.map(unpremultiply(*p, a)).to_array();
                let q = |v: f32| (v * 255.0 + 0.5) as u8;
                bytes.extend(c.map(|v| q(srgb_encode(v))));
                bytes.push(q(a.clamp(0.0, 1.0)));
            }
        }
        BitDepth::Sixteen => {
            encoder.set_depth(png::BitDepth::Sixteen);
            for (p, &a) in pixels {
                let c = t.map(unpremultiply(*p, a)).to_array();
                let q = |v: f32| ((v * 65535.0 + 0.5) as u16).to_be_bytes();
                bytes.extend(c.into_iter().flat_map(|v| q(srgb_encode(v))));
                bytes.extend(q(a.clamp(0.0, 1.0)));
            }
        }
    }
    let mut writer = encoder.write_header().map_err(|e| e.to_string())?;
    writer.write_image_data(&bytes).map_err(|e| e.to_string())?;
    writer.finish().map_err(|e| e.to_string())
}

/// RGBA EXR, float or half: the radiance and the coverage as `A`.
fn exr(
    out: impl Write + std::io::Seek,
    image: &Image,
    alpha: &[f32],
    samples: ExrSamples,
) -> Result<(), String> {
    use exr::prelude::{Image as ExrImage, SpecificChannels};
    let size = (image.width as usize, image.height as usize);
    let at = move |pos: exr::math::Vec2<usize>| pos.y() * size.0 + pos.x();
    let pixel = move |i: usize| {
        let p = image.pixels[i];
        (p.x, p.y, p.z, alpha[i])
    };
    let result = match samples {
        ExrSamples::Float => {
            ExrImage::from_channels(size, SpecificChannels::rgba(move |pos| pixel(at(pos))))
                .write()
                .to_buffered(out)
        }
        ExrSamples::Half => ExrImage::from_channels(
            size,
            SpecificChannels::rgba(move |pos| {
                let (r, g, b, a) = pixel(at(pos));
                (
                    f16::from_f32(r),
                    f16::from_f32(g),
                    f16::from_f32(b),
                    f16::from_f32(a),
                )
            }),
        )
        .write()
        .to_buffered(out),
    };
    result.map_err(|e| e.to_string())
}
