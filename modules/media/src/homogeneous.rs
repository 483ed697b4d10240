//! The `homogeneous` medium: the same σa and σs everywhere.

use radiant_core::params::Spanned;
use radiant_core::{
    BuildContext, Coefficients, Color, Medium, ModuleInfo, ParamDoc, ParamError, Params, Registry,
    Rgb,
};
use serde::Deserialize;

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct HomogeneousParams {
    sigma_a: Option<Spanned<Color>>,
    sigma_s: Option<Spanned<Color>>,
    albedo: Option<Spanned<Color>>,
    density: Option<Spanned<Color>>,
    scale: Option<Spanned<f32>>,
    emission: Option<Spanned<Color>>,
}

const DOCS: &[ParamDoc] = &[
    ParamDoc {
        name: "sigma_a",
        ty: "rgb | number, ≥ 0, per unit length",
        default: "0",
        doc: "Absorption coefficient σa (with `sigma_s`; not with `albedo`/`density`).",
    },
    ParamDoc {
        name: "sigma_s",
        ty: "rgb | number, ≥ 0, per unit length",
        default: "0",
        doc: "Scattering coefficient σs.",
    },
    ParamDoc {
        name: "albedo",
        ty: "rgb | number, [0, 1]",
        default: "0.8",
        doc: "Single-scattering albedo σs/σt (with `density`).",
    },
    ParamDoc {
        name: "density",
        ty: "rgb | number, ≥ 0, per unit length",
        default: "1",
        doc: "Extinction σt (with `albedo`).",
    },
    ParamDoc {
        name: "scale",
        ty: "number, ≥ 0",
        default: "1",
        doc: "Multiplies all coefficients (a unit change).",
    },
    ParamDoc {
        name: "emission",
        ty: "rgb | number, ≥ 0, W/(m²·sr)",
        default: "0",
        doc: "Emitted radiance Le (source σa·Le): glowing fog; an optically thick emitter shows Le.",
    },
];

/// A medium with constant coefficients (Mitsuba 3's `homogeneous`).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Homogeneous {
    coefficients: Coefficients,
}

impl Homogeneous {
    /// A medium of absorption `sigma_a`, scattering `sigma_s` and emitted
    /// radiance `emission`.
    pub fn new(sigma_a: Rgb, sigma_s: Rgb, emission: Rgb) -> Self {
        Self {
            coefficients: Coefficients {
                sigma_a,
                sigma_s,
                emission,
            },
        }
    }
}

impl Medium for Homogeneous {
    fn coefficients(&self) -> Coefficients {
        self.coefficients
    }
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

fn build(params: &Params, _ctx: &mut BuildContext<'_>) -> Result<Homogeneous, ParamError> {
    let p: HomogeneousParams = params.parse()?;
    let direct = p.sigma_a.is_some() || p.sigma_s.is_some();
    let derived = p.albedo.is_some() || p.density.is_some();
    if let (true, true, Some(c)) = (direct, derived, p.albedo.as_ref().or(p.density.as_ref())) {
        return Err(ParamError::at(
            c.span(),
            "give either `sigma_a`/`sigma_s` or `albedo`/`density`, not both",
        ));
    }
    let scale = match &p.scale {
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
            checked(&p.sigma_a, "sigma_a", Rgb::ZERO, f32::INFINITY)?,
            checked(&p.sigma_s, "sigma_s", Rgb::ZERO, f32::INFINITY)?,
        )
    } else {
        let albedo = checked(&p.albedo, "albedo", Rgb::splat(0.8), 1.0)?;
        let density = checked(&p.density, "density", Rgb::ONE, f32::INFINITY)?;
        (density * (Rgb::ONE - albedo), density * albedo)
    };
    let (sigma_a, sigma_s) = (sigma_a * scale, sigma_s * scale);
    if !(sigma_a + sigma_s).is_finite() {
        return Err(ParamError::new(
            "the medium's coefficients times `scale` overflow to infinity",
        ));
    }
    let emission = checked(&p.emission, "emission", Rgb::ZERO, f32::INFINITY)?;
    Ok(Homogeneous::new(sigma_a, sigma_s, emission))
}

pub(crate) fn register(registry: &mut Registry) {
    registry.register::<dyn Medium>(
        ModuleInfo {
            type_name: "homogeneous",
            summary: "Constant absorption and scattering; its `phase:` (a phase module, default isotropic) sets the scattering's angular distribution.",
            params: DOCS,
        },
        |params: &Params, ctx| Ok(Box::new(build(params, ctx)?) as Box<dyn Medium>),
    );
}

#[cfg(test)]
mod tests {
    // `unwrap` in this test code is the assertion: the parameters are the test's own, so a failure is a bug,
    // and the panic reports it.
    use super::*;
    use radiant_core::params::check_param_docs;

    #[test]
    fn documented_parameters_match() {
        check_param_docs::<HomogeneousParams>(DOCS).unwrap();
    }

    fn built(yaml: &str) -> Result<Homogeneous, ParamError> {
        // The test's own YAML text: it parses.
        let params = Params::from_yaml(yaml).unwrap();
        crate::build_standalone(|ctx| build(&params, ctx))
    }

    #[test]
    fn albedo_and_density_give_coefficients() {
        let m = built("albedo: 0.75\ndensity: 2\nscale: 2\n").unwrap();
        let c = m.coefficients();
        assert_eq!(c.sigma_s, Rgb::splat(3.0));
        assert_eq!(c.sigma_a, Rgb::splat(1.0));
    }

    #[test]
    fn bad_coefficients_are_located() {
        for (yaml, what) in [
            ("sigma_s: [1, -1, 1]\n", "sigma_s"),
            ("sigma_a: .nan\n", "sigma_a"),
            ("albedo: 1.5\n", "albedo"),
            ("density: .inf\n", "density"),
            ("scale: -1\nsigma_s: 1\n", "scale"),
            ("sigma_s: 1\nalbedo: 0.5\n", "not both"),
        ] {
            let e = built(yaml).unwrap_err();
            assert!(e.message.contains(what), "{yaml}: {}", e.message);
            assert!(e.location.is_some(), "{yaml}: no location");
        }
    }
}
