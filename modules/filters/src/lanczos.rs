//! The `lanczos` filter: the windowed sinc sinc(x) · sinc(x / a) on
//! [−a, a], where a is the number of lobes.

use crate::separable::{Kernel, Separable};
use radiant_core::{Filter, ModuleInfo, ParamDoc, ParamError, Registry};
use serde::Deserialize;
use std::f32::consts::PI;

/// The Lanczos kernel with `lobes` lobes.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LanczosKernel {
    lobes: f32,
}

/// The Lanczos filter.
pub type LanczosFilter = Separable<LanczosKernel>;

impl LanczosKernel {
    /// The kernel with `lobes` lobes (radius `lobes` pixels).
    pub fn new(lobes: u32) -> Self {
        Self {
            lobes: lobes as f32,
        }
    }
}

/// sin(πx)/(πx), 1 at 0.
fn sinc(x: f32) -> f32 {
    let px = PI * x;
    if px.abs() < 1e-4 {
        1.0 - px * px / 6.0
    } else {
        px.sin() / px
    }
}

impl Kernel for LanczosKernel {
    fn radius(&self) -> f32 {
        self.lobes
    }

    fn eval_1d(&self, x: f32) -> f32 {
        if x.abs() >= self.lobes {
            0.0
        } else {
            sinc(x) * sinc(x / self.lobes)
        }
    }
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct LanczosParams {
    #[serde(default = "three")]
    lobes: u32,
}

fn three() -> u32 {
    3
}

const DOCS: &[ParamDoc] = &[ParamDoc {
    name: "lobes",
    ty: "integer, 1 to 16",
    default: "3",
    doc: "Number of sinc lobes on each side; also the radius in pixels.",
}];

pub(crate) fn register(registry: &mut Registry) {
    registry.register::<dyn Filter>(
        ModuleInfo {
            type_name: "lanczos",
            summary: "Lanczos windowed sinc (negative lobes).",
            params: DOCS,
        },
        |params, _| {
            let p: LanczosParams = params.parse()?;
            if !(1..=16).contains(&p.lobes) {
                return Err(ParamError {
                    message: format!("`lobes` must be an integer from 1 to 16, found {}", p.lobes),
                    location: params.location_of("lobes"),
                });
            }
            Ok(Box::new(Separable(LanczosKernel::new(p.lobes))) as Box<dyn Filter>)
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
        check_param_docs::<LanczosParams>(DOCS).unwrap();
    }

    #[test]
    fn lanczos_values_at_known_points() {
        let k = LanczosKernel::new(3);
        assert!((k.eval_1d(0.0) - 1.0).abs() < 1e-6);
        for i in 1..3 {
            assert!(k.eval_1d(i as f32).abs() < 1e-6, "zero at {i}");
        }
        // sinc(0.5) sinc(1/6) = (2/π) · (sin(π/6)/(π/6)) = (2/π)(3/π).
        let expected = (2.0 / PI) * (3.0 / PI);
        assert!((k.eval_1d(0.5) - expected).abs() < 1e-6);
        assert!(k.eval_1d(1.5) < 0.0, "first negative lobe");
        assert_eq!(k.eval_1d(3.0), 0.0);
    }
}
