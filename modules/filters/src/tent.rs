//! The `tent` filter: 1 − |x|/r per axis (the seeds' SmallPT-style tent).

use crate::separable::{Kernel, Separable};
use crate::validate::radius;
use radiant_core::{Filter, ModuleInfo, ParamDoc, Registry};
use serde::Deserialize;

/// The tent (triangle) kernel.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct TentKernel {
    /// Where the tent reaches zero, in pixels.
    pub radius: f32,
}

/// The tent filter.
pub type TentFilter = Separable<TentKernel>;

impl Kernel for TentKernel {
    fn radius(&self) -> f32 {
        self.radius
    }

    fn eval_1d(&self, x: f32) -> f32 {
        (1.0 - x.abs() / self.radius).max(0.0)
    }
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct TentParams {
    #[serde(default = "one")]
    radius: f32,
}

fn one() -> f32 {
    1.0
}

const DOCS: &[ParamDoc] = &[ParamDoc {
    name: "radius",
    ty: "pixels, 0.5–32",
    default: "1",
    doc: "Where the tent reaches zero.",
}];

pub(crate) fn register(registry: &mut Registry) {
    registry.register::<dyn Filter>(
        ModuleInfo {
            type_name: "tent",
            summary: "Tent (triangle) filter, separable.",
            params: DOCS,
        },
        |params, _| {
            let p: TentParams = params.parse()?;
            let radius = radius(params, "radius", p.radius)?;
            Ok(Box::new(Separable(TentKernel { radius })) as Box<dyn Filter>)
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
        check_param_docs::<TentParams>(DOCS).unwrap();
    }

    #[test]
    fn tent_values() {
        let t = Separable(TentKernel { radius: 2.0 });
        assert_eq!(t.eval(0.0, 0.0), 1.0);
        assert_eq!(t.eval(1.0, 0.0), 0.5);
        assert_eq!(t.eval(1.0, -1.5), 0.125);
        assert_eq!(t.eval(2.0, 0.0), 0.0);
    }
}
