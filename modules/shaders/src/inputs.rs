//! Parameter helpers shared by the shaders: scalar inputs with range
//! checks, roughness (isotropic or anisotropic), and indices of refraction
//! given as numbers or by material name.

use radiant_core::params::Spanned;
use radiant_core::{BuildContext, Effects, ParamError, Rgb, TextureId, TextureInput};
use serde::Deserialize;
use serde::de::{self, Deserializer};

pub(crate) use radiant_core::shading::{checked, fraction, texture_effects};

/// [`Effects::TANGENT_FRAMES`] where the parameters along the shading
/// frame's two tangents, `u` and `v`, may differ (an anisotropic lobe);
/// empty where they are the same constant.
pub(crate) fn anisotropy(ctx: &BuildContext<'_>, u: TextureId, v: TextureId) -> Effects {
    let same = u == v || {
        let (a, b) = (ctx.textures.constant(u), ctx.textures.constant(v));
        a.is_some() && a == b
    };
    if same {
        Effects::empty()
    } else {
        Effects::TANGENT_FRAMES
    }
}

/// A scalar from a colour value: the mean of its channels.
#[inline]
pub(crate) fn scalar(c: Rgb) -> f32 {
    (c.x + c.y + c.z) * (1.0 / 3.0)
}

/// Roughness parameters as written: `alpha` or `alpha_u` and `alpha_v`.
struct RoughnessParams<'a> {
    alpha: &'a Option<Spanned<TextureInput>>,
    alpha_u: &'a Option<Spanned<TextureInput>>,
    alpha_v: &'a Option<Spanned<TextureInput>>,
}

/// Resolved roughness.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct Roughness {
    /// GGX α along local x.
    pub u: TextureId,
    /// GGX α along local y.
    pub v: TextureId,
    /// Both are the constant 0: the surface is smooth (a delta lobe).
    pub smooth: bool,
}

/// Documentation rows of the roughness parameters.
pub(crate) const ROUGHNESS_DOCS: [radiant_core::ParamDoc; 3] = [
    radiant_core::ParamDoc {
        name: "alpha",
        ty: "number | texture name, [0, 1] (GGX α = roughness²)",
        default: "0 (smooth)",
        doc: "Isotropic GGX roughness; 0 gives a perfectly smooth (delta) interface.",
    },
    radiant_core::ParamDoc {
        name: "alpha_u",
        ty: "number | texture name, [0, 1]",
        default: "alpha",
        doc: "Anisotropic GGX roughness along the shading frame's first tangent (with `alpha_v`; excludes `alpha`).",
    },
    radiant_core::ParamDoc {
        name: "alpha_v",
        ty: "number | texture name, [0, 1]",
        default: "alpha",
        doc: "Anisotropic GGX roughness along the second tangent (with `alpha_u`).",
    },
];

impl RoughnessParams<'_> {
    /// Resolves the roughness; both `alpha_u` and `alpha_v` must be given
    /// together, and not with `alpha`.
    fn resolve(&self, ctx: &mut BuildContext<'_>) -> Result<Roughness, ParamError> {
        let zero = TextureInput::spanned_value(Rgb::ZERO);
        let (u, v) = match (self.alpha, self.alpha_u, self.alpha_v) {
            (Some(a), None, None) => (a, a),
            (None, Some(u), Some(v)) => (u, v),
            (None, None, None) => (&zero, &zero),
            (Some(a), _, _) => {
                return Err(ParamError::at(
                    a.span(),
                    "give either `alpha` (isotropic) or both `alpha_u` and `alpha_v` (anisotropic), not both",
                ));
            }
            (None, Some(one), None) | (None, None, Some(one)) => {
                return Err(ParamError::at(
                    one.span(),
                    "anisotropic roughness needs both `alpha_u` and `alpha_v`",
                ));
            }
        };
        let smooth = matches!((&**u, &**v), (TextureInput::Value(a), TextureInput::Value(b)) if *a == Rgb::ZERO && *b == Rgb::ZERO);
        Ok(Roughness {
            u: fraction(ctx, u, "alpha")?,
            v: fraction(ctx, v, "alpha")?,
            smooth,
        })
    }
}

/// An index of refraction: a number or the name of a material in
/// Mitsuba 3's table.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct Ior(pub f32);

