//! Image files written row by row: a render hands finished rows, top to
//! bottom, to a [`RowSink`], which encodes them as they come — EXR as ZIP
//! blocks of 16 scan lines (`exr`'s block writer), PNG through `png`'s
//! stream writer, Radiance HDR a scan line at a time ([`super::rgbe`]) —
//! so no whole image need exist in memory. JPEG cannot stream: its rows
//! are kept as 8-bit sRGB (3 bytes a pixel, reserved before any row comes,
//! so a frame too large fails before rendering) and encoded at the end.
//! [`write_encoded`] opens the sink on a temporary file beside the target
//! and renames it into place once every row is written, so an interrupted
//! or failed render leaves no file.

pub use super::encoding::Format;
use super::encoding::{BitDepth, Encoding, ExrSamples};
use super::output::{ImageError, io_error, srgb_encode, temp_file_beside};
use super::tonemap::Tonemap;
use exr::block::UncompressedBlock;
use exr::block::chunk::Chunk;
use exr::block::writer::{ChunkWriter, ChunksWriter};
use exr::meta::header::Header;
use exr::prelude::f16;
use radiant_core::Rgb;
use rayon::prelude::*;
use std::fs::File;
use std::io::{BufWriter, Seek, Write};
use std::path::Path;

/// Scan lines per EXR block (ZIP compression's block height).
pub const BLOCK_ROWS: u32 = 16;

/// Receives an image's rows in order.
pub trait RowSink: Send {
    /// Encodes `rows`: whole rows of pixels, row-major, continuing below
    /// the rows of the last call.
    fn write_rows(&mut self, rows: &[Rgb]) -> Result<(), ImageError>;
}

/// Bytes of a compressor's own state (deflate's window and tables), at
/// most, per thread.
const COMPRESSOR_BYTES: u64 = 1 << 20;

/// Bytes the encoder holds at most for a `width`-pixel image written
/// `rows` rows at a time on `threads` threads: the EXR blocks compressed
/// at once (each raw, in the file's byte order and compressed), the
/// partial block kept between calls and the compressors' state; PNG needs
/// less.
pub fn buffer_bytes(width: u32, rows: u32, threads: usize) -> u64 {
    let block = width as u64 * BLOCK_ROWS as u64 * 12;
    let at_once = (rows.div_ceil(BLOCK_ROWS) as u64 + 1).min(threads.max(1) as u64);
    at_once * (3 * block + COMPRESSOR_BYTES) + block
}

/// [`write_encoded`] with the default [`Encoding`] (clamped 8-bit sRGB,
/// float EXR).
pub fn write_with<T, E: From<ImageError>>(
    path: &Path,
    width: u32,
    height: u32,
    produce: impl FnOnce(&mut dyn RowSink) -> Result<T, E>,
) -> Result<T, E> {
    write_encoded(path, &Encoding::default(), width, height, produce)
}

/// Writes a `width`×`height` image to `path` (the format chosen by its
/// extension, its values as `encoding` says): `produce` hands every row,
/// top to bottom, to the sink it is given. The file appears, renamed from
/// a temporary file beside it, only once `produce` has succeeded and every
/// row is written; on any error there is none, and `produce`'s own error
/// comes back as it was.
pub fn write_encoded<T, E: From<ImageError>>(
    path: &Path,
    encoding: &Encoding,
    width: u32,
    height: u32,
    produce: impl FnOnce(&mut dyn RowSink) -> Result<T, E>,
) -> Result<T, E> {
    let format = Format::of(path)?;
    let mut tmp = temp_file_beside(path, ".tmp").map_err(|e| io_error(path, e))?;
    let file = tmp.as_file_mut();
    let size = (width, height);
    let produced = match format {
        Format::Png => png_rows(file, path, encoding, size, produce),
        Format::Jpeg => jpeg_whole(file, path, encoding, size, produce),
        Format::Exr => exr_rows(file, path, encoding.exr, size, produce),
        Format::Hdr => super::rgbe::hdr_rows(file, path, size, produce),
    }?;
    tmp.as_file().sync_all().map_err(|e| io_error(path, e))?;
    tmp.persist(path).map_err(|e| io_error(path, e.error))?;
    Ok(produced)
}

/// Counts rows against the image's height.
pub(super) struct RowCount {
    pub(super) width: usize,
    height: usize,
    written: usize,
}

