//! Helpers every shader author needs, public so that a module crate writes
//! its shaders as the built-in ones are written: texture-or-constant
//! parameters with range checks ([`fraction`], [`checked`]), the effects of
//! the textures a shader reads ([`texture_effects`]), and the sample of a
//! non-delta reflection lobe ([`reflection_sample`]).
//!
//! A shader's `build` resolves its inputs once (`fraction(ctx, &p.reflectance,
//! "reflectance")?`), keeps the [`TextureId`]s, looks the values up per batch
//! with [`ShadeContext::lookup`](crate::ShadeContext::lookup), and fills
//! each point's [`BsdfSample`] with [`reflection_sample`] (or
//! [`BsdfSample::default`] for a failed sample).

use crate::params::Spanned;
use crate::{BsdfSample, BuildContext, Effects, ParamError, Rgb, TextureId, TextureInput};
use glam::Vec3;

/// Resolves a texture-or-constant input (a number, `[r, g, b]` or the name
/// of a texture under `textures:`); constants must lie in `[min, max]` in
/// every channel, else the error names `name` and points at the value.
pub fn checked(
    ctx: &mut BuildContext<'_>,
    input: &Spanned<TextureInput>,
    name: &str,
    min: f32,
    max: f32,
) -> Result<TextureId, ParamError> {
    if let TextureInput::Value(v) = &**input
        && !(v.is_finite() && v.min_element() >= min && v.max_element() <= max)
    {
        return Err(ParamError::at(
            input.span(),
            format!("`{name}` must lie in [{min}, {max}], found {v}"),
        ));
    }
    ctx.texture(input)
}

/// Resolves a texture-or-constant input whose constants must lie in
/// [0, 1] (reflectances, weights, roughness).
pub fn fraction(
    ctx: &mut BuildContext<'_>,
    input: &Spanned<TextureInput>,
    name: &str,
) -> Result<TextureId, ParamError> {
    checked(ctx, input, name, 0.0, 1.0)
}

/// The effects of the textures `ids` (empty for constants): a shader adds
/// them to its own [`Shader::effects`](crate::Shader::effects).
pub fn texture_effects(ctx: &BuildContext<'_>, ids: &[TextureId]) -> Effects {
    ids.iter()
        .fold(Effects::empty(), |e, &id| e | ctx.textures.effects(id))
}

/// A non-delta reflection sample: incident direction `wi` (local frame,
/// `wi.z > 0`), `weight` = f · cos θi / pdf, and the solid-angle density
/// `pdf`; no change of medium (η = 1).
#[inline]
pub fn reflection_sample(wi: Vec3, weight: Rgb, pdf: f32) -> BsdfSample {
    BsdfSample {
        wi,
        weight,
        pdf,
        delta: false,
        eta: 1.0,
    }
}
