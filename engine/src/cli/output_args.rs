//! Options of `render` that change how the image's values are written: the
//! tone map and exposure of PNG and JPEG output, the PNG bit depth and the
//! EXR sample type (overriding the scene's `film` keys).

use clap::Args;
use radiant::film::encoding::{BitDepth, ExrSamples, OutputOverrides};
use radiant::film::tonemap::Curve;

/// Tone map, exposure, bit depth and EXR sample type overrides.
#[derive(Args)]
pub struct OutputArgs {
    /// Tone curve of PNG and JPEG output: clamp, reinhard, aces or agx
    /// (overrides the scene's `film: {tonemap: {type}}`).
    #[arg(long, value_name = "CURVE")]
    pub tonemap: Option<Curve>,
    /// Exposure of PNG and JPEG output in stops: the image is scaled by
    /// 2^EV before the tone curve (EXR and HDR stay unscaled).
    #[arg(long, value_name = "EV", allow_negative_numbers = true, value_parser = finite)]
    pub exposure: Option<f32>,
    /// Bits per channel of PNG output, 8 or 16.
    #[arg(long, value_parser = bit_depth)]
    pub bit_depth: Option<BitDepth>,
    /// Write EXR output as 16-bit half floats instead of 32-bit floats.
    #[arg(long)]
    pub half: bool,
    /// Add the coverage as alpha to PNG (straight) and EXR (premultiplied)
    /// output: transparent where camera rays hit nothing. Renders the whole
    /// frame on the CPU.
    #[arg(long)]
    pub alpha: bool,
}

/// A finite number.
fn finite(text: &str) -> Result<f32, String> {
    match text.trim().parse::<f32>() {
        Ok(v) if v.is_finite() => Ok(v),
        _ => Err(format!("`{text}` is not a finite number of stops")),
    }
}

/// 8 or 16.
fn bit_depth(text: &str) -> Result<BitDepth, String> {
    let bits: u8 = text
        .trim()
        .parse()
        .map_err(|_| format!("`{text}` is not a bit depth; expected 8 or 16"))?;
    BitDepth::try_from(bits)
}

impl OutputArgs {
    /// The overrides these options ask for.
    pub fn overrides(&self) -> OutputOverrides {
        OutputOverrides {
            tonemap: self.tonemap,
            exposure: self.exposure,
            bit_depth: self.bit_depth,
            exr: self.half.then_some(ExrSamples::Half),
            alpha: self.alpha.then_some(true),
            // `--aov` is the passes' (`render/passes.rs`).
            aovs: None,
        }
    }
}
