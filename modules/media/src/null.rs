//! The `null` material: an index-matched boundary that only bounds a
//! medium. Rays go straight through it (the continuation keeps its
//! direction, with weight 1, as a delta lobe), and shadow rays pass it,
//! weighted by the transmittance of the media on either side; it reflects
//! nothing and is never lit.

use radiant_core::glam::Vec3;
use radiant_core::{
    BsdfEval, BsdfSample, BuildContext, Effects, GpuModule, GpuParams, ModuleInfo, ParamError,
    Params, Registry, Rgb, ShadeContext, Shader, SurfaceBatch,
};
use serde::Deserialize;

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct NullParams {}

/// The pass-through boundary (Mitsuba 3's `null` BSDF).
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct Null;

impl Shader for Null {
    fn sample(
        &self,
        _ctx: &mut ShadeContext<'_>,
        surface: SurfaceBatch<'_>,
        _u: &[Vec3],
        out: &mut [BsdfSample],
    ) {
        for (wo, o) in surface.wo.iter().zip(out.iter_mut()) {
            *o = BsdfSample {
                wi: -*wo,
                weight: Rgb::ONE,
                pdf: 1.0,
                delta: true,
                eta: 1.0,
            };
        }
    }

    fn eval(
        &self,
        _ctx: &mut ShadeContext<'_>,
        _surface: SurfaceBatch<'_>,
        _wi: &[Vec3],
        out: &mut [BsdfEval],
    ) {
        out.fill(BsdfEval::default());
    }

    fn effects(&self) -> Effects {
        Effects::DELTA_LOBES | Effects::TRANSMISSION | Effects::NULL_INTERFACE
    }

    fn gpu(&self) -> Option<GpuModule> {
        Some(GpuModule::new(
            "null",
            include_str!("null.wgsl"),
            GpuParams::new(),
        ))
    }
}

pub(crate) fn register(registry: &mut Registry) {
    registry.register::<dyn Shader>(
        ModuleInfo {
            type_name: "null",
            summary: "Index-matched boundary of a medium: rays and shadow rays pass straight through.",
            params: &[],
        },
        |params: &Params, _ctx: &mut BuildContext<'_>| -> Result<Box<dyn Shader>, ParamError> {
            params.parse::<NullParams>()?;
            Ok(Box::new(Null))
        },
    );
}

#[cfg(test)]
mod tests {
    // `unwrap` in this test code is the assertion: the parameters are the test's own, so a failure is a bug,
    // and the panic reports it.
    use super::*;
    use radiant_core::params::check_param_docs;

    #[test]
    fn no_parameters() {
        check_param_docs::<NullParams>(&[]).unwrap();
    }
}
