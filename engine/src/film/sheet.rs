//! Showing a rendered sequence: its frames laid out as a contact sheet
//! (PNG) or played as an animated GIF, written atomically like every other
//! output.

use super::output::{ImageError, read_exr, temp_file_beside, to_srgb8};
use image::codecs::gif::{GifEncoder, Repeat};
use image::{Delay, Frame, RgbImage, RgbaImage};
use std::io::BufWriter;
use std::path::Path;

/// Pixels between the frames of a contact sheet.
const GAP: u32 = 2;

/// A frame read back for a sheet: 8-bit sRGB, as PNG output shows it.
fn read_frame(path: &Path) -> Result<RgbImage, ImageError> {
    let err = |e: &dyn std::fmt::Display| ImageError::Io {
        path: path.display().to_string(),
        message: e.to_string(),
    };
    radiant_core::input_file::reject_special_file(path).map_err(|e| err(&e))?;
    let is_exr = path
        .extension()
        .is_some_and(|e| e.eq_ignore_ascii_case("exr"));
    if is_exr {
        let image = read_exr(path)?;
        return RgbImage::from_raw(image.width, image.height, to_srgb8(&image))
            .ok_or_else(|| err(&"the image's size does not match its pixels"));
    }
    image::open(path).map(|i| i.to_rgb8()).map_err(|e| err(&e))
}

/// Reads the frames `paths`, all of one size.
fn read_frames(paths: &[impl AsRef<Path>]) -> Result<Vec<RgbImage>, ImageError> {
    let mut frames: Vec<RgbImage> = Vec::with_capacity(paths.len());
    for path in paths {
        let path = path.as_ref();
        let frame = read_frame(path)?;
        if let Some(first) = frames.first()
            && first.dimensions() != frame.dimensions()
        {
            return Err(ImageError::Io {
                path: path.display().to_string(),
                message: format!(
                    "the frame is {}x{}, the first frame {}x{}: a sheet needs frames of one size",
                    frame.width(),
                    frame.height(),
                    first.width(),
                    first.height()
                ),
            });
        }
        frames.push(frame);
    }
    Ok(frames)
}

/// Lays `frames` out left to right, top to bottom, `columns` to a row,
/// `GAP` pixels apart on black.
pub fn contact_sheet(frames: &[RgbImage], columns: u32) -> RgbImage {
    let Some(first) = frames.first() else {
        return RgbImage::new(1, 1);
    };
    let (w, h) = first.dimensions();
    let columns = columns.clamp(1, frames.len() as u32);
    let rows = (frames.len() as u32).div_ceil(columns);
    let mut sheet = RgbImage::new(
        columns * w + (columns - 1) * GAP,
        rows * h + (rows - 1) * GAP,
    );
    for (i, frame) in frames.iter().enumerate() {
        let (col, row) = (i as u32 % columns, i as u32 / columns);
        image::imageops::replace(
            &mut sheet,
            frame,
            i64::from(col * (w + GAP)),
            i64::from(row * (h + GAP)),
        );
    }
    sheet
}

/// Writes the frames `paths` (PNG or EXR renders of one size) to `out`: a
/// contact sheet of `columns` frames to a row for `.png`, an animated GIF
/// at `fps` frames per second, looping, for `.gif`.
pub fn write_sheet(
    paths: &[impl AsRef<Path>],
    out: &Path,
    columns: u32,
    fps: f64,
) -> Result<(), ImageError> {
    let io = |e: &dyn std::fmt::Display| ImageError::Io {
        path: out.display().to_string(),
        message: e.to_string(),
    };
    let ext = out
        .extension()
        .and_then(|e| e.to_str())
        .map(str::to_ascii_lowercase);
    let gif = match ext.as_deref() {
        Some("png") => false,
        Some("gif") => true,
        _ => {
            return Err(io(
                &"the sheet's name must end in .png (a contact sheet) or .gif (an animation)",
            ));
        }
    };
    let frames = read_frames(paths)?;
    let mut tmp = temp_file_beside(out, ".tmp").map_err(|e| io(&e))?;
    if gif {
        let delay = Delay::from_saturating_duration(std::time::Duration::from_secs_f64(1.0 / fps));
        let mut encoder = GifEncoder::new_with_speed(BufWriter::new(tmp.as_file_mut()), 10);
        encoder.set_repeat(Repeat::Infinite).map_err(|e| io(&e))?;
        for frame in frames {
            let rgba: RgbaImage = image::DynamicImage::ImageRgb8(frame).to_rgba8();
            encoder
                .encode_frame(Frame::from_parts(rgba, 0, 0, delay))
                .map_err(|e| io(&e))?;
        }
    } else {
        contact_sheet(&frames, columns)
            .write_to(
                &mut BufWriter::new(tmp.as_file_mut()),
                image::ImageFormat::Png,
            )
            .map_err(|e| io(&e))?;
    }
    tmp.as_file().sync_all().map_err(|e| io(&e))?;
    tmp.persist(out).map_err(|e| io(&e.error))?;
    Ok(())
}

#[cfg(test)]
mod tests {
    // `unwrap` in this test code is the assertion: the inputs are the test's
    // own, so a failure is a bug, and the panic reports it with the error.
    use super::*;

    fn solid(value: u8) -> RgbImage {
        RgbImage::from_pixel(3, 2, image::Rgb([value, 0, 255 - value]))
    }

    #[test]
    fn frames_are_laid_out_in_rows() {
        let frames: Vec<RgbImage> = (0..5).map(|i| solid(i * 50)).collect();
        let sheet = contact_sheet(&frames, 2);
        assert_eq!(sheet.dimensions(), (2 * 3 + GAP, 3 * 2 + 2 * GAP));
        // Frame 3 is in row 1, column 1.
        assert_eq!(sheet.get_pixel(3 + GAP, 2 + GAP).0, [150, 0, 105]);
        // The gap and the empty last cell stay black.
        assert_eq!(sheet.get_pixel(3, 0).0, [0, 0, 0]);
        assert_eq!(sheet.get_pixel(3 + GAP + 1, 2 * (2 + GAP) + 1).0, [0, 0, 0]);
    }

    #[test]
    fn sheets_and_animations_are_written_and_mismatched_frames_refused() {
        let dir = tempfile::tempdir().unwrap();
        let paths: Vec<_> = (0..3)
            .map(|i| {
                let p = dir.path().join(format!("f{i}.png"));
                solid(i * 100).save(&p).unwrap();
                p
            })
            .collect();
        let png = dir.path().join("sheet.png");
        write_sheet(&paths, &png, 3, 24.0).unwrap();
        assert_eq!(image::open(&png).unwrap().width(), 3 * 3 + 2 * GAP);
        let gif = dir.path().join("anim.gif");
        write_sheet(&paths, &gif, 3, 12.0).unwrap();
        let decoder = image::codecs::gif::GifDecoder::new(std::io::BufReader::new(
            std::fs::File::open(&gif).unwrap(),
        ))
        .unwrap();
        use image::AnimationDecoder;
        assert_eq!(decoder.into_frames().count(), 3);
        let odd = dir.path().join("odd.png");
        RgbImage::new(4, 4).save(&odd).unwrap();
        let err = write_sheet(&[&paths[0], &odd], &png, 2, 24.0).unwrap_err();
        assert!(err.to_string().contains("one size"), "{err}");
        assert!(write_sheet(&paths, &dir.path().join("x.bmp"), 2, 24.0).is_err());
    }
}
