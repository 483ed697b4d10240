//! The `checkerboard` texture: 2 × 2 checks over the unit square, repeated
//! (Mitsuba 3's checkerboard); `color0` where ⌊2u⌋ + ⌊2v⌋ is even.

use crate::compose::{CHUNK, COMPOSE, Child, GpuCache, chunked, composite_gpu, grid_mean, resolve};
use radiant_core::glam::Vec2;
use radiant_core::params::Spanned;
use radiant_core::{
    BuildContext, GpuLibrary, GpuModule, GpuParams, ModuleInfo, ParamDoc, Params, Registry, Rgb,
    Texture, TextureInput,
};
use serde::Deserialize;

/// A checkerboard of two textures.
pub struct Checkerboard {
    colors: [Child; 2],
    mean: Rgb,
    gpu: GpuCache,
}

/// The checkerboard's WGSL helpers (`checkerboard_odd`), shared by its
/// instances of every combination of child types.
const CHECKS: GpuLibrary = GpuLibrary {
    name: "textures::checkerboard",
    wgsl: include_str!("checkerboard_lib.wgsl"),
    requires: &[],
};

impl Checkerboard {
    /// A checkerboard of `color0` and `color1` (a [`TextureRef`](radiant_core::TextureRef) or,
    /// for a GPU side with a varying input, a [`Child`] with its id).
    pub fn new(color0: impl Into<Child>, color1: impl Into<Child>) -> Self {
        let mut t = Self {
            colors: [color0.into(), color1.into()],
            mean: Rgb::ZERO,
            gpu: GpuCache::default(),
        };
        t.mean = grid_mean(|uv, out| t.eval(uv, out));
        t
    }
}

/// Whether `uv` lies in a `color1` check.
#[inline]
fn odd(uv: Vec2) -> bool {
    let c = (2.0 * uv).floor();
    (c.x as i64 + c.y as i64) & 1 == 1
}

impl Texture for Checkerboard {
    fn eval(&self, uv: &[Vec2], out: &mut [Rgb]) {
        chunked(uv, out, |uv, out| {
            let mut second = [Rgb::ZERO; CHUNK];
            self.colors[0].eval(uv, out);
            self.colors[1].eval(uv, &mut second);
            for ((o, s), p) in out.iter_mut().zip(&second).zip(uv) {
                if odd(*p) {
                    *o = *s;
                }
            }
        });
    }

    fn mean(&self) -> Rgb {
        self.mean
    }

    fn gpu(&self) -> Option<GpuModule> {
        self.gpu.get(|| {
            composite_gpu(
                "checkerboard",
                include_str!("checkerboard.wgsl"),
                &[COMPOSE, CHECKS],
                GpuParams::new(),
                &[&self.colors[0], &self.colors[1]],
            )
        })
    }
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
pub(crate) struct CheckerboardParams {
    #[serde(default = "default_color0")]
    color0: Spanned<TextureInput>,
    #[serde(default = "default_color1")]
    color1: Spanned<TextureInput>,
}

fn default_color0() -> Spanned<TextureInput> {
    TextureInput::spanned_value(Rgb::splat(0.4))
}

fn default_color1() -> Spanned<TextureInput> {
    TextureInput::spanned_value(Rgb::splat(0.2))
}

pub(crate) const DOCS: &[ParamDoc] = &[
    ParamDoc {
        name: "color0",
        ty: "rgb | number | texture",
        default: "0.4",
        doc: "Checks where ⌊2u⌋ + ⌊2v⌋ is even (including the one at the origin).",
    },
    ParamDoc {
        name: "color1",
        ty: "rgb | number | texture",
        default: "0.2",
        doc: "The other checks.",
    },
];

pub(crate) fn register(registry: &mut Registry) {
    registry.register::<dyn Texture>(
        ModuleInfo {
            type_name: "checkerboard",
            summary: "2 × 2 checks per unit square of uv (use `uv_transform` to scale).",
            params: DOCS,
        },
        |params: &Params, ctx: &mut BuildContext<'_>| {
            let p: CheckerboardParams = params.parse()?;
            let color0 = resolve(ctx, &p.color0)?;
            let color1 = resolve(ctx, &p.color1)?;
            Ok(Box::new(Checkerboard::new(color0, color1)) as Box<dyn Texture>)
        },
    );
}
