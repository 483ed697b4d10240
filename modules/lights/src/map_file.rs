//! Reading environment maps: OpenEXR (through the `exr` crate, any
//! channel type, first RGB(A) layer) and Radiance HDR (through `image`),
//! as linear RGB pixels, row-major from the top row.

use radiant_core::Rgb;
use radiant_core::glam::UVec2;
use std::path::Path;

/// Reads the map at `path`; errors name the file and say what is accepted.
pub(crate) fn load_map(path: &Path) -> Result<(Vec<Rgb>, UVec2), String> {
    radiant_core::input_file::reject_special_file(path)
        .map_err(|e| format!("cannot read the environment map: {e}"))?;
    let ext = path
        .extension()
        .and_then(|e| e.to_str())
        .map(str::to_ascii_lowercase);
    match ext.as_deref() {
        Some("exr") => read_exr(path),
        Some("hdr") => read_hdr(path),
        _ => Err(format!(
            "cannot read the environment map `{}`: the file name must end in .exr or .hdr",
            path.display()
        )),
    }
    .map_err(|e| {
        if e.starts_with("cannot read") {
            e
        } else {
            format!("cannot read the environment map `{}`: {e}", path.display())
        }
    })
}

fn read_exr(path: &Path) -> Result<(Vec<Rgb>, UVec2), String> {
    radiant_core::exr_file::read_exr_rgb(path).map_err(|e| e.to_string())
}

fn read_hdr(path: &Path) -> Result<(Vec<Rgb>, UVec2), String> {
    let file = std::fs::File::open(path).map_err(|e| e.to_string())?;
    let decoder = image::codecs::hdr::HdrDecoder::new(std::io::BufReader::new(file))
        .map_err(|e| e.to_string())?;
    let image = image::DynamicImage::from_decoder(decoder).map_err(|e| e.to_string())?;
    let rgb = image.to_rgb32f();
    let size = UVec2::new(rgb.width(), rgb.height());
    let pixels = rgb.pixels().map(|p| Rgb::from_array(p.0)).collect();
    Ok((pixels, size))
}

#[cfg(test)]
mod tests {
    // `unwrap` in this test code is the assertion: the inputs are the test's
    // own, so a failure is a bug, and the panic reports it with the error.
    use super::*;

    #[test]
    fn unsupported_and_missing_files_are_errors_naming_the_file() {
        let e = load_map(Path::new("sky.png")).unwrap_err();
        assert!(e.contains("sky.png") && e.contains(".exr or .hdr"), "{e}");
        let e = load_map(Path::new("/nonexistent/sky.exr")).unwrap_err();
        assert!(e.contains("/nonexistent/sky.exr"), "{e}");
        let e = load_map(Path::new("/nonexistent/sky.hdr")).unwrap_err();
        assert!(e.contains("/nonexistent/sky.hdr"), "{e}");
    }

    #[test]
    fn reads_radiance_hdr() {
        // A 2 × 1 RGBE file: (1, 0.5, 0.25) and (4, 4, 4).
        let mut bytes = b"#?RADIANCE\nFORMAT=32-bit_rle_rgbe\n\n-Y 1 +X 2\n".to_vec();
        bytes.extend_from_slice(&[128, 64, 32, 129, 128, 128, 128, 131]);
        let dir = std::env::temp_dir().join(format!("radiant-hdr-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let path = dir.join("t.hdr");
        std::fs::write(&path, bytes).unwrap();
        let (pixels, size) = load_map(&path).unwrap();
        std::fs::remove_dir_all(&dir).unwrap();
        assert_eq!(size, UVec2::new(2, 1));
        assert_eq!(pixels, vec![Rgb::new(1.0, 0.5, 0.25), Rgb::splat(4.0)]);
    }
}
