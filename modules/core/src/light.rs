//! Lights: next-event estimation samples and emitted radiance at hits.
//!
//! The engine picks a light per path vertex (in proportion to
//! [`Light::power`]), groups the vertices by light and calls
//! [`Light::sample`] once per group. Rays that hit an emissive surface are
//! likewise grouped and passed to [`Light::eval_hits`], which returns the
//! emitted radiance and the density with which `sample` would have produced
//! that point, for multiple importance sampling. Rays that leave the scene
//! are passed, per light whose effects contain [`Effects::ENVIRONMENT`], to
//! [`Light::eval_escaped`].
//!
//! Lights infinitely far away (environment, directional) place their
//! next-event sample points outside the scene's bounding sphere
//! ([`BuildContext::scene_sphere`](crate::BuildContext::scene_sphere)):
//! `p = reference + direction · 2r`, with `n = 0`.

use crate::{Effects, GpuModule, Rgb};
use glam::{Vec2, Vec3};

/// One light sample as seen from a reference point.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct LightSample {
    /// The sampled point on the light, in render space.
    pub p: Vec3,
    /// Unit surface normal at `p` (zero for point-like lights).
    pub n: Vec3,
    /// Radiance arriving at the reference point from `p`, before division by
    /// `pdf` (for delta lights: intensity / distance²).
    pub radiance: Rgb,
    /// Density of `p` in solid angle at the reference point (1 for delta
    /// lights; 0 marks a failed sample).
    pub pdf: f32,
}

/// A ray that hit a surface emitter, as handed to [`Light::eval_hits`].
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct EmitterHit {
    /// Where the ray started (the previous path vertex).
    pub origin: Vec3,
    /// The hit point.
    pub p: Vec3,
    /// Unit geometric normal at the hit point.
    pub n: Vec3,
    /// Index of the hit primitive within the emitter's [`EmitterShape`](crate::EmitterShape).
    pub primitive: u32,
}

/// The answer of [`Light::eval_hits`] for one hit.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct EmitterEval {
    /// Radiance emitted from the hit point towards the ray origin.
    pub radiance: Rgb,
    /// Density in solid angle with which [`Light::sample`] picks this point
    /// from the ray origin.
    pub pdf: f32,
}

/// A light module.
pub trait Light: Send + Sync {
    /// Total emitted power (a scalar proxy, e.g. luminance × area × π for a
    /// diffuse area light); light selection is proportional to it.
    fn power(&self) -> f32;

    /// Whether the light's emission is a delta distribution (cannot be hit).
    fn is_delta(&self) -> bool;

    /// Samples a point on the light for each reference point `refs[i]`
    /// (render space) with the 2D sample `u[i]`, writing every `out[i]`
    /// (`out` is not cleared between batches; a failed sample is
    /// [`LightSample::default`], pdf 0). A surface light's `n` is its
    /// emitting side's normal: it emits towards `refs[i]` where
    /// `n · (refs[i] − p) > 0`.
    fn sample(&self, refs: &[Vec3], u: &[Vec2], out: &mut [LightSample]);

    /// Evaluates emission for rays that hit this light's surface. Lights
    /// without surfaces are never hit, so the default writes nothing.
    fn eval_hits(&self, hits: &[EmitterHit], out: &mut [EmitterEval]) {
        out[..hits.len()].fill(EmitterEval::default());
    }

    /// Evaluates emission for rays that left the scene in the unit
    /// directions `dirs` (render space): the radiance arriving along `-dirs[i]`
    /// and the solid-angle density with which [`sample`](Self::sample) picks
    /// that direction. Only lights whose effects contain
    /// [`Effects::ENVIRONMENT`] are asked; the default writes zeros.
    fn eval_escaped(&self, dirs: &[Vec3], out: &mut [EmitterEval]) {
        out[..dirs.len()].fill(EmitterEval::default());
    }

    /// Where the light is and where it emits, for selection that weighs
    /// lights by their importance at the shading point
    /// (`light_selection: spatial`). `None` (the default) for lights at
    /// infinity and lights that do not say: spatial selection then gives
    /// them a fixed share of the samples.
    fn bounds(&self) -> Option<crate::LightBounds> {
        None
    }

    /// The light's GPU side (see [`crate::gpu`]), `None` where the type has
    /// none.
    fn gpu(&self) -> Option<GpuModule> {
        None
    }
    /// Effects this light needs.
    fn effects(&self) -> Effects;
}