impl RowCount {
    /// No rows yet of a `width`×`height` image.
    pub(super) fn new(width: u32, height: u32) -> Self {
        Self {
            width: width as usize,
            height: height as usize,
            written: 0,
        }
    }

    /// Counts `pixels` as rows, or says why they do not continue the image.
    pub(super) fn add(&mut self, pixels: usize) -> Result<usize, String> {
        let rows = pixels / self.width.max(1);
        if rows * self.width != pixels || self.written + rows > self.height {
            return Err(format!(
                "{pixels} pixels do not continue a {}×{} image at row {}",
                self.width, self.height, self.written
            ));
        }
        self.written += rows;
        Ok(rows)
    }

    /// An error unless every row was written.
    pub(super) fn complete(&self) -> Result<(), String> {
        if self.written == self.height {
            Ok(())
        } else {
            Err(format!(
                "only {} of {} rows were written",
                self.written, self.height
            ))
        }
    }
}

/// A pixel as 8-bit output shows it: tone-mapped, sRGB-encoded.
#[inline]
pub fn display8(tonemap: &Tonemap, p: Rgb) -> [u8; 3] {
    tonemap
        .map(p)
        .to_array()
        .map(|c| (srgb_encode(c) * 255.0 + 0.5) as u8)
}

/// A pixel as 16-bit output shows it: tone-mapped, sRGB-encoded.
#[inline]
pub fn display16(tonemap: &Tonemap, p: Rgb) -> [u16; 3] {
    tonemap
        .map(p)
        .to_array()
        .map(|c| (srgb_encode(c) * 65535.0 + 0.5) as u16)
}

/// PNG rows: tone-mapped and sRGB-encoded into one row of bytes at a time
/// (16-bit samples big-endian, as PNG stores them) and streamed to the
/// deflate encoder.
struct PngRows<'w, W: Write> {
    stream: png::StreamWriter<'w, W>,
    count: RowCount,
    bytes: Vec<u8>,
    path: &'w Path,
    tonemap: Tonemap,
    depth: BitDepth,
}

impl<W: Write + Send> RowSink for PngRows<'_, W> {
    fn write_rows(&mut self, rows: &[Rgb]) -> Result<(), ImageError> {
        self.count
            .add(rows.len())
            .map_err(|e| io_error(self.path, e))?;
        let t = &self.tonemap;
        for row in rows.chunks_exact(self.count.width.max(1)) {
            self.bytes.clear();
            match self.depth {
                BitDepth::Eight => self.bytes.extend(row.iter().flat_map(|p| display8(t, *p))),
                BitDepth::Sixteen => self.bytes.extend(
                    row.iter()
                        .flat_map(|p| display16(t, *p))
                        .flat_map(u16::to_be_bytes),
                ),
            }
            self.stream
                .write_all(&self.bytes)
                .map_err(|e| io_error(self.path, e))?;
        }
        Ok(())
    }
}

/// [`write_with`] for PNG: `produce` writes into `file` (named `path` in
/// errors) through a [`PngRows`] sink.
fn png_rows<T, E: From<ImageError>>(
    file: &mut File,
    path: &Path,
    encoding: &Encoding,
    (width, height): (u32, u32),
    produce: impl FnOnce(&mut dyn RowSink) -> Result<T, E>,
) -> Result<T, E> {
    let mut encoder = png::Encoder::new(BufWriter::new(file), width, height);
    encoder.set_color(png::ColorType::Rgb);
    encoder.set_depth(match encoding.bit_depth {
        BitDepth::Eight => png::BitDepth::Eight,
        BitDepth::Sixteen => png::BitDepth::Sixteen,
    });
    let mut writer = encoder.write_header().map_err(|e| io_error(path, e))?;
    let produced = {
        let mut sink = PngRows {
            stream: writer.stream_writer().map_err(|e| io_error(path, e))?,
            count: RowCount::new(width, height),
            bytes: Vec::new(),
            path,
            tonemap: encoding.tonemap,
            depth: encoding.bit_depth,
        };
        let produced = produce(&mut sink)?;
        let PngRows { stream, count, .. } = sink;
        count.complete().map_err(|e| io_error(path, e))?;
        stream.finish().map_err(|e| io_error(path, e))?;
        produced
    };
    writer.finish().map_err(|e| io_error(path, e))?;
    Ok(produced)
}

