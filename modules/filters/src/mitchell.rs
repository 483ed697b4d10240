//! The `mitchell` filter: the Mitchell–Netravali cubic with parameters B
//! and C, stretched from its natural support [−2, 2] to [−r, r].

use crate::separable::{Kernel, Separable};
use crate::validate::{radius, unit};
use radiant_core::{Filter, ModuleInfo, ParamDoc, Registry};
use serde::Deserialize;

/// The Mitchell–Netravali kernel.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct MitchellKernel {
    radius: f32,
    /// Polynomial coefficients (cubic, quadratic, linear, constant) on
    /// |x'| < 1 and 1 ≤ |x'| < 2, already divided by 6.
    inner: [f32; 4],
    outer: [f32; 4],
}

/// The Mitchell–Netravali filter.
pub type MitchellFilter = Separable<MitchellKernel>;

impl MitchellKernel {
    /// The kernel with parameters `b`, `c` over [−radius, radius].
    pub fn new(b: f32, c: f32, radius: f32) -> Self {
        let s = 1.0 / 6.0;
        Self {
            radius,
            inner: [
                (12.0 - 9.0 * b - 6.0 * c) * s,
                (-18.0 + 12.0 * b + 6.0 * c) * s,
                0.0,
                (6.0 - 2.0 * b) * s,
            ],
            outer: [
                (-b - 6.0 * c) * s,
                (6.0 * b + 30.0 * c) * s,
                (-12.0 * b - 48.0 * c) * s,
                (8.0 * b + 24.0 * c) * s,
            ],
        }
    }
}

impl Kernel for MitchellKernel {
    fn radius(&self) -> f32 {
        self.radius
    }

    fn eval_1d(&self, x: f32) -> f32 {
        let x = (2.0 * x / self.radius).abs();
        let k = if x < 1.0 {
            &self.inner
        } else if x < 2.0 {
            &self.outer
        } else {
            return 0.0;
        };
        ((k[0] * x + k[1]) * x + k[2]) * x + k[3]
    }
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
#[allow(non_snake_case)]
struct MitchellParams {
    #[serde(default = "third")]
    B: f32,
    #[serde(default = "third")]
    C: f32,
    #[serde(default = "two")]
    radius: f32,
}

fn third() -> f32 {
    1.0 / 3.0
}

fn two() -> f32 {
    2.0
}

const DOCS: &[ParamDoc] = &[
    ParamDoc {
        name: "B",
        ty: "0–1",
        default: "1/3",
        doc: "Blur parameter B of the Mitchell–Netravali family (B = 1, C = 0 is the cubic B-spline).",
    },
    ParamDoc {
        name: "C",
        ty: "0–1",
        default: "1/3",
        doc: "Ringing parameter C (B = 0, C = 0.5 is Catmull–Rom).",
    },
    ParamDoc {
        name: "radius",
        ty: "pixels, 0.5–32",
        default: "2",
        doc: "Support half-width; the cubic's natural support [−2, 2] is scaled to it.",
    },
];

pub(crate) fn register(registry: &mut Registry) {
    registry.register::<dyn Filter>(
        ModuleInfo {
            type_name: "mitchell",
            summary: "Mitchell–Netravali cubic filter (negative lobes for C > 0).",
            params: DOCS,
        },
        |params, _| {
            let p: MitchellParams = params.parse()?;
            let b = unit(params, "B", p.B)?;
            let c = unit(params, "C", p.C)?;
            let radius = radius(params, "radius", p.radius)?;
            Ok(Box::new(Separable(MitchellKernel::new(b, c, radius))) as Box<dyn Filter>)
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
        check_param_docs::<MitchellParams>(DOCS).unwrap();
    }

    #[test]
    fn mitchell_values_at_known_points() {
        let k = MitchellKernel::new(1.0 / 3.0, 1.0 / 3.0, 2.0);
        assert!((k.eval_1d(0.0) - 8.0 / 9.0).abs() < 1e-6);
        assert!((k.eval_1d(1.0) - 1.0 / 18.0).abs() < 1e-6);
        assert!((k.eval_1d(-1.0) - 1.0 / 18.0).abs() < 1e-6);
        assert!(k.eval_1d(2.0).abs() < 1e-6);
        // Negative lobe between 1 and 2: at 1.5, (−7/3·3.375 + 12·2.25 − 20·1.5 + 32/3)/6.
        let at = 1.5f32;
        let expected = (-7.0 / 3.0 * at.powi(3) + 12.0 * at * at - 20.0 * at + 32.0 / 3.0) / 6.0;
        assert!((k.eval_1d(at) - expected).abs() < 1e-6 && expected < 0.0);
        // Catmull–Rom interpolates: 1 at 0, 0 at ±1.
        let cr = MitchellKernel::new(0.0, 0.5, 2.0);
        assert!((cr.eval_1d(0.0) - 1.0).abs() < 1e-6 && cr.eval_1d(1.0).abs() < 1e-6);
        // A radius of 4 stretches the kernel by 2.
        let wide = MitchellKernel::new(1.0 / 3.0, 1.0 / 3.0, 4.0);
        assert!((wide.eval_1d(2.0) - 1.0 / 18.0).abs() < 1e-6);
    }

    #[test]
    fn reproduces_constants_at_its_natural_size() {
        // Σ_k k(x − k) = 1 for every x: a flat image stays flat.
        let k = MitchellKernel::new(0.3, 0.4, 2.0);
        for i in 0..10 {
            let x = i as f32 / 10.0;
            let s: f32 = (-2..=3).map(|j| k.eval_1d(x - j as f32)).sum();
            assert!((s - 1.0).abs() < 1e-5, "{x}: {s}");
        }
    }
}
