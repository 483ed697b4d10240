//! Tone mapping: how linear radiance becomes display values for the 8- and
//! 16-bit outputs (PNG, JPEG). The developed pixel is scaled by the
//! exposure (2^EV), mapped through a [`Curve`] to display-linear values in
//! [0, 1], and then sRGB-encoded and quantized by the encoder
//! ([`super::encode`]). EXR and Radiance HDR files store the developed
//! radiance itself: neither the exposure nor the curve touch them, so they
//! stay comparable to references and to each other.
//!
//! The curves, per channel unless said:
//! - `clamp`: min(x, 1), what Radiant always did (the default);
//! - `reinhard`: simple Reinhard, x / (1 + x) (Reinhard et al. 2002, eq. 3,
//!   applied to each channel rather than to luminance);
//! - `aces`: Narkowicz's fit of the ACES RRT + sRGB ODT,
//!   x(2.51x + 0.03) / (x(2.43x + 0.59) + 0.14), clamped to [0, 1]
//!   (applied to the exposed value as is, without Narkowicz's 0.6 pre-scale:
//!   use `exposure: -0.737` for it);
//! - `agx`: Sobotka's AgX base look as in Wrensch's minimal reference
//!   implementation (iolite, 2023): the inset matrix, log2 encoding over
//!   [−12.47393, 4.026069] EV, the 6th-order contrast polynomial, the
//!   outset matrix; its result is sRGB-encoded display values, so it is
//!   sRGB-decoded here and the encoder's sRGB encoding gives it back.

use radiant_core::Rgb;
use radiant_textures::srgb_to_linear;
use serde::Deserialize;

/// The tone curve (`film: {tonemap: {type: …}}`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Curve {
    /// Clamped to [0, 1].
    #[default]
    Clamp,
    /// x / (1 + x) per channel.
    Reinhard,
    /// Narkowicz's ACES filmic fit.
    Aces,
    /// AgX (Sobotka), Wrensch's minimal implementation.
    Agx,
}

impl Curve {
    /// The name a scene file uses.
    pub fn name(self) -> &'static str {
        match self {
            Curve::Clamp => "clamp",
            Curve::Reinhard => "reinhard",
            Curve::Aces => "aces",
            Curve::Agx => "agx",
        }
    }

    /// Every curve, in the order the documentation lists them.
    pub const ALL: [Curve; 4] = [Curve::Clamp, Curve::Reinhard, Curve::Aces, Curve::Agx];
}

impl std::str::FromStr for Curve {
    type Err = String;

    /// A curve by its scene-file name (for command-line options).
    fn from_str(s: &str) -> Result<Self, String> {
        Curve::ALL
            .into_iter()
            .find(|c| c.name() == s)
            .ok_or_else(|| {
                format!("unknown tone curve `{s}`; expected clamp, reinhard, aces or agx")
            })
    }
}

/// A tone map whose exposure is not a finite number.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[error("the exposure must be a finite number of stops (EV), found {0}")]
pub struct BadExposure(pub f32);

/// Exposure and curve: linear radiance to display-linear values.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Tonemap {
    curve: Curve,
    exposure: f32,
    /// 2^exposure.
    scale: f32,
}

/// The exposure is finite (checked by [`Tonemap::new`]), so equality is
/// reflexive.
impl Eq for Tonemap {}

impl Default for Tonemap {
    /// `clamp` at exposure 0: linear values clamped to [0, 1].
    fn default() -> Self {
        Self {
            curve: Curve::Clamp,
            exposure: 0.0,
            scale: 1.0,
        }
    }
}

impl Tonemap {
    /// `curve` after scaling by 2^`exposure`.
    pub fn new(curve: Curve, exposure: f32) -> Result<Self, BadExposure> {
        if !exposure.is_finite() {
            return Err(BadExposure(exposure));
        }
        Ok(Self {
            curve,
            exposure,
            scale: exposure.exp2(),
        })
    }

    /// The curve.
    pub fn curve(&self) -> Curve {
        self.curve
    }

