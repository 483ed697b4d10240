//! Participating media: the `medium` and `phase` module kinds, and the
//! sampling maths of volumetric path tracing.
//!
//! A scene names its media under `media:`; shapes bound them (`interior:`,
//! `exterior:`), the camera may sit in one. Extract builds each medium and
//! its phase function through the [`crate::Registry`]; the engine's path
//! integrator then samples free-flight distances with [`free_flight`]
//! (hero-channel sampling with one-sample MIS over the three colour
//! channels, so chromatic media keep bounded weights), scatters with the
//! medium's [`Phase`], and weights shadow rays by [`transmittance`].
//! Media whose density varies give a [`Profile`]: exponential height fog
//! in closed form ([`HeightProfile`], `height.rs`), or a density field
//! tracked against majorants ([`DensityField`], [`delta_track`],
//! [`ratio_track`], `tracking.rs`).
//! Everything here runs only for scenes whose effect set contains
//! [`crate::Effects::MEDIA`].

mod height;
mod tracking;

pub use height::HeightProfile;
pub use tracking::{DensityField, Stream, Tracked, delta_track, ratio_track};

use crate::{BsdfEval, BsdfSample, Rgb};
use glam::{Vec2, Vec3};
use std::f32::consts::PI;

/// Absorption and scattering coefficients (per unit length, per channel).
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct Coefficients {
    /// σa: absorption.
    pub sigma_a: Rgb,
    /// σs: scattering.
    pub sigma_s: Rgb,
    /// Le: emitted radiance, with source term σa·Le per unit length
    /// (pbrt-v4's convention: an optically thick emitter glows at Le).
    pub emission: Rgb,
}

impl Coefficients {
    /// σt = σa + σs: extinction.
    #[inline]
    pub fn sigma_t(&self) -> Rgb {
        self.sigma_a + self.sigma_s
    }
}

/// A participating medium. Built once per frame; the integrator reads its
/// coefficients and profile once per batch, not per ray.
pub trait Medium: Send + Sync {
    /// The medium's coefficients where its density is 1 (everywhere, for
    /// homogeneous media).
    fn coefficients(&self) -> Coefficients;
    /// How its density varies in space; its coefficients at p are the
    /// density at p times [`Medium::coefficients`].
    fn profile(&self) -> Profile<'_> {
        Profile::Uniform
    }
    /// The medium's GPU side (`medium_flight_T`, `medium_transmittance_T`,
    /// see [`crate::gpu`]), if it has one.
    fn gpu(&self) -> Option<crate::GpuModule> {
        None
    }
}

/// The spatial variation of a medium's density.
#[derive(Clone, Copy)]
pub enum Profile<'a> {
    /// Density 1 everywhere: free flights and transmittance in closed form.
    Uniform,
    /// Exponential in height: closed forms along rays.
    Height(HeightProfile),
    /// A field tracked against its majorants.
    Field(&'a dyn DensityField),
}

/// A phase function: the angular distribution of scattering in a medium.
/// Directions may be given in any frame (phase functions depend only on
/// the angle between them); `wo` points away from the scattering point,
/// back along the path, as a surface's outgoing direction does.
pub trait Phase: Send + Sync {
    /// Samples an incident direction for each `wo[i]` from `u[i]`; the
    /// weight is p/pdf and `pdf` the solid-angle density.
    fn sample(&self, wo: &[Vec3], u: &[Vec2], out: &mut [BsdfSample]);
    /// Evaluates the phase function (`value`, the same in every channel)
    /// and the density `sample` has for `wi[i]`.
    fn eval(&self, wo: &[Vec3], wi: &[Vec3], out: &mut [BsdfEval]);
    /// The phase function's GPU side (`phase_sample_T`, `phase_eval_T`,
    /// see [`crate::gpu`]), if it has one.
    fn gpu(&self) -> Option<crate::GpuModule> {
        None
    }
}

/// The isotropic phase function's value, 1/4π.
pub const ISOTROPIC: f32 = 1.0 / (4.0 * PI);

/// The Henyey–Greenstein phase function at cos θ = wo·wi (`wo` pointing
/// away from the scattering point, so g > 0 scatters forward, towards
/// wi ≈ −wo), pbrt-v4's convention.
#[inline]
pub fn henyey_greenstein(cos_theta: f32, g: f32) -> f32 {
    let denom = 1.0 + g * g + 2.0 * g * cos_theta;
    ISOTROPIC * (1.0 - g * g) / (denom * denom.max(0.0).sqrt())
}

