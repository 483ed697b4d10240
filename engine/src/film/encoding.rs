//! What an output file holds: the [`Format`] its extension names, and the
//! [`Encoding`] settings of the scene's `film` (tone map, PNG bit depth,
//! EXR sample type, JPEG quality) with their command-line
//! [`OutputOverrides`]. The encoders of [`super::encode`] read them; the
//! render settings carry them from the scene file to the backend's write.
//!
//! | extension | values | bits | rows streamed |
//! |---|---|---|---|
//! | `.png` | tone-mapped sRGB | 8 or 16 (`bit_depth`) | yes |
//! | `.jpg`, `.jpeg` | tone-mapped sRGB | 8 | no: encoded whole |
//! | `.exr` | linear radiance | 32-bit float or 16-bit half (`exr`) | yes |
//! | `.hdr` | linear radiance | shared-exponent RGBE | yes |

use super::output::ImageError;
use super::tonemap::{BadExposure, Curve, Tonemap};
use serde::Deserialize;
use std::path::Path;

/// The image formats, by file extension.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Format {
    /// Tone-mapped sRGB, 8 or 16 bits per channel.
    Png,
    /// Tone-mapped sRGB, 8 bits per channel, lossy.
    Jpeg,
    /// Linear float or half RGB.
    Exr,
    /// Radiance RGBE: linear, 8-bit mantissas with a shared exponent.
    Hdr,
}

impl Format {
    /// The extensions Radiant writes, for messages.
    pub const EXTENSIONS: &str = ".png, .jpg, .jpeg, .exr or .hdr";

    /// The format `path`'s extension names.
    pub fn of(path: &Path) -> Result<Self, ImageError> {
        let ext = path
            .extension()
            .and_then(|e| e.to_str())
            .map(str::to_ascii_lowercase);
        match ext.as_deref() {
            Some("png") => Ok(Self::Png),
            Some("jpg" | "jpeg") => Ok(Self::Jpeg),
            Some("exr") => Ok(Self::Exr),
            Some("hdr") => Ok(Self::Hdr),
            _ => Err(ImageError::UnknownFormat(path.display().to_string())),
        }
    }

    /// Whether rows go to the file as they come (JPEG's encoder needs the
    /// whole image).
    pub fn streams(self) -> bool {
        self != Self::Jpeg
    }
}

/// Bits per channel of PNG output (`film: {bit_depth: 8 | 16}`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Deserialize)]
#[serde(try_from = "u8")]
pub enum BitDepth {
    /// 8 bits per channel.
    #[default]
    Eight,
    /// 16 bits per channel.
    Sixteen,
}

impl TryFrom<u8> for BitDepth {
    type Error = String;

    fn try_from(bits: u8) -> Result<Self, String> {
        match bits {
            8 => Ok(Self::Eight),
            16 => Ok(Self::Sixteen),
            _ => Err(format!("the bit depth must be 8 or 16, found {bits}")),
        }
    }
}

/// The sample type of EXR output (`film: {exr: float | half}`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum ExrSamples {
    /// 32-bit float.
    #[default]
    Float,
    /// 16-bit half float (11 significant bits, up to 65504).
    Half,
}

/// How an image's values are written.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Encoding {
    /// Exposure and tone curve of PNG and JPEG output.
    pub tonemap: Tonemap,
    /// Bits per channel of PNG output.
    pub bit_depth: BitDepth,
    /// Sample type of EXR output.
    pub exr: ExrSamples,
    /// JPEG quality, 1 to 100.
    pub jpeg_quality: u8,
    /// Whether PNG and EXR output carry the coverage as alpha
    /// ([`super::alpha`]).
    pub alpha: bool,
    /// The output variables written as layers of EXR output
    /// (`film: {aovs: […]}`, `--aov`; [`super::aov`]).
    pub aovs: super::aov::AovSet,
}

/// JPEG quality when the scene gives none.
pub const DEFAULT_JPEG_QUALITY: u8 = 90;

impl Default for Encoding {
    /// Clamped 8-bit sRGB, float EXR, JPEG quality 90.
    fn default() -> Self {
        Self {
            tonemap: Tonemap::default(),
            bit_depth: BitDepth::default(),
            exr: ExrSamples::default(),
            jpeg_quality: DEFAULT_JPEG_QUALITY,
            alpha: false,
            aovs: super::aov::AovSet::default(),
        }
    }
}

/// Command-line changes to the scene's [`Encoding`]; `None` keeps its value.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct OutputOverrides {
    /// The tone curve.
    pub tonemap: Option<Curve>,
    /// The exposure in stops.
    pub exposure: Option<f32>,
    /// PNG bits per channel.
    pub bit_depth: Option<BitDepth>,
    /// EXR sample type.
    pub exr: Option<ExrSamples>,
    /// Alpha in PNG and EXR output.
    pub alpha: Option<bool>,
    /// The output variables (`--aov` replaces the scene's `film.aovs`).
    pub aovs: Option<super::aov::AovSet>,
}

/// Equality is that of the fields; an override's exposure is checked to
/// be finite before it is used ([`Encoding::with`]).
impl Eq for OutputOverrides {}

impl Encoding {
    /// This encoding with `o` applied; fails on a non-finite exposure.
    pub fn with(self, o: &OutputOverrides) -> Result<Self, BadExposure> {
        let tonemap = Tonemap::new(
            o.tonemap.unwrap_or(self.tonemap.curve()),
            o.exposure.unwrap_or(self.tonemap.exposure()),
        )?;
        Ok(Self {
            tonemap,
            bit_depth: o.bit_depth.unwrap_or(self.bit_depth),
            exr: o.exr.unwrap_or(self.exr),
            alpha: o.alpha.unwrap_or(self.alpha),
            aovs: o.aovs.unwrap_or(self.aovs),
            ..self
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn extensions_name_formats() {
        for (name, format) in [
            ("a.png", Format::Png),
            ("a.PNG", Format::Png),
            ("a.jpg", Format::Jpeg),
            ("a.jpeg", Format::Jpeg),
            ("a.exr", Format::Exr),
            ("a.hdr", Format::Hdr),
        ] {
            assert_eq!(Format::of(Path::new(name)).ok(), Some(format), "{name}");
        }
        for bad in ["a.bmp", "a", "a.tiff"] {
            assert!(Format::of(Path::new(bad)).is_err(), "{bad}");
        }
        assert!(!Format::Jpeg.streams() && Format::Png.streams());
    }

    #[test]
    fn overrides_replace_what_they_name() {
        let base = Encoding::default();
        let o = OutputOverrides {
            tonemap: Some(Curve::Aces),
            bit_depth: Some(BitDepth::Sixteen),
            ..OutputOverrides::default()
        };
        let e = base.with(&o).expect("finite exposure");
        assert_eq!(e.tonemap.curve(), Curve::Aces);
        assert_eq!(e.tonemap.exposure(), 0.0);
        assert_eq!((e.bit_depth, e.exr), (BitDepth::Sixteen, ExrSamples::Float));
        let nan = OutputOverrides {
            exposure: Some(f32::NAN),
            ..OutputOverrides::default()
        };
        assert!(base.with(&nan).is_err());
        assert_eq!(BitDepth::try_from(16), Ok(BitDepth::Sixteen));
        assert!(BitDepth::try_from(12).is_err());
    }
}
