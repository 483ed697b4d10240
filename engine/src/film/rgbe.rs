//! Radiance HDR (`.hdr`) output, a scan line at a time: the text header,
//! then each row as flat RGBE pixels (three 8-bit mantissas sharing one
//! exponent, Ward's format). Flat rows are never taken for run-length
//! encoded ones by a reader: the largest mantissa of a pixel that is not
//! black is at least 128, so a row never starts with the (1, 1, 1) or
//! (2, 2, < 128) markers. The values are the linear radiance, untouched
//! by the tone map.

use super::encode::{RowCount, RowSink};
use super::output::{ImageError, io_error};
use radiant_core::Rgb;
use std::fs::File;
use std::io::{BufWriter, Write};
use std::path::Path;

/// A linear pixel as RGBE: mantissas of the channels over 2^e, e + 128.
/// Negative and NaN channels become 0; values beyond 2^127 saturate.
#[inline]
pub fn to_rgbe(p: Rgb) -> [u8; 4] {
    let p = p.max(Rgb::ZERO);
    let v = p.max_element();
    // NaN fails the comparison too.
    if v.partial_cmp(&1e-32) != Some(std::cmp::Ordering::Greater) {
        return [0; 4];
    }
    // v = m·2^e with m in [0.5, 1): e is the float's biased exponent − 126.
    let e = (((v.to_bits() >> 23) & 0xff) as i32 - 126).min(127);
    let scale = ((8 - e) as f32).exp2();
    let [r, g, b] = p.to_array().map(|c| (c * scale) as u8);
    [r, g, b, (e + 128) as u8]
}

/// HDR rows: RGBE-encoded a row at a time into the file.
struct HdrRows<'w, W: Write> {
    out: W,
    count: RowCount,
    bytes: Vec<u8>,
    path: &'w Path,
}

impl<W: Write + Send> RowSink for HdrRows<'_, W> {
    fn write_rows(&mut self, rows: &[Rgb]) -> Result<(), ImageError> {
        self.count
            .add(rows.len())
            .map_err(|e| io_error(self.path, e))?;
        for row in rows.chunks_exact(self.count.width.max(1)) {
            self.bytes.clear();
            self.bytes.extend(row.iter().flat_map(|p| to_rgbe(*p)));
            self.out
                .write_all(&self.bytes)
                .map_err(|e| io_error(self.path, e))?;
        }
        Ok(())
    }
}

/// [`super::encode::write_encoded`] for Radiance HDR: `produce` writes
/// into `file` (named `path` in errors) through an [`HdrRows`] sink.
pub(super) fn hdr_rows<T, E: From<ImageError>>(
    file: &mut File,
    path: &Path,
    (width, height): (u32, u32),
    produce: impl FnOnce(&mut dyn RowSink) -> Result<T, E>,
) -> Result<T, E> {
    let mut out = BufWriter::new(file);
    write!(
        out,
        "#?RADIANCE\n# Radiant\nFORMAT=32-bit_rle_rgbe\n\n-Y {height} +X {width}\n"
    )
    .map_err(|e| io_error(path, e))?;
    let mut sink = HdrRows {
        out,
        count: RowCount::new(width, height),
        bytes: Vec::new(),
        path,
    };
    let produced = produce(&mut sink)?;
    sink.count.complete().map_err(|e| io_error(path, e))?;
    sink.out.flush().map_err(|e| io_error(path, e))?;
    Ok(produced)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn rgbe_keeps_eight_significant_bits_of_the_largest_channel() {
        assert_eq!(to_rgbe(Rgb::ZERO), [0; 4]);
        assert_eq!(to_rgbe(Rgb::new(-1.0, f32::NAN, 0.0)), [0; 4]);
        // 1.0 = 0.5·2^1: mantissa 128, exponent 129.
        assert_eq!(to_rgbe(Rgb::new(1.0, 0.5, 0.0)), [128, 64, 0, 129]);
        for v in [1e-20f32, 0.001, 0.37, 1.0, 5.5, 1e4, 3e30] {
            let [r, g, b, e] = to_rgbe(Rgb::new(v, v * 0.5, v * 0.01));
            assert!(r >= 128, "{v}");
            let decode = |m: u8| (m as f64 + 0.5) * 2f64.powi(e as i32 - 136);
            for (m, c) in [(r, v), (g, v * 0.5), (b, v * 0.01)] {
                assert!((decode(m) - c as f64).abs() <= v as f64 / 256.0, "{v}");
            }
        }
        assert_eq!(to_rgbe(Rgb::splat(f32::MAX))[3], 255);
    }
}
