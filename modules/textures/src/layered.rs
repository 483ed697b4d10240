//! The `layered` texture of seed 004: `upper` over `lower` through a
//! `mask`, lower · (1 − mask) + upper · mask per channel.

use crate::compose::{CHUNK, COMPOSE, Child, GpuCache, chunked, composite_gpu, grid_mean, resolve};
use radiant_core::glam::Vec2;
use radiant_core::params::Spanned;
use radiant_core::{
    BuildContext, GpuModule, GpuParams, ModuleInfo, ParamDoc, Params, Registry, Rgb, Texture,
    TextureInput,
};
use serde::Deserialize;

/// Two textures blended by a mask texture.
pub struct Layered {
    upper: Child,
    lower: Child,
    mask: Child,
    mean: Rgb,
    gpu: GpuCache,
}

impl Layered {
    /// `upper` over `lower` where `mask` is 1 (each a
    /// [`TextureRef`](radiant_core::TextureRef) or, for a GPU side with
    /// varying inputs, a [`Child`] with its id).
    pub fn new(upper: impl Into<Child>, lower: impl Into<Child>, mask: impl Into<Child>) -> Self {
        let mut t = Self {
            upper: upper.into(),
            lower: lower.into(),
            mask: mask.into(),
            mean: Rgb::ZERO,
            gpu: GpuCache::default(),
        };
        t.mean = grid_mean(|uv, out| t.eval(uv, out));
        t
    }
}

impl Texture for Layered {
    fn eval(&self, uv: &[Vec2], out: &mut [Rgb]) {
        chunked(uv, out, |uv, out| {
            let mut upper = [Rgb::ZERO; CHUNK];
            let mut mask = [Rgb::ZERO; CHUNK];
            self.lower.eval(uv, out);
            self.upper.eval(uv, &mut upper);
            self.mask.eval(uv, &mut mask);
            for ((o, u), m) in out.iter_mut().zip(&upper).zip(&mask) {
                *o += (*u - *o) * *m;
            }
        });
    }

    fn mean(&self) -> Rgb {
        self.mean
    }

    fn gpu(&self) -> Option<GpuModule> {
        self.gpu.get(|| {
            composite_gpu(
                "layered",
                include_str!("layered.wgsl"),
                &[COMPOSE],
                GpuParams::new(),
                &[&self.upper, &self.lower, &self.mask],
            )
        })
    }
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
pub(crate) struct LayeredParams {
    upper: Spanned<TextureInput>,
    lower: Spanned<TextureInput>,
    mask: Spanned<TextureInput>,
}

pub(crate) const DOCS: &[ParamDoc] = &[
    ParamDoc {
        name: "upper",
        ty: "rgb | number | texture",
        default: "required",
        doc: "The layer on top, shown where the mask is 1.",
    },
    ParamDoc {
        name: "lower",
        ty: "rgb | number | texture",
        default: "required",
        doc: "The layer below, shown where the mask is 0.",
    },
    ParamDoc {
        name: "mask",
        ty: "rgb | number | texture, [0, 1]",
        default: "required",
        doc: "Per-channel blend weight of `upper`.",
    },
];

pub(crate) fn register(registry: &mut Registry) {
    registry.register::<dyn Texture>(
        ModuleInfo {
            type_name: "layered",
            summary: "Blend of two textures by a mask: lower·(1 − mask) + upper·mask.",
            params: DOCS,
        },
        |params: &Params, ctx: &mut BuildContext<'_>| {
            let p: LayeredParams = params.parse()?;
            let upper = resolve(ctx, &p.upper)?;
            let lower = resolve(ctx, &p.lower)?;
            let mask = resolve(ctx, &p.mask)?;
            Ok(Box::new(Layered::new(upper, lower, mask)) as Box<dyn Texture>)
        },
    );
}
