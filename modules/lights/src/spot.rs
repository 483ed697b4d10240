//! The `spot` light: a point source emitting into a cone, with Mitsuba 3's
//! falloff (full intensity inside `beam_width`, then linear in angle down
//! to zero at `cutoff_angle`).

use crate::delta::sample_delta;
use crate::params::{axis, check_colour, place};
use radiant_core::glam::{DVec3, Vec2, Vec3};
use radiant_core::{
    BuildContext, Color, Effects, GpuModule, GpuParams, Light, LightBounds, LightSample, Numbers,
    ParamDoc, ParamError, Params, Registry, Rgb, luminance,
};
use serde::Deserialize;

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct SpotParams {
    #[serde(default)]
    position: Numbers<3>,
    direction: Option<Numbers<3>>,
    target: Option<Numbers<3>>,
    intensity: Color,
    #[serde(default = "default_cutoff")]
    cutoff_angle: f32,
    beam_width: Option<f32>,
}

fn default_cutoff() -> f32 {
    20.0
}

const DOCS: &[ParamDoc] = &[
    ParamDoc {
        name: "position",
        ty: "[x, y, z], world space",
        default: "[0, 0, 0]",
        doc: "Where the light is (moved by the light's `transform`).",
    },
    ParamDoc {
        name: "direction",
        ty: "[x, y, z]",
        default: "[0, 0, 1]",
        doc: "Axis of the cone (turned by the light's `transform`); give this or `target`.",
    },
    ParamDoc {
        name: "target",
        ty: "[x, y, z], world space",
        default: "none",
        doc: "A point on the cone's axis, instead of `direction`.",
    },
    ParamDoc {
        name: "intensity",
        ty: "rgb, W/sr",
        default: "required",
        doc: "Radiant intensity along the axis.",
    },
    ParamDoc {
        name: "cutoff_angle",
        ty: "degrees, (0, 180]",
        default: "20",
        doc: "Half-angle of the cone; nothing is emitted outside it.",
    },
    ParamDoc {
        name: "beam_width",
        ty: "degrees, [0, cutoff_angle]",
        default: "3/4 × cutoff_angle",
        doc: "Half-angle of full intensity; from there to the cutoff the intensity falls linearly in angle.",
    },
];

/// A spot light: a point source whose intensity depends on the angle θ to
/// its axis as Mitsuba 3's `spot`: 1 for θ ≤ beam width, (cutoff − θ) /
/// (cutoff − beam width) up to the cutoff, 0 beyond.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SpotLight {
    position: Vec3,
    axis: Vec3,
    intensity: Rgb,
    cutoff: f32,
    beam: f32,
    cos_cutoff: f32,
    cos_beam: f32,
}

impl SpotLight {
    /// A spot light at `position` (render space) pointing along the unit
    /// vector `axis`; angles in radians, `0 ≤ beam ≤ cutoff ≤ π`.
    pub fn new(position: Vec3, axis: Vec3, intensity: Rgb, cutoff: f32, beam: f32) -> Self {
        Self {
            position,
            axis,
            intensity,
            cutoff,
            beam,
            cos_cutoff: cutoff.cos(),
            cos_beam: beam.cos(),
        }
    }

    /// The intensity factor at cos θ to the axis.
    #[inline]
    pub fn falloff(&self, cos_theta: f32) -> f32 {
        if cos_theta <= self.cos_cutoff {
            0.0
        } else if cos_theta >= self.cos_beam {
            1.0
        } else {
            ((self.cutoff - cos_theta.clamp(-1.0, 1.0).acos()) / (self.cutoff - self.beam))
                .clamp(0.0, 1.0)
        }
    }

    /// ∫ falloff dω over the sphere, in closed form: 2π (1 + (sin β − sin c)
    /// / (c − β)) for beam width β < cutoff c, 2π (1 − cos c) for β = c.
    pub fn falloff_integral(&self) -> f32 {
        let (c, b) = (self.cutoff as f64, self.beam as f64);
        let f = if c - b > 1e-6 {
            1.0 + (b.sin() - c.sin()) / (c - b)
        } else {
            1.0 - c.cos()
        };
        (std::f64::consts::TAU * f) as f32
    }
}

