//! Phase functions: `isotropic` and `hg` (Henyey–Greenstein).

use radiant_core::glam::{Vec2, Vec3};
use radiant_core::medium::{ISOTROPIC, henyey_greenstein, sample_henyey_greenstein};
use radiant_core::params::Spanned;
use radiant_core::warp::square_to_uniform_sphere;
use radiant_core::{
    BsdfEval, BsdfSample, BuildContext, GpuModule, GpuParams, ModuleInfo, ParamDoc, ParamError,
    Params, Phase, Registry, Rgb,
};
use serde::Deserialize;

/// Scattering equally in all directions.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct Isotropic;

/// A phase sample of weight 1 (the density equals the value).
fn exact(wi: Vec3, pdf: f32) -> BsdfSample {
    BsdfSample {
        wi,
        weight: Rgb::ONE,
        pdf,
        delta: false,
        eta: 1.0,
    }
}

impl Phase for Isotropic {
    fn sample(&self, _wo: &[Vec3], u: &[Vec2], out: &mut [BsdfSample]) {
        for (u, o) in u.iter().zip(out.iter_mut()) {
            *o = exact(square_to_uniform_sphere(*u), ISOTROPIC);
        }
    }

    fn eval(&self, _wo: &[Vec3], _wi: &[Vec3], out: &mut [BsdfEval]) {
        out.fill(BsdfEval {
            value: Rgb::splat(ISOTROPIC),
            pdf: ISOTROPIC,
        });
    }

    fn gpu(&self) -> Option<GpuModule> {
        Some(GpuModule::new(
            "isotropic",
            include_str!("isotropic.wgsl"),
            GpuParams::new(),
        ))
    }
}

/// The Henyey–Greenstein phase function of asymmetry `g` in (−1, 1):
/// g > 0 scatters forward, g < 0 backward, 0 is isotropic.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct HenyeyGreenstein {
    g: f32,
}

impl HenyeyGreenstein {
    /// The phase function of asymmetry `g` (the caller checks the range).
    pub fn new(g: f32) -> Self {
        Self { g }
    }
}

impl Phase for HenyeyGreenstein {
    fn sample(&self, wo: &[Vec3], u: &[Vec2], out: &mut [BsdfSample]) {
        for ((wo, u), o) in wo.iter().zip(u).zip(out.iter_mut()) {
            let (wi, pdf) = sample_henyey_greenstein(*wo, self.g, *u);
            *o = exact(wi, pdf);
        }
    }

    fn eval(&self, wo: &[Vec3], wi: &[Vec3], out: &mut [BsdfEval]) {
        for ((wo, wi), o) in wo.iter().zip(wi).zip(out.iter_mut()) {
            let p = henyey_greenstein(wo.dot(*wi), self.g);
            *o = BsdfEval {
                value: Rgb::splat(p),
                pdf: p,
            };
        }
    }

    fn gpu(&self) -> Option<GpuModule> {
        Some(GpuModule::new(
            "hg",
            include_str!("hg.wgsl"),
            GpuParams::new().f32(self.g),
        ))
    }
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct IsotropicParams {}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct HgParams {
    g: Option<Spanned<f32>>,
}

const HG_DOCS: &[ParamDoc] = &[ParamDoc {
    name: "g",
    ty: "number, in (−1, 1)",
    default: "0.8",
    doc: "Mean cosine of the scattering angle: > 0 forward, < 0 backward.",
}];

fn build_hg(params: &Params, _ctx: &mut BuildContext<'_>) -> Result<HenyeyGreenstein, ParamError> {
    let p: HgParams = params.parse()?;
    let Some(g) = p.g else {
        // Mitsuba 3's default.
        return Ok(HenyeyGreenstein::new(0.8));
    };
    if !(g.is_finite() && *g > -1.0 && *g < 1.0) {
        return Err(ParamError::at(
            g.span(),
            format!("`g` must lie strictly between −1 and 1, found {}", *g),
        ));
    }
    Ok(HenyeyGreenstein::new(*g))
}

pub(crate) fn register(registry: &mut Registry) {
    registry.register::<dyn Phase>(
        ModuleInfo {
            type_name: "isotropic",
            summary: "Scatters equally in all directions (1/4π).",
            params: &[],
        },
        |params: &Params, _ctx| {
            params.parse::<IsotropicParams>()?;
            Ok(Box::new(Isotropic) as Box<dyn Phase>)
        },
    );
    registry.register::<dyn Phase>(
        ModuleInfo {
            type_name: "hg",
            summary: "Henyey–Greenstein, sampled exactly by inverting its CDF.",
            params: HG_DOCS,
        },
        |params: &Params, ctx| Ok(Box::new(build_hg(params, ctx)?) as Box<dyn Phase>),
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
        check_param_docs::<HgParams>(HG_DOCS).unwrap();
        check_param_docs::<IsotropicParams>(&[]).unwrap();
    }

    #[test]
    fn g_outside_the_open_interval_is_located() {
        for yaml in ["g: 1\n", "g: -1.5\n", "g: 1e39\n"] {
            // The test's own YAML text: it parses.
            let params = Params::from_yaml(yaml).unwrap();
            let e = crate::build_standalone(|ctx| build_hg(&params, ctx)).unwrap_err();
            assert!(e.message.contains("strictly between"), "{}", e.message);
            assert!(e.location.is_some());
        }
    }

    #[test]
    fn sample_agrees_with_eval() {
        let hg = HenyeyGreenstein::new(0.6);
        let wo = [Vec3::new(0.0, 0.6, 0.8); 16];
        let u: Vec<Vec2> = (0..16)
            .map(|i| Vec2::new((i as f32 + 0.5) / 16.0, 0.3))
            .collect();
        let mut s = [BsdfSample::default(); 16];
        hg.sample(&wo, &u, &mut s);
        let wi: Vec<Vec3> = s.iter().map(|s| s.wi).collect();
        let mut e = [BsdfEval::default(); 16];
        hg.eval(&wo, &wi, &mut e);
        for (s, e) in s.iter().zip(&e) {
            assert!((s.pdf - e.pdf).abs() <= 1e-4 * e.pdf, "{} {}", s.pdf, e.pdf);
            assert!((s.wi.length() - 1.0).abs() < 1e-5);
        }
    }
}