/// Samples the Henyey–Greenstein phase function around `wo` by inverting
/// its CDF in cos θ (pbrt-v4's `SampleHenyeyGreenstein`); returns the
/// direction wi and its density (equal to the phase value).
pub fn sample_henyey_greenstein(wo: Vec3, g: f32, u: Vec2) -> (Vec3, f32) {
    let cos_theta = if g.abs() < 1e-3 {
        1.0 - 2.0 * u.x
    } else {
        // In f64: near |g| = 1 the f32 form loses the tail of the lobe.
        let (g, u0) = (f64::from(g), f64::from(u.x));
        let s = (1.0 - g * g) / (1.0 + g - 2.0 * g * u0);
        (-(1.0 + g * g - s * s) / (2.0 * g)) as f32
    }
    .clamp(-1.0, 1.0);
    let sin_theta = (1.0 - cos_theta * cos_theta).max(0.0).sqrt();
    let phi = 2.0 * PI * u.y;
    let frame = crate::Frame::from_normal(wo);
    let wi = frame.to_world(Vec3::new(
        sin_theta * phi.cos(),
        sin_theta * phi.sin(),
        cos_theta,
    ));
    (wi, henyey_greenstein(cos_theta, g))
}

/// One free-flight sample along a ray segment of length `t_max` in a
/// homogeneous medium.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct FreeFlight {
    /// Distance of the sampled interaction, or `t_max` where the ray
    /// passes.
    pub t: f32,
    /// Whether the ray interacts with the medium at `t` (else it reaches
    /// the end of the segment); an interaction also gathers the medium's
    /// emission, σa·Le times `weight` (the collision estimator).
    pub scattered: bool,
    /// The throughput factor: T(t)/pdf(t) for an interaction (the caller
    /// multiplies by σs and samples the phase function), T(t_max)/P(pass)
    /// where the ray passes.
    pub weight: Rgb,
}

/// Samples a free-flight distance through a homogeneous medium of
/// extinction `sigma_t` (per channel) over a segment of length `t_max`
/// (`f32::INFINITY` where the ray leaves the scene).
///
/// Chromatic media: the distance is drawn from the exponential of one
/// channel chosen uniformly by `u_channel` (the hero channel), and weighted
/// by the one-sample balance heuristic over the three channels — the
/// density is the average of the three channels' densities — so the weight
/// stays bounded however different the channels are (Miller et al. 2019,
/// Mitsuba 3's `volpathmis`, pbrt-v4's hero-wavelength ratios).
pub fn free_flight(sigma_t: Rgb, u_channel: f32, u: f32, t_max: f32) -> FreeFlight {
    let channel = ((u_channel * 3.0) as usize).min(2);
    let s = sigma_t[channel];
    let t = if s > 0.0 {
        // 1 − u in (0, 1]: the logarithm is finite.
        -(1.0 - u).ln() / s
    } else {
        f32::INFINITY
    };
    if t < t_max {
        let tr = transmittance(sigma_t, t);
        let pdf = (sigma_t * tr).element_sum() / 3.0;
        FreeFlight {
            t,
            scattered: true,
            weight: if pdf > 0.0 { tr / pdf } else { Rgb::ZERO },
        }
    } else {
        let tr = transmittance(sigma_t, t_max);
        let pass = tr.element_sum() / 3.0;
        FreeFlight {
            t: t_max,
            scattered: false,
            weight: if pass > 0.0 { tr / pass } else { Rgb::ZERO },
        }
    }
}

/// Beer–Lambert transmittance exp(−σt·d) per channel; 0 at infinite
/// distance where σt > 0, 1 where σt = 0.
#[inline]
pub fn transmittance(sigma_t: Rgb, d: f32) -> Rgb {
    Rgb::new(beer(sigma_t.x, d), beer(sigma_t.y, d), beer(sigma_t.z, d))
}

#[inline]
fn beer(s: f32, d: f32) -> f32 {
    if s == 0.0 { 1.0 } else { (-s * d).exp() }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn henyey_greenstein_integrates_to_one() {
        for g in [-0.9f32, 0.0, 0.3, 0.99] {
            // ∫ p dω = 2π ∫ p(μ) dμ, midpoint rule in f64 over a fine grid.
            let n = 200_000;
            let sum: f64 = (0..n)
                .map(|i| {
                    let mu = -1.0 + (2.0 * i as f64 + 1.0) / n as f64;
                    f64::from(henyey_greenstein(mu as f32, g))
                })
                .sum();
            let integral = 2.0 * std::f64::consts::PI * sum * 2.0 / n as f64;
            assert!((integral - 1.0).abs() < 2e-3, "g = {g}: {integral}");
        }
    }

    #[test]
    fn free_flight_weights_are_one_for_grey_media() {
        let f = free_flight(Rgb::splat(2.0), 0.4, 0.3, 10.0);
        assert!(f.scattered);
        // T/pdf = 1/σt for a grey medium.
        assert!((f.weight - Rgb::splat(0.5)).abs().max_element() < 1e-6);
        let f = free_flight(Rgb::splat(2.0), 0.4, 0.3, 0.01);
        assert!(!f.scattered);
        assert!((f.weight - Rgb::ONE).abs().max_element() < 1e-6);
    }

    #[test]
    fn vacuum_channel_passes() {
        let f = free_flight(Rgb::new(0.0, 1.0, 1.0), 0.1, 0.5, f32::INFINITY);
        assert!(!f.scattered);
        // Only the σt = 0 channel survives an infinite segment.
        assert_eq!(f.weight, Rgb::new(3.0, 0.0, 0.0));
    }
}