impl Light for SpotLight {
    fn power(&self) -> f32 {
        luminance(self.intensity) * self.falloff_integral()
    }

    fn bounds(&self) -> Option<LightBounds> {
        // Full intensity within the beam, falling off over cutoff − beam.
        Some(LightBounds::point(
            self.position,
            luminance(self.intensity),
            self.axis,
            self.cos_beam,
            (self.cutoff - self.beam).cos(),
        ))
    }

    fn is_delta(&self) -> bool {
        true
    }

    fn uses_point_samples(&self) -> bool {
        false
    }

    fn sample(&self, refs: &[Vec3], _u: &[Vec2], out: &mut [LightSample]) {
        sample_delta(refs, out, |r| {
            let d = r - self.position;
            let dist2 = d.length_squared();
            let radiance = if dist2 > 0.0 {
                self.intensity * (self.falloff(self.axis.dot(d) / dist2.sqrt()) / dist2)
            } else {
                Rgb::ZERO
            };
            (self.position, radiance)
        });
    }

    fn effects(&self) -> Effects {
        Effects::DELTA_LIGHTS
    }

    fn emission(&self) -> Option<&dyn radiant_core::Emission> {
        Some(self)
    }

    fn gpu(&self) -> Option<GpuModule> {
        let params = GpuParams::new()
            .vec3(self.position)
            .vec3(self.axis)
            .rgb(self.intensity)
            .f32s([self.cutoff, self.beam, self.cos_cutoff, self.cos_beam]);
        Some(GpuModule::new("spot", include_str!("spot.wgsl"), params))
    }
}

/// Emitted rays: from the light's position, uniformly over the cone of
/// `cutoff_angle`, carrying the falloff.
impl radiant_core::Emission for SpotLight {
    fn kind(&self) -> radiant_core::EmissionKind {
        radiant_core::EmissionKind::Point
    }

    fn sample_emission(
        &self,
        _u_pos: &[Vec2],
        u_dir: &[Vec2],
        out: &mut [radiant_core::EmissionSample],
    ) {
        let frame = radiant_core::Frame::from_normal(self.axis);
        let pdf_dir = 1.0 / (std::f32::consts::TAU * (1.0 - self.cos_cutoff));
        for (u, o) in u_dir.iter().zip(out.iter_mut()) {
            let cos = 1.0 - u.x * (1.0 - self.cos_cutoff);
            let sin = (1.0 - cos * cos).max(0.0).sqrt();
            let (s, c) = (std::f32::consts::TAU * u.y).sin_cos();
            *o = radiant_core::EmissionSample {
                p: self.position,
                n: Vec3::ZERO,
                dir: frame.to_world(Vec3::new(sin * c, sin * s, cos)),
                radiance: self.intensity * self.falloff(cos),
                pdf_pos: 1.0,
                pdf_dir,
                kind: radiant_core::EmissionKind::Point,
                primitive: 0,
            };
        }
    }

    fn emission_pdf(
        &self,
        rays: &[radiant_core::EmittedRay],
        out: &mut [radiant_core::EmissionPdf],
    ) {
        let pdf_dir = 1.0 / (std::f32::consts::TAU * (1.0 - self.cos_cutoff));
        for (r, o) in rays.iter().zip(out.iter_mut()) {
            let inside = r.dir.dot(self.axis) > self.cos_cutoff;
            *o = radiant_core::EmissionPdf {
                pdf_pos: 1.0,
                pdf_dir: if inside { pdf_dir } else { 0.0 },
            };
        }
    }
}

fn build(params: &Params, ctx: &mut BuildContext<'_>) -> Result<SpotLight, ParamError> {
    let p: SpotParams = params.parse()?;
    check_colour(params, "intensity", p.intensity.0)?;
    let cutoff = p.cutoff_angle;
    if !(cutoff > 0.0 && cutoff <= 180.0) {
        return Err(ParamError {
            message: format!("`cutoff_angle` must be in (0, 180] degrees, found {cutoff}"),
            location: params.location_of("cutoff_angle"),
        });
    }
    let beam = p.beam_width.unwrap_or(0.75 * cutoff);
    if !(0.0..=cutoff).contains(&beam) {
        return Err(ParamError {
            message: format!(
                "`beam_width` must be in [0, cutoff_angle = {cutoff}] degrees, found {beam}"
            ),
            location: params.location_of("beam_width"),
        });
    }
    let position = DVec3::from(p.position);
    let axis = axis(params, ctx, position, p.direction, p.target)?;
    Ok(SpotLight::new(
        place(ctx, position),
        axis,
        p.intensity.0,
        cutoff.to_radians(),
        beam.to_radians(),
    ))
}

