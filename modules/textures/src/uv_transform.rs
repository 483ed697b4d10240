//! The `uv_transform` texture: any texture looked up at transformed
//! coordinates uv' = R(rotate) · (scale ⊙ uv) + offset — scale first, then
//! rotate (counter-clockwise, degrees) about the origin, then offset.

use crate::compose::{CHUNK, COMPOSE, Child, GpuCache, chunked, composite_gpu, grid_mean, resolve};
use radiant_core::glam::{Mat2, Vec2};
use radiant_core::params::Spanned;
use radiant_core::{
    BuildContext, GpuModule, GpuParams, ModuleInfo, ParamDoc, ParamError, Params, Registry, Rgb,
    Texture, TextureInput,
};
use serde::Deserialize;
use serde::de::{self, Deserializer, SeqAccess, Visitor};
use std::fmt;

/// A texture read through an affine map of its coordinates.
pub struct UvTransform {
    texture: Child,
    matrix: Mat2,
    offset: Vec2,
    mean: Rgb,
    gpu: GpuCache,
}

impl UvTransform {
    /// `texture` scaled by `scale`, rotated by `rotate_degrees` and shifted
    /// by `offset` (`texture` a [`TextureRef`](radiant_core::TextureRef)
    /// or, for a GPU side with a varying input, a [`Child`] with its id).
    pub fn new(texture: impl Into<Child>, scale: Vec2, rotate_degrees: f32, offset: Vec2) -> Self {
        let matrix = Mat2::from_angle(rotate_degrees.to_radians()) * Mat2::from_diagonal(scale);
        let mut t = Self {
            texture: texture.into(),
            matrix,
            offset,
            mean: Rgb::ZERO,
            gpu: GpuCache::default(),
        };
        t.mean = grid_mean(|uv, out| t.eval(uv, out));
        t
    }

    /// The transformed coordinates of `uv`.
    #[inline]
    pub fn map(&self, uv: Vec2) -> Vec2 {
        self.matrix * uv + self.offset
    }
}

impl Texture for UvTransform {
    fn eval(&self, uv: &[Vec2], out: &mut [Rgb]) {
        chunked(uv, out, |uv, out| {
            let mut mapped = [Vec2::ZERO; CHUNK];
            for (m, p) in mapped.iter_mut().zip(uv) {
                *m = self.map(*p);
            }
            self.texture.eval(&mapped[..uv.len()], out);
        });
    }

    fn mean(&self) -> Rgb {
        self.mean
    }

    fn gpu(&self) -> Option<GpuModule> {
        self.gpu.get(|| {
            let own = GpuParams::new()
                .f32s(self.matrix.to_cols_array())
                .f32s(self.offset.to_array());
            composite_gpu(
                "uv_transform",
                include_str!("uv_transform.wgsl"),
                &[COMPOSE],
                own,
                &[&self.texture],
            )
        })
    }
}

/// A 2D parameter given as one number for both axes or as `[x, y]`.
#[derive(Debug, Clone, Copy, PartialEq)]
struct Pair(Vec2);

impl<'de> Deserialize<'de> for Pair {
    fn deserialize<D: Deserializer<'de>>(deserializer: D) -> Result<Self, D::Error> {
        struct PairVisitor;
        impl<'de> Visitor<'de> for PairVisitor {
            type Value = Pair;
            fn expecting(&self, f: &mut fmt::Formatter) -> fmt::Result {
                f.write_str("a number or a [u, v] list")
            }
            fn visit_f64<E: de::Error>(self, v: f64) -> Result<Pair, E> {
                Ok(Pair(Vec2::splat(v as f32)))
            }
            fn visit_i64<E: de::Error>(self, v: i64) -> Result<Pair, E> {
                self.visit_f64(v as f64)
            }
            fn visit_u64<E: de::Error>(self, v: u64) -> Result<Pair, E> {
                self.visit_f64(v as f64)
            }
            fn visit_str<E: de::Error>(self, v: &str) -> Result<Pair, E> {
                v.trim()
                    .parse::<f32>()
                    .map(|x| Pair(Vec2::splat(x)))
                    .map_err(|_| {
                        E::custom(format!("expected a number or a [u, v] list, found `{v}`"))
                    })
            }
            fn visit_seq<A: SeqAccess<'de>>(self, mut seq: A) -> Result<Pair, A::Error> {
                let mut c = [0.0f32; 2];
                for (i, slot) in c.iter_mut().enumerate() {
                    *slot = seq
                        .next_element()?
                        .ok_or_else(|| de::Error::invalid_length(i, &"2 values, [u, v]"))?;
                }
                if seq.next_element::<f32>()?.is_some() {
                    return Err(de::Error::invalid_length(3, &"2 values, [u, v]"));
                }
                Ok(Pair(Vec2::from_array(c)))
            }
        }
        deserializer.deserialize_any(PairVisitor)
    }
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
pub(crate) struct UvTransformParams {
    texture: Spanned<TextureInput>,
    #[serde(default = "one")]
    scale: Pair,
    #[serde(default = "zero")]
    offset: Pair,
    #[serde(default)]
    rotate: f32,
}

fn one() -> Pair {
    Pair(Vec2::ONE)
}

fn zero() -> Pair {
    Pair(Vec2::ZERO)
}

pub(crate) const DOCS: &[ParamDoc] = &[
    ParamDoc {
        name: "texture",
        ty: "texture name | rgb | number",
        default: "required",
        doc: "The texture to transform.",
    },
    ParamDoc {
        name: "scale",
        ty: "number | [u, v]",
        default: "1",
        doc: "Multiplies uv first (8 tiles a repeating texture 8 times).",
    },
    ParamDoc {
        name: "rotate",
        ty: "degrees",
        default: "0",
        doc: "Counter-clockwise rotation about uv = 0, after scaling.",
    },
    ParamDoc {
        name: "offset",
        ty: "number | [u, v]",
        default: "0",
        doc: "Added last.",
    },
];

pub(crate) fn register(registry: &mut Registry) {
    registry.register::<dyn Texture>(
        ModuleInfo {
            type_name: "uv_transform",
            summary: "Any texture at transformed coordinates: scale, then rotate, then offset.",
            params: DOCS,
        },
        |params: &Params, ctx: &mut BuildContext<'_>| {
            let p: UvTransformParams = params.parse()?;
            for (key, ok) in [
                ("scale", p.scale.0.is_finite()),
                ("offset", p.offset.0.is_finite()),
                ("rotate", p.rotate.is_finite()),
            ] {
                if !ok {
                    return Err(ParamError {
                        message: format!("`{key}` must be finite"),
                        location: params.location_of(key),
                    });
                }
            }
            let texture = resolve(ctx, &p.texture)?;
            Ok(
                Box::new(UvTransform::new(texture, p.scale.0, p.rotate, p.offset.0))
                    as Box<dyn Texture>,
            )
        },
    );
}
