//! `radiant compare`: how far an image is from a reference — RMSE,
//! relative MSE, mean ratio and mean FLIP — for any format Radiant writes
//! (EXR, Radiance HDR, PNG 8 or 16 bit, JPEG; PNG and JPEG sRGB-decoded),
//! and optionally a heat map of the per-pixel FLIP error.

use clap::Args;
use image::ImageEncoder;
use radiant::film::Image;
use radiant::film::output::{read, temp_file_beside};
use std::path::{Path, PathBuf};

/// Options of `radiant compare`.
#[derive(Args)]
pub struct CompareArgs {
    /// The image to judge (EXR, HDR, PNG or JPEG).
    image: PathBuf,
    /// The reference (EXR, HDR, PNG or JPEG).
    reference: PathBuf,
    /// Write a heat map of the per-pixel FLIP error to this PNG file
    /// (FLIP's magma colours: black where the images agree, yellow where
    /// they differ most).
    #[arg(long, value_name = "OUT.png")]
    diff: Option<PathBuf>,
}

/// Reads `path`, refusing images with NaN or infinite pixels.
fn read_finite(path: &Path) -> miette::Result<Image> {
    let img = read(path).map_err(|e| miette::miette!("{e}"))?;
    let bad = img.pixels.iter().filter(|p| !p.is_finite()).count();
    if bad > 0 {
        miette::bail!(
            "`{}`: {bad} pixels are NaN or infinite; compare needs finite images",
            path.display()
        );
    }
    Ok(img)
}

/// Compares as the arguments say and prints the metrics.
pub fn run(args: &CompareArgs) -> miette::Result<()> {
    if let Some(diff) = &args.diff {
        let ext = diff.extension().and_then(|e| e.to_str());
        if !ext.is_some_and(|e| e.eq_ignore_ascii_case("png")) {
            miette::bail!(
                "cannot write the difference map `{}`: its name must end in .png",
                diff.display()
            );
        }
    }
    let (a, b) = (read_finite(&args.image)?, read_finite(&args.reference)?);
    let c = radiant::compare::compare(&a, &b).ok_or_else(|| {
        miette::miette!(
            "the images differ in size: `{}` is {}x{} and `{}` is {}x{}",
            args.image.display(),
            a.width,
            a.height,
            args.reference.display(),
            b.width,
            b.height
        )
    })?;
    let mut report = format!("rmse {:.6}\nrelative_mse {:.6}\n", c.rmse, c.relative_mse);
    if c.mean_ratio.is_finite() {
        report += &format!("mean_ratio {:.6}\n", c.mean_ratio);
    } else {
        report += "mean_ratio undefined (the reference's mean is 0)\n";
    }
    let map = radiant::accuracy::metrics::flip_map(&a, &b);
    report += &format!("flip {:.6}\n", radiant::accuracy::metrics::mean_flip(&map));
    // A reader that stops early (`| head -1`) is not an error.
    match std::io::Write::write_all(&mut std::io::stdout().lock(), report.as_bytes()) {
        Err(e) if e.kind() != std::io::ErrorKind::BrokenPipe => {
            miette::bail!("cannot write the comparison to standard output: {e}")
        }
        _ => {}
    }
    if let Some(diff) = &args.diff {
        write_heat_map(diff, &map).map_err(|e| miette::miette!("{e}"))?;
        eprintln!("wrote the FLIP error map to {}", diff.display());
    }
    Ok(())
}

/// Writes FLIP's error map in its magma colours as an 8-bit PNG,
/// atomically.
pub(crate) fn write_heat_map(path: &Path, map: &nv_flip::FlipImageFloat) -> Result<(), String> {
    let colours = map.apply_color_lut(&nv_flip::magma_lut());
    let bytes = colours.to_vec();
    let fail = |e: &dyn std::fmt::Display| format!("cannot write `{}`: {e}", path.display());
    let mut tmp = temp_file_beside(path, ".png").map_err(|e| fail(&e))?;
    {
        let mut out = std::io::BufWriter::new(tmp.as_file_mut());
        image::codecs::png::PngEncoder::new(&mut out)
            .write_image(
                &bytes,
                colours.width(),
                colours.height(),
                image::ExtendedColorType::Rgb8,
            )
            .map_err(|e| fail(&e))?;
        std::io::Write::flush(&mut out).map_err(|e| fail(&e))?;
    }
    tmp.persist(path).map_err(|e| fail(&e.error))?;
    Ok(())
}