    /// The exposure in stops.
    pub fn exposure(&self) -> f32 {
        self.exposure
    }

    /// Display-linear values in [0, 1] of the linear pixel `p` (NaN and
    /// negative channels become 0).
    #[inline]
    pub fn map(&self, p: Rgb) -> Rgb {
        let x = (p * self.scale).max(Rgb::ZERO);
        // `max` keeps NaN only where both are NaN: Rgb::ZERO is not.
        let y = match self.curve {
            Curve::Clamp => x,
            Curve::Reinhard => x / (Rgb::ONE + x),
            Curve::Aces => x.to_array().map(aces).into(),
            Curve::Agx => agx(x),
        };
        y.clamp(Rgb::ZERO, Rgb::ONE)
    }
}

/// Narkowicz's ACES fit (2016), unclamped.
#[inline]
pub fn aces(x: f32) -> f32 {
    (x * (2.51 * x + 0.03)) / (x * (2.43 * x + 0.59) + 0.14)
}

/// AgX's inset matrix (rows), linear Rec.709 in.
const AGX_INSET: [[f32; 3]; 3] = [
    [0.842_479_06, 0.078_433_6, 0.079_223_745],
    [0.042_328_242, 0.878_468_6, 0.079_166_13],
    [0.042_375_655, 0.078_433_6, 0.879_143],
];

/// AgX's outset matrix (rows): the inverse of the inset.
const AGX_OUTSET: [[f32; 3]; 3] = [
    [1.196_879, -0.098_020_88, -0.099_029_74],
    [-0.052_896_85, 1.151_903_1, -0.098_961_18],
    [-0.052_971_635, -0.098_043_45, 1.151_073_7],
];

/// AgX's log2 range in stops around 0.18·2^… (its normalisation).
const AGX_MIN_EV: f32 = -12.473_93;
/// See [`AGX_MIN_EV`].
const AGX_MAX_EV: f32 = 4.026_069;

/// `m` times `v`.
#[inline]
fn mul(m: &[[f32; 3]; 3], v: [f32; 3]) -> [f32; 3] {
    m.map(|row| row[0] * v[0] + row[1] * v[1] + row[2] * v[2])
}

/// AgX's 6th-order fit of its default contrast sigmoid, on [0, 1].
#[inline]
pub fn agx_contrast(x: f32) -> f32 {
    let (x2, x4) = (x * x, x * x * x * x);
    15.5 * x4 * x2 - 40.14 * x4 * x + 31.96 * x4 - 6.868 * x2 * x + 0.4298 * x2 + 0.1191 * x
        - 0.002_32
}

/// AgX of a non-negative linear pixel, as display-linear values.
#[inline]
fn agx(x: Rgb) -> Rgb {
    let inset = mul(&AGX_INSET, x.to_array()).map(|c| {
        let ev = c
            .max(f32::MIN_POSITIVE)
            .log2()
            .clamp(AGX_MIN_EV, AGX_MAX_EV);
        agx_contrast((ev - AGX_MIN_EV) / (AGX_MAX_EV - AGX_MIN_EV))
    });
    let encoded = mul(&AGX_OUTSET, inset);
    Rgb::from(encoded.map(|c| srgb_to_linear(c.clamp(0.0, 1.0))))
}

#[cfg(test)]
mod tests {
    // `unwrap` in this test code is the assertion: the curves and exposures are the test's own, so a failure is a bug,
    // and the panic reports it.
    use super::*;
    use crate::film::output::srgb_encode;

    fn grey(t: &Tonemap, x: f32) -> f32 {
        t.map(Rgb::splat(x)).x
    }

