//! The `box` filter: every sample within the radius counts equally.

use crate::separable::{Kernel, Separable};
use crate::validate::{half, radius};
use radiant_core::{Filter, ModuleInfo, ParamDoc, Registry};
use serde::Deserialize;

/// The box kernel of half-width `radius`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct BoxKernel {
    /// Half-width in pixels.
    pub radius: f32,
}

/// The box filter.
pub type BoxFilter = Separable<BoxKernel>;

impl Kernel for BoxKernel {
    fn radius(&self) -> f32 {
        self.radius
    }

    fn eval_1d(&self, _x: f32) -> f32 {
        1.0
    }
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct BoxParams {
    #[serde(default = "half")]
    radius: f32,
}

const DOCS: &[ParamDoc] = &[ParamDoc {
    name: "radius",
    ty: "pixels, 0.5–32",
    default: "0.5",
    doc: "Half-width of the box.",
}];

pub(crate) fn register(registry: &mut Registry) {
    registry.register::<dyn Filter>(
        ModuleInfo {
            type_name: "box",
            summary: "Box filter: uniform weight within the radius.",
            params: DOCS,
        },
        |params, _| {
            let p: BoxParams = params.parse()?;
            let radius = radius(params, "radius", p.radius)?;
            Ok(Box::new(Separable(BoxKernel { radius })) as Box<dyn Filter>)
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
        check_param_docs::<BoxParams>(DOCS).unwrap();
    }

    #[test]
    fn box_is_flat() {
        let b = Separable(BoxKernel { radius: 0.5 });
        assert_eq!(b.eval(0.49, -0.49), 1.0);
        assert_eq!(b.eval(0.51, 0.0), 0.0);
    }
}