/// Named indices of refraction (Mitsuba 3's table).
pub(crate) const IOR_TABLE: &[(&str, f32)] = &[
    ("vacuum", 1.0),
    ("helium", 1.000036),
    ("hydrogen", 1.000132),
    ("air", 1.000277),
    ("carbon dioxide", 1.00045),
    ("water", 1.3330),
    ("acetone", 1.36),
    ("ethanol", 1.361),
    ("carbon tetrachloride", 1.461),
    ("glycerol", 1.4729),
    ("benzene", 1.501),
    ("silicone oil", 1.52045),
    ("bromine", 1.661),
    ("water ice", 1.31),
    ("fused quartz", 1.458),
    ("pyrex", 1.470),
    ("acrylic glass", 1.49),
    ("polypropylene", 1.49),
    ("bk7", 1.5046),
    ("sodium chloride", 1.544),
    ("amber", 1.55),
    ("pet", 1.5750),
    ("diamond", 2.419),
];

impl<'de> Deserialize<'de> for Ior {
    fn deserialize<D: Deserializer<'de>>(deserializer: D) -> Result<Self, D::Error> {
        let input = TextureInput::deserialize(deserializer)?;
        let value = match input {
            TextureInput::Value(v) if v.x == v.y && v.y == v.z => v.x,
            TextureInput::Value(_) => {
                return Err(de::Error::custom(
                    "an index of refraction is one number, not a colour",
                ));
            }
            TextureInput::Named(name) => IOR_TABLE
                .iter()
                .find(|(n, _)| n.eq_ignore_ascii_case(&name))
                .map(|&(_, v)| v)
                .ok_or_else(|| {
                    let names: Vec<&str> = IOR_TABLE.iter().map(|(n, _)| *n).collect();
                    de::Error::custom(format!(
                        "unknown material `{name}` for an index of refraction; expected a number ≥ 1 or one of: {}",
                        names.join(", ")
                    ))
                })?,
        };
        if !(value.is_finite() && value >= 1.0) {
            return Err(de::Error::custom(format!(
                "an index of refraction must be a finite number ≥ 1, found {value}"
            )));
        }
        Ok(Ior(value))
    }
}

/// Serde default of a texture input: the constant 0.
pub(crate) fn zero() -> Spanned<TextureInput> {
    TextureInput::spanned_value(Rgb::ZERO)
}

/// Serde default of a texture input: the constant 0.5.
pub(crate) fn half() -> Spanned<TextureInput> {
    TextureInput::spanned_value(Rgb::splat(0.5))
}

/// Serde default of a texture input: the constant 1.
pub(crate) fn one() -> Spanned<TextureInput> {
    TextureInput::spanned_value(Rgb::ONE)
}

/// Mitsuba 3's default interior index of glass (BK7).
pub(crate) const BK7: f32 = 1.5046;

/// Mitsuba 3's default exterior index (air).
fn air() -> Ior {
    Ior(1.000277)
}

/// The relative index int/ext (defaults: `default_int` inside, air
/// outside). An index-matched interface (η = 1) is allowed: it refracts
/// nothing and reflects nothing, so the surface vanishes (Mitsuba 3 refuses
/// it; an index animated towards 1 or a matched liquid is legitimate).
pub(crate) fn relative_ior(
    int: &Option<Spanned<Ior>>,
    ext: &Option<Spanned<Ior>>,
    default_int: f32,
) -> f32 {
    let i = int.as_ref().map_or(Ior(default_int), |s| **s);
    let e = ext.as_ref().map_or(air(), |s| **s);
    i.0 / e.0
}

/// Resolves the roughness keys of a shader's parameters (serde's `flatten`
/// does not combine with `deny_unknown_fields`, so shaders list the three
/// keys themselves and call this).
pub(crate) fn roughness(
    alpha: &Option<Spanned<TextureInput>>,
    alpha_u: &Option<Spanned<TextureInput>>,
    alpha_v: &Option<Spanned<TextureInput>>,
    ctx: &mut BuildContext<'_>,
) -> Result<Roughness, ParamError> {
    RoughnessParams {
        alpha,
        alpha_u,
        alpha_v,
    }
    .resolve(ctx)
}