/// EXR rows: gathered into blocks of [`BLOCK_ROWS`] scan lines, the
/// complete blocks of each call compressed in parallel (a few at a time)
/// and written in order; a partial block waits for the next call.
struct ExrRows<'w, W> {
    writer: &'w mut ChunkWriter<W>,
    path: &'w Path,
    header: &'w [Header],
    samples: ExrSamples,
    count: RowCount,
    /// Rows of the block being gathered.
    partial: Vec<Rgb>,
}

impl<W: Write + Seek + Send> ExrRows<'_, W> {
    /// Compresses and writes the blocks of `rows` (whole blocks, or the
    /// image's last one), the first starting at image row `first`.
    fn write_blocks(&mut self, first: usize, rows: &[Rgb]) -> exr::error::UnitResult {
        let width = self.count.width.max(1);
        let block = BLOCK_ROWS as usize * width;
        let batch = block * rayon::current_num_threads().max(1);
        let (header, samples) = (self.header, self.samples);
        for (b, batch_rows) in rows.chunks(batch).enumerate() {
            let first = first + b * batch / width;
            let chunks: Vec<(usize, Chunk)> = batch_rows
                .par_chunks(block)
                .enumerate()
                .map(|(i, pixels)| {
                    let y = first + i * BLOCK_ROWS as usize;
                    let chunk = exr_block(width, y, pixels, samples).compress_to_chunk(header)?;
                    Ok((y / BLOCK_ROWS as usize, chunk))
                })
                .collect::<exr::error::Result<_>>()?;
            for (index, chunk) in chunks {
                self.writer.write_chunk(index, chunk)?;
            }
        }
        Ok(())
    }

    /// Writes the complete blocks that `rows` (already counted) finish or
    /// hold, keeping the rest for the next call.
    fn write_rows_exr(&mut self, mut rows: &[Rgb]) -> exr::error::UnitResult {
        let width = self.count.width.max(1);
        let block = BLOCK_ROWS as usize * width;
        let before = self.count.written - rows.len() / width;
        let mut start = before - self.partial.len() / width;
        if !self.partial.is_empty() {
            let take = (block - self.partial.len()).min(rows.len());
            self.partial.extend_from_slice(&rows[..take]);
            rows = &rows[take..];
            if self.partial.len() == block || self.count.written == self.count.height {
                let partial = std::mem::take(&mut self.partial);
                self.write_blocks(start, &partial)?;
                self.partial = partial;
                self.partial.clear();
                start += block / width;
            }
        }
        let whole = if self.count.written == self.count.height {
            rows.len()
        } else {
            rows.len() / block * block
        };
        self.write_blocks(start, &rows[..whole])?;
        self.partial.extend_from_slice(&rows[whole..]);
        Ok(())
    }
}

impl<W: Write + Seek + Send> RowSink for ExrRows<'_, W> {
    fn write_rows(&mut self, rows: &[Rgb]) -> Result<(), ImageError> {
        self.count
            .add(rows.len())
            .map_err(|e| io_error(self.path, e))?;
        self.write_rows_exr(rows)
            .map_err(|e| io_error(self.path, e))
    }
}

/// The uncompressed block of image rows `y..` (`pixels`, row-major): per
/// scan line, the B, G and R samples (the file's alphabetical channel
/// order) as native-endian f32 or f16.
fn exr_block(width: usize, y: usize, pixels: &[Rgb], samples: ExrSamples) -> UncompressedBlock {
    let rows = pixels.len() / width;
    let mut data = Vec::with_capacity(pixels.len() * 12);
    for row in pixels.chunks_exact(width) {
        for channel in [2, 1, 0] {
            match samples {
                ExrSamples::Float => data.extend(row.iter().flat_map(|p| p[channel].to_ne_bytes())),
                ExrSamples::Half => data.extend(
                    row.iter()
                        .flat_map(|p| f16::from_f32(p[channel]).to_ne_bytes()),
                ),
            }
        }
    }
    UncompressedBlock {
        index: exr::block::BlockIndex {
            layer: 0,
            pixel_position: exr::math::Vec2(0, y),
            pixel_size: exr::math::Vec2(width, rows),
            level: exr::math::Vec2(0, 0),
        },
        data,
    }
}

