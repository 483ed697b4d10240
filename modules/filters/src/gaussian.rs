//! The `gaussian` filter: Mitsuba 3's truncated Gaussian,
//! max(0, exp(−x²/2σ²) − exp(−r²/2σ²)) per axis.

use crate::separable::{Kernel, Separable};
use crate::validate::{half, positive, radius};
use radiant_core::{Filter, ModuleInfo, ParamDoc, ParamError, Registry};
use serde::Deserialize;

/// The widest cut-off in standard deviations: the film tabulates a filter at
/// 64 points over its radius, so a narrower Gaussian would fall between them.
const MAX_RADII: f32 = 16.0;

/// The truncated Gaussian kernel.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct GaussianKernel {
    radius: f32,
    alpha: f32,
    bias: f32,
}

/// The truncated Gaussian filter.
pub type GaussianFilter = Separable<GaussianKernel>;

impl GaussianKernel {
    /// A Gaussian of standard deviation `stddev` truncated at `radius`.
    pub fn new(stddev: f32, radius: f32) -> Self {
        let alpha = -1.0 / (2.0 * stddev * stddev);
        Self {
            radius,
            alpha,
            bias: (alpha * radius * radius).exp(),
        }
    }
}

impl Kernel for GaussianKernel {
    fn radius(&self) -> f32 {
        self.radius
    }

    fn eval_1d(&self, x: f32) -> f32 {
        ((self.alpha * x * x).exp() - self.bias).max(0.0)
    }
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct GaussianParams {
    #[serde(default = "half")]
    stddev: f32,
    radius: Option<f32>,
}

const DOCS: &[ParamDoc] = &[
    ParamDoc {
        name: "stddev",
        ty: "pixels, > 0",
        default: "0.5",
        doc: "Standard deviation.",
    },
    ParamDoc {
        name: "radius",
        ty: "pixels, 0.5–32, ≤ 16 × stddev",
        default: "4 × stddev",
        doc: "Where the Gaussian is cut off (it is shifted down to reach 0 there).",
    },
];

pub(crate) fn register(registry: &mut Registry) {
    registry.register::<dyn Filter>(
        ModuleInfo {
            type_name: "gaussian",
            summary: "Truncated Gaussian (Mitsuba 3's default filter).",
            params: DOCS,
        },
        |params, _| {
            let p: GaussianParams = params.parse()?;
            let stddev = positive(params, "stddev", p.stddev)?;
            let key = if p.radius.is_some() {
                "radius"
            } else {
                "stddev"
            };
            let radius = radius(params, key, p.radius.unwrap_or(4.0 * stddev))?;
            if radius > MAX_RADII * stddev {
                return Err(ParamError {
                    message: format!(
                        "`radius` ({radius}) must be at most {MAX_RADII} × `stddev` ({stddev}): \
                         a narrower Gaussian falls between the filter table's samples"
                    ),
                    location: params.location_of("radius"),
                });
            }
            Ok(Box::new(Separable(GaussianKernel::new(stddev, radius))) as Box<dyn Filter>)
        },
    );
}

#[cfg(test)]
mod tests {
    // `unwrap` in this test code is the assertion: the inputs are the test's
    // own, so a failure is a bug, and the panic reports it with the error.
    use super::*;
    use radiant_core::params::check_param_docs;

    #[test]
    fn documented_parameters_match() {
        check_param_docs::<GaussianParams>(DOCS).unwrap();
    }

    #[test]
    fn gaussian_is_mitsubas_truncated_gaussian() {
        let g = Separable(GaussianKernel::new(0.5, 2.0));
        assert!((g.eval(0.0, 0.0) - (1.0 - (-8.0f32).exp()).powi(2)).abs() < 1e-6);
        assert_eq!(g.eval(2.0, 0.0), 0.0);
        assert_eq!(g.eval(0.0, -2.5), 0.0);
        assert!(g.eval(0.5, 0.0) < g.eval(0.25, 0.0));
        let x = 0.7f32;
        let expected = (-x * x / 0.5).exp() - (-8.0f32).exp();
        assert!(
            (g.eval(x, 0.0) / g.eval(0.0, 0.0) - expected / (1.0 - (-8.0f32).exp())).abs() < 1e-6
        );
    }
}
