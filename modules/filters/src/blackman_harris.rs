//! The `blackman_harris` filter: the four-term Blackman–Harris window
//! a0 + a1 cos(πx/r) + a2 cos(2πx/r) + a3 cos(3πx/r) on [−r, r].

use crate::separable::{Kernel, Separable};
use crate::validate::radius;
use radiant_core::{Filter, ModuleInfo, ParamDoc, Registry};
use serde::Deserialize;
use std::f32::consts::PI;

/// The Blackman–Harris coefficients a0..a3 (Harris 1978, −92 dB).
pub const BLACKMAN_HARRIS: [f32; 4] = [0.358_75, 0.488_29, 0.141_28, 0.011_68];

/// The Blackman–Harris kernel.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct BlackmanHarrisKernel {
    /// Half-width in pixels.
    pub radius: f32,
}

/// The Blackman–Harris filter.
pub type BlackmanHarrisFilter = Separable<BlackmanHarrisKernel>;

impl Kernel for BlackmanHarrisKernel {
    fn radius(&self) -> f32 {
        self.radius
    }

    fn eval_1d(&self, x: f32) -> f32 {
        let t = PI * x / self.radius;
        let [a0, a1, a2, a3] = BLACKMAN_HARRIS;
        a0 + a1 * t.cos() + a2 * (2.0 * t).cos() + a3 * (3.0 * t).cos()
    }
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct BlackmanHarrisParams {
    #[serde(default = "two")]
    radius: f32,
}

fn two() -> f32 {
    2.0
}

const DOCS: &[ParamDoc] = &[ParamDoc {
    name: "radius",
    ty: "pixels, 0.5–32",
    default: "2",
    doc: "Half-width of the window.",
}];

pub(crate) fn register(registry: &mut Registry) {
    registry.register::<dyn Filter>(
        ModuleInfo {
            type_name: "blackman_harris",
            summary: "Four-term Blackman–Harris window: smooth, nearly Gaussian, no negative lobes.",
            params: DOCS,
        },
        |params, _| {
            let p: BlackmanHarrisParams = params.parse()?;
            let radius = radius(params, "radius", p.radius)?;
            Ok(Box::new(Separable(BlackmanHarrisKernel { radius })) as Box<dyn Filter>)
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
        check_param_docs::<BlackmanHarrisParams>(DOCS).unwrap();
    }

    #[test]
    fn window_values_at_known_points() {
        let k = BlackmanHarrisKernel { radius: 2.0 };
        assert!((k.eval_1d(0.0) - 1.0).abs() < 1e-6, "a0 + a1 + a2 + a3 = 1");
        assert!((k.eval_1d(2.0) - 6e-5).abs() < 1e-6, "a0 − a1 + a2 − a3");
        // At r/2: a0 − a2 (the odd cosines vanish).
        assert!((k.eval_1d(1.0) - (0.358_75 - 0.141_28)).abs() < 1e-6);
    }
}
