//! Mitsuba's `.vol` grid file, the `grid` medium's format: Mitsuba 3 reads
//! the same files, so one file feeds a scene and its reference render.
//!
//! Layout (little-endian): the bytes `VOL`, version byte 3, encoding
//! `i32` = 1 (32-bit floats), the resolution `i32` x, y, z, the channel
//! count `i32` (1: density), the bounding box as six `f32` (min x, y, z,
//! max x, y, z), then x·y·z·channels `f32` values, x fastest, then y,
//! then z. Voxel values sit at cell centres.

use std::path::Path;

/// Length of the header in bytes.
const HEADER: usize = 48;

/// A density grid read from a `.vol` file.
#[derive(Debug, Clone, PartialEq)]
pub struct VolGrid {
    /// Resolution [x, y, z].
    pub resolution: [usize; 3],
    /// The bounding box written in the file: [min, max].
    pub bounds: [[f32; 3]; 2],
    /// Values, x fastest, then y, then z.
    pub values: Vec<f32>,
}

fn i32_at(bytes: &[u8], at: usize) -> i32 {
    i32::from_le_bytes([bytes[at], bytes[at + 1], bytes[at + 2], bytes[at + 3]])
}

fn f32_at(bytes: &[u8], at: usize) -> f32 {
    f32::from_bits(i32_at(bytes, at) as u32)
}

impl VolGrid {
    /// Reads and checks `path`: the header, the length, and every voxel
    /// finite and ≥ 0. Errors name the file and what is wrong (the voxel's
    /// coordinates for a bad value).
    pub fn read(path: &Path) -> Result<Self, String> {
        let name = path.display();
        radiant_core::input_file::reject_special_file(path)?;
        let bytes = std::fs::read(path).map_err(|e| format!("cannot read `{name}`: {e}"))?;
        Self::parse(&bytes).map_err(|e| format!("`{name}`: {e}"))
    }

    /// Parses the bytes of a `.vol` file (see [`VolGrid::read`]).
    pub fn parse(bytes: &[u8]) -> Result<Self, String> {
        if bytes.len() < HEADER {
            return Err(format!(
                "not a grid file: {} bytes, shorter than the 48-byte `.vol` header",
                bytes.len()
            ));
        }
        if &bytes[..3] != b"VOL" || bytes[3] != 3 {
            return Err("not a Mitsuba `.vol` grid file (expected the bytes `VOL` and version 3 at its start)".into());
        }
        let encoding = i32_at(bytes, 4);
        if encoding != 1 {
            return Err(format!(
                "encoding {encoding} is not supported: only 1 (32-bit floats)"
            ));
        }
        let dims = [i32_at(bytes, 8), i32_at(bytes, 12), i32_at(bytes, 16)];
        if dims.iter().any(|&d| d <= 0) {
            return Err(format!(
                "resolution {dims:?}: every axis needs at least one voxel"
            ));
        }
        let channels = i32_at(bytes, 20);
        if channels != 1 {
            return Err(format!("{channels} channels: a density grid has exactly 1"));
        }
        let resolution = dims.map(|d| d as usize);
        let count = resolution[0]
            .checked_mul(resolution[1])
            .and_then(|n| n.checked_mul(resolution[2]));
        let expected = count
            .and_then(|n| n.checked_mul(4))
            .and_then(|n| n.checked_add(HEADER));
        if expected != Some(bytes.len()) {
            return Err(format!(
                "wrong size: a {}×{}×{} grid of 1 channel takes {} bytes, the file has {}",
                dims[0],
                dims[1],
                dims[2],
                expected.map_or("more than addressable".to_string(), |n| n.to_string()),
                bytes.len()
            ));
        }
        let mut bounds = [[0.0f32; 3]; 2];
        for (k, v) in bounds.iter_mut().flatten().enumerate() {
            *v = f32_at(bytes, 24 + 4 * k);
        }
        let values: Vec<f32> = bytes[HEADER..]
            .chunks_exact(4)
            .map(|c| f32::from_le_bytes([c[0], c[1], c[2], c[3]]))
            .collect();
        if let Some(i) = values.iter().position(|v| !(v.is_finite() && *v >= 0.0)) {
            let (x, y, z) = (
                i % resolution[0],
                i / resolution[0] % resolution[1],
                i / (resolution[0] * resolution[1]),
            );
            return Err(format!(
                "voxel ({x}, {y}, {z}) is {}: densities must be finite and ≥ 0",
                values[i]
            ));
        }
        Ok(Self {
            resolution,
            bounds,
            values,
        })
    }

    /// The file's bytes (for tests and tools that write grids).
    pub fn to_bytes(&self) -> Vec<u8> {
        let mut out = Vec::with_capacity(HEADER + 4 * self.values.len());
        out.extend_from_slice(b"VOL\x03");
        out.extend_from_slice(&1i32.to_le_bytes());
        for d in self.resolution {
            out.extend_from_slice(&(d as i32).to_le_bytes());
        }
        out.extend_from_slice(&1i32.to_le_bytes());
        for v in self.bounds.iter().flatten().chain(&self.values) {
            out.extend_from_slice(&v.to_le_bytes());
        }
        out
    }
}

#[cfg(test)]
mod tests {
    // `unwrap` in this test code is the assertion: the grids are the test's own.
    use super::*;

    fn grid() -> VolGrid {
        VolGrid {
            resolution: [2, 3, 1],
            bounds: [[0.0, -1.0, 0.0], [1.0, 1.0, 0.5]],
            values: vec![0.0, 1.0, 2.0, 3.0, 4.0, 5.0],
        }
    }

    #[test]
    fn round_trips_and_checks_its_input() {
        let g = grid();
        let bytes = g.to_bytes();
        assert_eq!(VolGrid::parse(&bytes).unwrap(), g);
        let short = &bytes[..bytes.len() - 4];
        assert!(VolGrid::parse(short).unwrap_err().contains("wrong size"));
        let mut nan = bytes.clone();
        let at = HEADER + 4 * 3;
        nan[at..at + 4].copy_from_slice(&f32::NAN.to_le_bytes());
        assert!(
            VolGrid::parse(&nan)
                .unwrap_err()
                .contains("voxel (1, 1, 0) is NaN")
        );
        let mut negative = bytes.clone();
        negative[HEADER..HEADER + 4].copy_from_slice(&(-1.0f32).to_le_bytes());
        assert!(
            VolGrid::parse(&negative)
                .unwrap_err()
                .contains("voxel (0, 0, 0) is -1")
        );
        assert!(VolGrid::parse(b"PNG").unwrap_err().contains("48-byte"));
        let mut two = bytes;
        two[20..24].copy_from_slice(&2i32.to_le_bytes());
        assert!(VolGrid::parse(&two).unwrap_err().contains("2 channels"));
    }
}
