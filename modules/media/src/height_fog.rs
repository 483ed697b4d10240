//! The `height_fog` medium: seed 000's exponential height fog. Its density
//! is ρ(p) = exp(−(up·p − height)/scale_height) times the coefficients
//! written (so σa, σs or `density` are the values at the reference
//! height); distance sampling and transmittance use the closed form of its
//! integral along rays ([`HeightProfile`]), so they are exact.

use crate::coefficients::{medium_docs, medium_params};
use radiant_core::glam::DVec3;
use radiant_core::medium::HeightProfile;
use radiant_core::params::Spanned;
use radiant_core::{
    BuildContext, Coefficients, GpuModule, GpuParams, Medium, Numbers, ParamDoc, ParamError,
    Params, Profile, Registry,
};

medium_params!(HeightFogParams {
    up: Option<Spanned<Numbers<3>>>,
    height: Option<Spanned<f64>>,
    scale_height: Option<Spanned<f64>>,
});

const DOCS: &[ParamDoc] = medium_docs!(
    "Extinction σt at the reference `height` (with `albedo`).",
    ParamDoc {
        name: "up",
        ty: "[x, y, z], non-zero",
        default: "[0, 1, 0]",
        doc: "The direction in which the density falls (world space).",
    },
    ParamDoc {
        name: "height",
        ty: "number",
        default: "0",
        doc: "The reference height h0 (along `up`, world space) where the coefficients are as written.",
    },
    ParamDoc {
        name: "scale_height",
        ty: "number, > 0",
        default: "1",
        doc: "H: the density falls by a factor e every H upwards, ρ = exp(−(h − h0)/H).",
    },
);

/// Exponential height fog (seed 000's fog).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct HeightFog {
    coefficients: Coefficients,
    profile: HeightProfile,
}

impl Medium for HeightFog {
    fn coefficients(&self) -> Coefficients {
        self.coefficients
    }

    fn profile(&self) -> Profile<'_> {
        Profile::Height(self.profile)
    }

    fn gpu(&self) -> Option<GpuModule> {
        let h = &self.profile;
        Some(crate::gpu::medium(
            "height_fog",
            include_str!("height_fog.wgsl"),
            &self.coefficients,
            GpuParams::new()
                .vec3(h.up)
                .f32(h.h0 as f32)
                .f32(h.scale_height as f32),
        ))
    }
}

fn build(params: &Params, ctx: &mut BuildContext<'_>) -> Result<HeightFog, ParamError> {
    let p: HeightFogParams = params.parse()?;
    let coefficients = p.shared().coefficients()?;
    let up = match &p.up {
        None => DVec3::Y,
        Some(u) => {
            let v = DVec3::from_array(u.0);
            if !v.is_finite() || v.length() == 0.0 {
                return Err(ParamError::at(
                    u.span(),
                    format!("`up` must be a finite, non-zero direction, found {v}"),
                ));
            }
            v.normalize()
        }
    };
    let height = match &p.height {
        None => 0.0,
        Some(h) if h.is_finite() => **h,
        Some(h) => {
            return Err(ParamError::at(
                h.span(),
                format!("`height` must be a finite number, found {}", **h),
            ));
        }
    };
    let scale_height = match &p.scale_height {
        None => 1.0,
        Some(h) if h.is_finite() && **h > 0.0 => **h,
        Some(h) => {
            return Err(ParamError::at(
                h.span(),
                format!("`scale_height` must be a finite number > 0, found {}", **h),
            ));
        }
    };
    // Render space is world space translated by −render_origin.
    let h0 = height - up.dot(ctx.render_origin);
    Ok(HeightFog {
        coefficients,
        profile: HeightProfile {
            up: up.as_vec3(),
            h0,
            rho0: 1.0,
            scale_height,
        },
    })
}

pub(crate) fn register(registry: &mut Registry) {
    let info = crate::medium_info(
        "height_fog",
        "Fog whose density falls exponentially with height (exact distance sampling and transmittance); its `phase:` as for `homogeneous`.",
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
        check_param_docs::<HeightFogParams>(DOCS).unwrap();
    }

    #[test]
    fn the_profile_is_placed_in_render_space() {
        let params = Params::from_yaml("density: 2\nheight: 3\nup: [0, 0, 2]\n").unwrap();
        let fog = crate::build_standalone(|ctx| {
            ctx.render_origin = DVec3::new(0.0, 0.0, 1.0);
            build(&params, ctx)
        })
        .unwrap();
        // World height 3 is render height 2 along +z.
        assert!((fog.profile.h0 - 2.0).abs() < 1e-12);
        assert!(
            (fog.profile
                .density(radiant_core::glam::Vec3::new(0.0, 0.0, 2.0))
                - 1.0)
                .abs()
                < 1e-6
        );
        assert_eq!(fog.coefficients.sigma_t(), radiant_core::Rgb::splat(2.0));
    }

    #[test]
    fn bad_parameters_are_located() {
        crate::assert_located_errors(
            build,
            &[
                ("scale_height: 0\n", "scale_height"),
                ("scale_height: -2\n", "scale_height"),
                ("up: [0, 0, 0]\n", "up"),
                ("height: .inf\n", "height"),
                ("density: -1\n", "density"),
            ],
        );
    }
}
