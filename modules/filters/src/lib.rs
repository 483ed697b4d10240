//! # radiant-filters: built-in pixel reconstruction filters
//!
//! The film (the last stage of the wavefront) splats each sample into the
//! pixels within a filter's radius; these modules define the weights.

use radiant_core::{Filter, ModuleInfo, ParamDoc, ParamError, Params, Registry};
use serde::Deserialize;

/// The box filter: every sample within `radius` counts equally.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct BoxFilter {
    radius: f32,
}

impl Filter for BoxFilter {
    fn radius(&self) -> f32 {
        self.radius
    }

    fn eval(&self, x: f32, y: f32) -> f32 {
        if x.abs() <= self.radius && y.abs() <= self.radius {
            1.0
        } else {
            0.0
        }
    }
}

/// The truncated Gaussian of Mitsuba 3: `max(0, exp(-x²/2σ²) - exp(-r²/2σ²))`
/// per axis, separable.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct GaussianFilter {
    radius: f32,
    alpha: f32,
    bias: f32,
}

impl GaussianFilter {
    /// A Gaussian of standard deviation `stddev` truncated at `radius`.
    pub fn new(stddev: f32, radius: f32) -> Self {
        let alpha = -1.0 / (2.0 * stddev * stddev);
        Self {
            radius,
            alpha,
            bias: (alpha * radius * radius).exp(),
        }
    }

    fn eval_1d(&self, x: f32) -> f32 {
        ((self.alpha * x * x).exp() - self.bias).max(0.0)
    }
}

impl Filter for GaussianFilter {
    fn radius(&self) -> f32 {
        self.radius
    }

    fn eval(&self, x: f32, y: f32) -> f32 {
        self.eval_1d(x) * self.eval_1d(y)
    }
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct BoxParams {
    #[serde(default = "half")]
    radius: f32,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct GaussianParams {
    #[serde(default = "half")]
    stddev: f32,
    radius: Option<f32>,
}

fn half() -> f32 {
    0.5
}

const BOX_DOCS: &[ParamDoc] = &[ParamDoc {
    name: "radius",
    ty: "pixels, > 0",
    default: "0.5",
    doc: "Half-width of the box.",
}];

const GAUSSIAN_DOCS: &[ParamDoc] = &[
    ParamDoc {
        name: "stddev",
        ty: "pixels, > 0",
        default: "0.5",
        doc: "Standard deviation.",
    },
    ParamDoc {
        name: "radius",
        ty: "pixels, > 0",
        default: "4 × stddev",
        doc: "Where the Gaussian is cut off (it is shifted down to reach 0 there).",
    },
];

fn positive(params: &Params, key: &str, value: f32) -> Result<f32, ParamError> {
    if value > 0.0 && value.is_finite() {
        Ok(value)
    } else {
        Err(ParamError {
            message: format!("`{key}` must be a positive number of pixels, found {value}"),
            location: params.location_of(key),
        })
    }
}

/// Registers every built-in filter type.
pub fn register(registry: &mut Registry) {
    registry.register::<dyn Filter>(
        ModuleInfo {
            type_name: "box",
            summary: "Box filter: uniform weight within the radius.",
            params: BOX_DOCS,
        },
        |params, _| {
            let p: BoxParams = params.parse()?;
            let radius = positive(params, "radius", p.radius)?;
            Ok(Box::new(BoxFilter { radius }) as Box<dyn Filter>)
        },
    );
    registry.register::<dyn Filter>(
        ModuleInfo {
            type_name: "gaussian",
            summary: "Truncated Gaussian (Mitsuba 3's default filter).",
            params: GAUSSIAN_DOCS,
        },
        |params, _| {
            let p: GaussianParams = params.parse()?;
            let stddev = positive(params, "stddev", p.stddev)?;
            let radius = positive(params, "radius", p.radius.unwrap_or(4.0 * stddev))?;
            Ok(Box::new(GaussianFilter::new(stddev, radius)) as Box<dyn Filter>)
        },
    );
}

#[cfg(test)]
mod tests {
    use super::*;
    use radiant_core::params::check_param_docs;

    #[test]
    fn documented_parameters_match() {
        check_param_docs::<BoxParams>(BOX_DOCS).unwrap();
        check_param_docs::<GaussianParams>(GAUSSIAN_DOCS).unwrap();
    }

    #[test]
    fn gaussian_is_mitsubas_truncated_gaussian() {
        let g = GaussianFilter::new(0.5, 2.0);
        assert!((g.eval(0.0, 0.0) - (1.0 - (-8.0f32).exp()).powi(2)).abs() < 1e-6);
        assert_eq!(g.eval(2.0, 0.0), 0.0);
        assert_eq!(g.eval(0.0, -2.5), 0.0);
        assert!(g.eval(0.5, 0.0) < g.eval(0.25, 0.0));
    }

    #[test]
    fn box_is_flat() {
        let b = BoxFilter { radius: 0.5 };
        assert_eq!(b.eval(0.49, -0.49), 1.0);
        assert_eq!(b.eval(0.51, 0.0), 0.0);
    }
}
