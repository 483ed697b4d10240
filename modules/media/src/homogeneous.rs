//! The `homogeneous` medium: the same σa and σs everywhere.

use crate::coefficients::{medium_docs, medium_params};
use radiant_core::{
    BuildContext, Coefficients, GpuModule, GpuParams, Medium, ParamDoc, ParamError, Params,
    Registry, Rgb,
};

medium_params!(HomogeneousParams {});

const DOCS: &[ParamDoc] = medium_docs!("Extinction σt (with `albedo`).");

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

    fn gpu(&self) -> Option<GpuModule> {
        Some(crate::gpu::medium(
            "homogeneous",
            include_str!("homogeneous.wgsl"),
            &self.coefficients,
            GpuParams::new(),
        ))
    }
}

fn build(params: &Params, _ctx: &mut BuildContext<'_>) -> Result<Homogeneous, ParamError> {
    let p: HomogeneousParams = params.parse()?;
    let c = p.shared().coefficients()?;
    Ok(Homogeneous::new(c.sigma_a, c.sigma_s, c.emission))
}

pub(crate) fn register(registry: &mut Registry) {
    let info = crate::medium_info(
        "homogeneous",
        "Constant absorption and scattering; its `phase:` (a phase module, default isotropic) sets the scattering's angular distribution.",
        DOCS,
    );
    crate::register_medium(registry, info, build);
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

    #[test]
    fn albedo_and_density_give_coefficients() {
        let m = crate::built("albedo: 0.75\ndensity: 2\nscale: 2\n", build).unwrap();
        let c = m.coefficients();
        assert_eq!(c.sigma_s, Rgb::splat(3.0));
        assert_eq!(c.sigma_a, Rgb::splat(1.0));
    }

    #[test]
    fn bad_coefficients_are_located() {
        crate::assert_located_errors(
            build,
            &[
                ("sigma_s: [1, -1, 1]\n", "sigma_s"),
                ("sigma_a: .nan\n", "sigma_a"),
                ("albedo: 1.5\n", "albedo"),
                ("density: .inf\n", "density"),
                ("scale: -1\nsigma_s: 1\n", "scale"),
                ("sigma_s: 1\nalbedo: 0.5\n", "not both"),
            ],
        );
    }
}
