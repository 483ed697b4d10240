//! The coefficient parameters every medium shares: σa and σs (or albedo
//! and density), a `scale` and an `emission`, checked and combined into
//! [`Coefficients`]. Each medium's parameter struct and documentation
//! table are declared through [`medium_params!`] and [`medium_docs!`], so
//! the shared keys are written once.

use radiant_core::params::Spanned;
use radiant_core::{Coefficients, Color, ParamError, Rgb};

/// Declares a medium's parameter struct: the shared coefficient keys plus
/// the medium's own fields, with a `shared()` accessor for the former.
macro_rules! medium_params {
    ($name:ident { $($field:ident : $ty:ty),* $(,)? }) => {
        #[derive(serde::Deserialize)]
        #[serde(deny_unknown_fields)]
        struct $name {
            sigma_a: Option<radiant_core::params::Spanned<radiant_core::Color>>,
            sigma_s: Option<radiant_core::params::Spanned<radiant_core::Color>>,
            albedo: Option<radiant_core::params::Spanned<radiant_core::Color>>,
            density: Option<radiant_core::params::Spanned<radiant_core::Color>>,
            scale: Option<radiant_core::params::Spanned<f32>>,
            emission: Option<radiant_core::params::Spanned<radiant_core::Color>>,
            $($field: $ty),*
        }

        impl $name {
            fn shared(&self) -> $crate::coefficients::Shared<'_> {
                $crate::coefficients::Shared {
                    sigma_a: &self.sigma_a,
                    sigma_s: &self.sigma_s,
                    albedo: &self.albedo,
                    density: &self.density,
                    scale: &self.scale,
                    emission: &self.emission,
                }
            }
        }
    };
}

/// The documentation table of a medium: the shared keys (`density` is
/// described as `$density`), then the medium's own entries.
macro_rules! medium_docs {
    ($density:expr $(, $extra:expr)* $(,)?) => {
        &[
            radiant_core::ParamDoc {
                name: "sigma_a",
                ty: "rgb | number, ≥ 0, per unit length",
                default: "0",
                doc: "Absorption coefficient σa (with `sigma_s`; not with `albedo`/`density`).",
            },
            radiant_core::ParamDoc {
                name: "sigma_s",
                ty: "rgb | number, ≥ 0, per unit length",
                default: "0",
                doc: "Scattering coefficient σs.",
            },
            radiant_core::ParamDoc {
                name: "albedo",
                ty: "rgb | number, [0, 1]",
                default: "0.8",
                doc: "Single-scattering albedo σs/σt (with `density`).",
            },
            radiant_core::ParamDoc {
                name: "density",
                ty: "rgb | number, ≥ 0, per unit length",
                default: "1",
                doc: $density,
            },
            radiant_core::ParamDoc {
                name: "scale",
                ty: "number, ≥ 0",
                default: "1",
                doc: "Multiplies all coefficients (a unit change).",
            },
            radiant_core::ParamDoc {
                name: "emission",
                ty: "rgb | number, ≥ 0, W/(m²·sr)",
                default: "0",
                doc: "Emitted radiance Le (source σa·Le): glowing fog; an optically thick emitter shows Le.",
            },
            $($extra),*
        ]
    };
}

pub(crate) use {medium_docs, medium_params};

/// The shared coefficient keys of a medium's parameters, as written.
pub(crate) struct Shared<'a> {
    pub sigma_a: &'a Option<Spanned<Color>>,
    pub sigma_s: &'a Option<Spanned<Color>>,
    pub albedo: &'a Option<Spanned<Color>>,
    pub density: &'a Option<Spanned<Color>>,
    pub scale: &'a Option<Spanned<f32>>,
    pub emission: &'a Option<Spanned<Color>>,
}

/// The value of `c`, checked to be finite and in [0, max] in every channel.
fn checked(
    c: &Option<Spanned<Color>>,
    name: &str,
    default: Rgb,
    max: f32,
) -> Result<Rgb, ParamError> {
    let Some(c) = c else {
        return Ok(default);
    };
    let v = c.0;
    if v.is_finite() && v.min_element() >= 0.0 && v.max_element() <= max {
        Ok(v)
    } else {
        let range = if max.is_finite() {
            format!("[0, {max}]")
        } else {
            "0 or more (and finite)".to_string()
        };
        Err(ParamError::at(
            c.span(),
            format!("`{name}` must be {range} in every channel, found {v}"),
        ))
    }
}

impl Shared<'_> {
    /// The checked coefficients: σa and σs given directly, or as albedo
    /// and density, times `scale`; and the emission.
    pub fn coefficients(&self) -> Result<Coefficients, ParamError> {
        let direct = self.sigma_a.is_some() || self.sigma_s.is_some();
        let derived = self.albedo.is_some() || self.density.is_some();
        if let (true, true, Some(c)) = (
            direct,
            derived,
            self.albedo.as_ref().or(self.density.as_ref()),
        ) {
            return Err(ParamError::at(
                c.span(),
                "give either `sigma_a`/`sigma_s` or `albedo`/`density`, not both",
            ));
        }
        let scale = match self.scale {
            None => 1.0,
            Some(s) if s.is_finite() && **s >= 0.0 => **s,
            Some(s) => {
                return Err(ParamError::at(
                    s.span(),
                    format!("`scale` must be a finite number ≥ 0, found {}", **s),
                ));
            }
        };
        let (sigma_a, sigma_s) = if direct {
            (
                checked(self.sigma_a, "sigma_a", Rgb::ZERO, f32::INFINITY)?,
                checked(self.sigma_s, "sigma_s", Rgb::ZERO, f32::INFINITY)?,
            )
        } else {
            let albedo = checked(self.albedo, "albedo", Rgb::splat(0.8), 1.0)?;
            let density = checked(self.density, "density", Rgb::ONE, f32::INFINITY)?;
            (density * (Rgb::ONE - albedo), density * albedo)
        };
        let (sigma_a, sigma_s) = (sigma_a * scale, sigma_s * scale);
        if !(sigma_a + sigma_s).is_finite() {
            return Err(ParamError::new(
                "the medium's coefficients times `scale` overflow to infinity",
            ));
        }
        let emission = checked(self.emission, "emission", Rgb::ZERO, f32::INFINITY)?;
        Ok(Coefficients {
            sigma_a,
            sigma_s,
            emission,
        })
    }
}
