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
//! Bidirectional integrators also start paths *at* lights: a light that
//! supports this answers [`Light::emission`] with its [`Emission`] side,
//! which samples emitted rays and gives the densities of a given one.
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

    /// Whether [`sample`](Self::sample) reads its 2D samples `u`. A light at
    /// one point or from one direction returns `false`, and the integrator
    /// then draws no samples for it (their contents are unspecified). The
    /// default, `true`, is always correct.
    fn uses_point_samples(&self) -> bool {
        true
    }

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

    /// The light's emission side, for light paths (bidirectional path
    /// tracing); `None` where the type has none, and integrators that need
    /// it refuse the scene, naming the light's type.
    fn emission(&self) -> Option<&dyn Emission> {
        None
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

/// Where an emitted ray's origin lies, which decides how its densities are
/// measured.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub enum EmissionKind {
    /// On a surface: `pdf_pos` per unit area, `pdf_dir` per unit solid
    /// angle, the ray carries `radiance · |n · dir| / (pdf_pos · pdf_dir)`.
    #[default]
    Surface,
    /// At one point (`point`, `spot`): the position is a delta
    /// (`pdf_pos` 1), `radiance` is the intensity (W/sr).
    Point,
    /// From infinitely far away (`environment`): the ray starts on a disc
    /// of the scene sphere's radius, perpendicular to `dir`, outside the
    /// scene; `pdf_pos` is per unit area of that disc, `pdf_dir` per unit
    /// solid angle, `n` is zero.
    Infinite,
    /// From infinitely far away along one direction (`directional`): the
    /// direction is a delta (`pdf_dir` 1), `radiance` is the irradiance
    /// (W/m²) and `pdf_pos` is per unit area of the disc.
    Directional,
}

/// One emitted ray, as [`Emission::sample_emission`] draws it.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct EmissionSample {
    /// The ray's origin, render space.
    pub p: Vec3,
    /// Unit surface normal at `p` on the emitting side (zero where there
    /// is no surface).
    pub n: Vec3,
    /// Unit direction of travel.
    pub dir: Vec3,
    /// Radiance along `dir` (see [`EmissionKind`] for point-like and
    /// directional lights), before division by the densities.
    pub radiance: Rgb,
    /// Density of `p` (see [`EmissionKind`]); 0 marks a failed sample.
    pub pdf_pos: f32,
    /// Density of `dir` given `p`, per unit solid angle (see
    /// [`EmissionKind`]).
    pub pdf_dir: f32,
    /// How the densities are measured.
    pub kind: EmissionKind,
    /// Index of the primitive `p` lies on within the emitter's shape (as
    /// in [`EmitterHit`]; 0 for lights without surfaces).
    pub primitive: u32,
}

/// An emitted ray whose densities [`Emission::emission_pdf`] is asked
/// for: a camera path that hit the light (`p` on its surface, `primitive`
/// as in [`EmitterHit`]) or left the scene towards it (`p` unused).
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct EmittedRay {
    /// The point the ray leaves, render space.
    pub p: Vec3,
    /// Unit geometric normal at `p` (zero for lights at infinity).
    pub n: Vec3,
    /// Unit direction of travel (from the light towards the scene).
    pub dir: Vec3,
    /// Index of the primitive within the emitter's shape.
    pub primitive: u32,
}

/// The densities of an [`EmittedRay`]: what [`Emission::sample_emission`]
/// would give for it.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct EmissionPdf {
    /// Density of the origin (as [`EmissionSample::pdf_pos`]).
    pub pdf_pos: f32,
    /// Density of the direction (as [`EmissionSample::pdf_dir`]).
    pub pdf_dir: f32,
}

/// The emission side of a light: emitted rays for light paths.
pub trait Emission: Send + Sync {
    /// How this light's emitted rays are measured (the same for all).
    fn kind(&self) -> EmissionKind;

    /// Samples one emitted ray per pair of 2D samples (`u_pos[i]` for the
    /// origin, `u_dir[i]` for the direction), writing every `out[i]`
    /// (`pdf_pos` 0 for a failed sample).
    fn sample_emission(&self, u_pos: &[Vec2], u_dir: &[Vec2], out: &mut [EmissionSample]);

    /// The densities with which `sample_emission` draws each ray `rays[i]`
    /// (0 where it never does), writing every `out[i]`. Delta
    /// distributions count as 1 (a point light's `pdf_pos`, a directional
    /// light's `pdf_dir`).
    fn emission_pdf(&self, rays: &[EmittedRay], out: &mut [EmissionPdf]);
}