    #[test]
    fn curves_match_their_published_formulas() {
        let reinhard = Tonemap::new(Curve::Reinhard, 0.0).unwrap();
        let aces = Tonemap::new(Curve::Aces, 0.0).unwrap();
        for x in [0.01f32, 0.18, 0.5, 1.0, 2.0, 10.0, 1000.0] {
            let x64 = x as f64;
            let r = x64 / (1.0 + x64);
            assert!((grey(&reinhard, x) as f64 - r).abs() < 1e-6, "reinhard {x}");
            let a = ((x64 * (2.51 * x64 + 0.03)) / (x64 * (2.43 * x64 + 0.59) + 0.14)).min(1.0);
            assert!((grey(&aces, x) as f64 - a).abs() < 1e-5, "aces {x}");
        }
        // Published values of Narkowicz's fit: 0.18 → 0.2669, 1 → 0.8038.
        assert!((grey(&aces, 0.18) - 0.2669).abs() < 1e-3);
        assert!((grey(&aces, 1.0) - 0.8038).abs() < 1e-3);
        // Exposure is a factor of 2^EV before the curve.
        let up = Tonemap::new(Curve::Reinhard, 2.0).unwrap();
        assert!((grey(&up, 0.25) - 0.5).abs() < 1e-6);
        let clamp = Tonemap::default();
        assert_eq!(grey(&clamp, 0.3), 0.3);
        assert_eq!(grey(&clamp, 3.0), 1.0);
    }

    #[test]
    fn agx_follows_the_reference_implementation() {
        // The outset matrix inverts the inset one.
        for j in 0..3 {
            let column = mul(&AGX_INSET, AGX_OUTSET.map(|row| row[j]));
            for (i, e) in column.into_iter().enumerate() {
                assert!((e - f32::from(i == j)).abs() < 1e-5, "{i}{j}: {e}");
            }
        }
        let agx = Tonemap::new(Curve::Agx, 0.0).unwrap();
        // A grey stays grey (the matrices' rows sum to 1 within 1.4e-4),
        // and its sRGB encoding is the reference's output: log2 encoding,
        // polynomial.
        for x in [0.001f32, 0.18, 1.0, 4.0] {
            let y = agx.map(Rgb::splat(x));
            assert!(
                (y.x - y.y).abs() < 1e-3 && (y.y - y.z).abs() < 1e-3,
                "{x}: {y}"
            );
            let t = ((x.log2() - AGX_MIN_EV) / (AGX_MAX_EV - AGX_MIN_EV)) as f64;
            let poly = 15.5 * t.powi(6) - 40.14 * t.powi(5) + 31.96 * t.powi(4) - 6.868 * t.powi(3)
                + 0.4298 * t * t
                + 0.1191 * t
                - 0.00232;
            assert!(
                (srgb_encode(y.y) as f64 - poly).abs() < 2e-3,
                "{x}: {y} {poly}"
            );
        }
        // Middle grey lands near the middle of the display range.
        let mid = srgb_encode(grey(&agx, 0.18));
        assert!((0.4..0.6).contains(&mid), "{mid}");
    }

    #[test]
    fn every_curve_is_monotonic_and_maps_zero_to_zero() {
        for curve in Curve::ALL {
            let t = Tonemap::new(curve, 0.0).unwrap();
            assert_eq!(grey(&t, 0.0), 0.0, "{curve:?}");
            assert_eq!(grey(&t, -1.0), 0.0, "{curve:?}");
            assert_eq!(t.map(Rgb::splat(f32::NAN)), Rgb::ZERO, "{curve:?}");
            let mut last = 0.0;
            for i in 1..=4000 {
                // 2^-20 to 2^20, in 1/100 stops.
                let x = ((i as f32 - 2000.0) / 100.0).exp2();
                let y = grey(&t, x);
                assert!(y >= last, "{curve:?} falls at {x}: {y} < {last}");
                assert!((0.0..=1.0).contains(&y), "{curve:?} {x}: {y}");
                last = y;
            }
            // Bright values approach white.
            assert!(grey(&t, 1e6) > 0.95, "{curve:?}");
        }
    }

    #[test]
    fn non_finite_exposure_is_refused() {
        for bad in [f32::NAN, f32::INFINITY, f32::NEG_INFINITY] {
            assert!(Tonemap::new(Curve::Aces, bad).is_err());
        }
        let t = Tonemap::new(Curve::Aces, -1.5).unwrap();
        assert_eq!((t.curve(), t.exposure()), (Curve::Aces, -1.5));
    }
}