/// The header of a linear float or half RGB layer named `rgb`,
/// ZIP-compressed in blocks of 16 scan lines, top to bottom.
fn exr_header(width: u32, height: u32, samples: ExrSamples) -> Header {
    use exr::meta::attribute::{ChannelDescription, LineOrder, SampleType};
    let sample_type = match samples {
        ExrSamples::Float => SampleType::F32,
        ExrSamples::Half => SampleType::F16,
    };
    let channels = ["B", "G", "R"]
        .into_iter()
        .map(|name| ChannelDescription::named(name, sample_type))
        .collect();
    Header::new(
        exr::meta::attribute::Text::from("rgb"),
        (width as usize, height as usize),
        channels,
    )
    .with_encoding(
        exr::compression::Compression::ZIP16,
        exr::meta::BlockDescription::ScanLines,
        LineOrder::Increasing,
    )
}

/// [`write_with`] for EXR: `produce` runs inside `exr`'s block writer
/// (which writes the header first and the offset table last) with an
/// [`ExrRows`] sink; its own error aborts the file and is returned as is.
fn exr_rows<T, E: From<ImageError>>(
    file: &mut File,
    path: &Path,
    samples: ExrSamples,
    (width, height): (u32, u32),
    produce: impl FnOnce(&mut dyn RowSink) -> Result<T, E>,
) -> Result<T, E> {
    let mut produced = None;
    let headers = vec![exr_header(width, height, samples)].into();
    let written = exr::block::write(BufWriter::new(file), headers, true, |meta, writer| {
        let mut sink = ExrRows {
            writer,
            path,
            header: &meta.headers,
            samples,
            count: RowCount::new(width, height),
            partial: Vec::new(),
        };
        let result = produce(&mut sink);
        let complete = sink.count.complete();
        let ok = result.is_ok();
        produced = Some(result);
        match (ok, complete) {
            (false, _) => Err(exr::error::Error::Aborted),
            (true, Err(e)) => Err(exr::error::Error::Invalid(e.into())),
            (true, Ok(())) => Ok(()),
        }
    });
    match (produced, written) {
        (Some(Err(e)), _) => Err(e),
        (_, Err(e)) => Err(io_error(path, e).into()),
        (Some(Ok(t)), Ok(())) => Ok(t),
        (None, Ok(())) => Err(io_error(path, "the image was not written").into()),
    }
}

/// JPEG rows: tone-mapped 8-bit sRGB kept in memory (reserved whole when
/// the sink opens), encoded once the last row is in.
struct JpegRows<'w> {
    bytes: Vec<u8>,
    count: RowCount,
    path: &'w Path,
    tonemap: Tonemap,
}

impl RowSink for JpegRows<'_> {
    fn write_rows(&mut self, rows: &[Rgb]) -> Result<(), ImageError> {
        self.count
            .add(rows.len())
            .map_err(|e| io_error(self.path, e))?;
        let t = &self.tonemap;
        self.bytes.extend(rows.iter().flat_map(|p| display8(t, *p)));
        Ok(())
    }
}

/// [`write_encoded`] for JPEG: the whole image's 8-bit pixels are reserved
/// first (failing, before `produce` renders anything, where they do not
/// fit), gathered through a [`JpegRows`] sink and encoded at the end.
fn jpeg_whole<T, E: From<ImageError>>(
    file: &mut File,
    path: &Path,
    encoding: &Encoding,
    (width, height): (u32, u32),
    produce: impl FnOnce(&mut dyn RowSink) -> Result<T, E>,
) -> Result<T, E> {
    let need = 3 * width as usize * height as usize;
    let mut bytes = Vec::new();
    if bytes.try_reserve_exact(need).is_err() {
        return Err(io_error(
            path,
            format!(
                "a {width}×{height} JPEG is encoded whole and needs {:.1} GB of memory for \
                 its pixels, which cannot be had; write .png, .exr or .hdr, which are \
                 written row by row",
                need as f64 / 1e9
            ),
        )
        .into());
    }
    let mut sink = JpegRows {
        bytes,
        count: RowCount::new(width, height),
        path,
        tonemap: encoding.tonemap,
    };
    let produced = produce(&mut sink)?;
    sink.count.complete().map_err(|e| io_error(path, e))?;
    let mut out = BufWriter::new(file);
    image::codecs::jpeg::JpegEncoder::new_with_quality(&mut out, encoding.jpeg_quality)
        .encode(&sink.bytes, width, height, image::ExtendedColorType::Rgb8)
        .map_err(|e| io_error(path, e))?;
    out.flush().map_err(|e| io_error(path, e))?;
    Ok(produced)
}