pub(crate) fn register(registry: &mut Registry) {
    crate::register_light(
        registry,
        "spot",
        "Point light emitting into a cone, with Mitsuba 3's linear angular falloff.",
        DOCS,
        build,
    );
}

#[cfg(test)]
mod tests {
    // `unwrap` in this test code is the assertion: the inputs are the test's
    // own, so a failure is a bug, and the panic reports it with the error.
    use super::*;
    use radiant_core::params::check_param_docs;

    fn spot(cutoff_deg: f32, beam_deg: f32) -> SpotLight {
        SpotLight::new(
            Vec3::ZERO,
            Vec3::Z,
            Rgb::splat(2.0),
            cutoff_deg.to_radians(),
            beam_deg.to_radians(),
        )
    }

    #[test]
    fn documented_parameters_match() {
        check_param_docs::<SpotParams>(DOCS).unwrap();
    }

    #[test]
    fn falloff_at_known_angles() {
        // Cutoff 40°, beam 20°: full up to 20°, half at 30°, a quarter at
        // 35°, zero from 40° on (Mitsuba 3's spot).
        let s = spot(40.0, 20.0);
        let at = |deg: f32| s.falloff(deg.to_radians().cos());
        assert_eq!(at(0.0), 1.0);
        assert_eq!(at(19.9), 1.0);
        assert!((at(30.0) - 0.5).abs() < 1e-4, "{}", at(30.0));
        assert!((at(35.0) - 0.25).abs() < 1e-4, "{}", at(35.0));
        assert!(at(39.99) < 1e-3);
        assert_eq!(at(40.01), 0.0);
        assert_eq!(at(120.0), 0.0);
    }

    #[test]
    fn sample_gives_intensity_times_falloff_over_distance_squared() {
        let s = spot(40.0, 20.0);
        let dir = Vec3::new(30f32.to_radians().sin(), 0.0, 30f32.to_radians().cos());
        let mut out = [LightSample::default(); 3];
        let refs = [Vec3::Z * 2.0, dir * 2.0, -Vec3::Z];
        s.sample(&refs, &[Vec2::ZERO; 3], &mut out);
        assert_eq!(out[0].radiance, Rgb::splat(0.5));
        assert!((out[1].radiance - Rgb::splat(0.25)).abs().max_element() < 1e-4);
        assert_eq!(out[2].radiance, Rgb::ZERO);
        assert!(out.iter().all(|o| o.pdf == 1.0 && o.p == Vec3::ZERO));
    }

    #[test]
    fn falloff_integral_matches_quadrature() {
        for (c, b) in [
            (40.0, 20.0),
            (20.0, 15.0),
            (90.0, 0.0),
            (30.0, 30.0),
            (180.0, 90.0),
        ] {
            let s = spot(c, b);
            let n = 200_000;
            let mut sum = 0.0f64;
            for i in 0..n {
                // ∫ f dω = 2π ∫ f(cos θ) d(cos θ), midpoint rule in cos θ.
                let z = -1.0 + 2.0 * (i as f64 + 0.5) / n as f64;
                sum += s.falloff(z as f32) as f64 * 2.0 / n as f64;
            }
            let quad = std::f64::consts::TAU * sum;
            let closed = s.falloff_integral() as f64;
            assert!(
                (quad - closed).abs() < 1e-4 * closed.max(1e-3),
                "{c}/{b}: {quad} vs {closed}"
            );
        }
        assert!(
            (spot(40.0, 20.0).power() - 2.0 * spot(40.0, 20.0).falloff_integral()).abs() < 1e-5
        );
    }
}
