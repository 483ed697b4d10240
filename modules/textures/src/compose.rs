//! What textures built from other textures share: resolving an input
//! (inline value or texture name) to a [`Child`], evaluating in
//! fixed-size chunks on the stack (no allocation per batch), estimating a
//! mean by evaluating a grid, and the GPU side of a composite.
//!
//! On the GPU a composite cannot evaluate its children through
//! `texture_eval`: that would make the kernel's call graph recursive
//! (`texture_eval` → the composite → `texture_eval`), which WGSL forbids.
//! Instead each composite instance's WGSL calls its children's type
//! functions directly, so its identifier names its children's types
//! (`uv_transform_5image`: see [`composite_gpu`]). A constant child's
//! value is among the composite's parameters; a module child is reached
//! by its id in the scene's texture table, through the texture directory
//! (`texture_child_params` in `compose.wgsl`).

use radiant_core::glam::Vec2;
use radiant_core::params::Spanned;
use radiant_core::{
    BuildContext, GpuLibrary, GpuModule, GpuParams, ParamError, Rgb, TextureId, TextureInput,
    TextureRef, TextureTable,
};
use std::borrow::Cow;
use std::sync::OnceLock;

/// Lookups per chunk of a composite texture's evaluation.
pub(crate) const CHUNK: usize = 64;

/// An input of a composite texture: the texture, and its id where it is an
/// entry of the scene's [`TextureTable`] (the composite's GPU code reaches
/// a varying child by its id; without one it has no GPU side).
#[derive(Clone)]
pub struct Child {
    /// The texture.
    pub texture: TextureRef,
    /// Its id in the scene's table, if it is an entry there.
    pub id: Option<TextureId>,
}

impl Child {
    /// Entry `id` of `table`.
    pub fn from_table(table: &TextureTable, id: TextureId) -> Self {
        Self {
            texture: table.get(id),
            id: Some(id),
        }
    }

    /// Evaluates the child at every `uv[i]` into `out[i]`.
    #[inline]
    pub(crate) fn eval(&self, uv: &[Vec2], out: &mut [Rgb]) {
        self.texture.eval(uv, out);
    }

    /// The child's part of its parent's GPU side: the fragment of the
    /// parent's identifier, its words, and the identifier of the type to
    /// call (`None`: a constant, its value being its words).
    fn gpu(&self) -> Option<(String, GpuParams, Option<String>)> {
        match &self.texture {
            TextureRef::Constant(c) => Some(("k".into(), GpuParams::new().rgb(*c), None)),
            TextureRef::Module(t) => {
                let id = self.id?;
                let ident = t.gpu()?.ident.into_owned();
                let fragment = format!("{}{ident}", ident.len());
                Some((fragment, GpuParams::new().texture(id), Some(ident)))
            }
        }
    }
}

impl From<TextureRef> for Child {
    /// A texture held without an id: on the GPU only a constant can be
    /// reached this way.
    fn from(texture: TextureRef) -> Self {
        Self { texture, id: None }
    }
}

/// Resolves a colour input to a texture and its id.
pub(crate) fn resolve(
    ctx: &mut BuildContext<'_>,
    input: &Spanned<TextureInput>,
) -> Result<Child, ParamError> {
    let id = ctx.texture(input)?;
    Ok(Child::from_table(ctx.textures, id))
}

/// The WGSL the composites share (`texture_child_params`).
pub(crate) const COMPOSE: GpuLibrary = GpuLibrary {
    name: "textures::compose",
    wgsl: include_str!("compose.wgsl"),
    requires: &[],
};

/// The GPU side of a composite of type `name`: `template` is its WGSL,
/// with `$IDENT` for the instance's identifier and `$CHILD0`, `$CHILD1`, …
/// for the expressions of its children's values at `uv` (a variable the
/// template defines); its parameters are `own`, then each child's words
/// (a constant's value, or a module's id). The identifier is `name`
/// followed by one fragment per child: `k` for a constant, the length and
/// identifier of a module's type (so `checkerboard_k_5image`), which tells
/// every combination of child types apart. `None` where a child has no
/// GPU side or no id.
pub(crate) fn composite_gpu(
    name: &str,
    template: &str,
    libraries: &'static [GpuLibrary],
    own: GpuParams,
    children: &[&Child],
) -> Option<GpuModule> {
    let mut ident = name.to_string();
    let mut wgsl = template.to_string();
    let mut params = own;
    for (k, child) in children.iter().enumerate() {
        let (fragment, words, call) = child.gpu()?;
        ident = format!("{ident}_{fragment}");
        let at = params.len();
        let value = match call {
            None => format!("param_vec3(p + {at}u)"),
            Some(t) => format!("texture_{t}(texture_child_params(param_u32(p + {at}u)), uv)"),
        };
        wgsl = wgsl.replace(&format!("$CHILD{k}"), &value);
        params = params.append(&words);
    }
    Some(GpuModule {
        ident: Cow::Owned(ident.clone()),
        wgsl: Cow::Owned(wgsl.replace("$IDENT", &ident)),
        requires: libraries,
        params,
    })
}

/// A composite's GPU side, made once: composites do not change once
/// built, and making it asks every child for its own.
#[derive(Default)]
pub(crate) struct GpuCache(OnceLock<Option<GpuModule>>);

impl GpuCache {
    /// The cached module, made by `make` on first use.
    pub(crate) fn get(&self, make: impl FnOnce() -> Option<GpuModule>) -> Option<GpuModule> {
        self.0.get_or_init(make).clone()
    }
}

/// Calls `f` on consecutive chunks of at most [`CHUNK`] lookups of `uv`
/// and the matching part of `out`.
#[inline]
pub(crate) fn chunked(uv: &[Vec2], out: &mut [Rgb], mut f: impl FnMut(&[Vec2], &mut [Rgb])) {
    for (uv, out) in uv.chunks(CHUNK).zip(out.chunks_mut(CHUNK)) {
        f(uv, out);
    }
}

/// The mean of `eval` over the unit square, from a 128 × 128 grid of
/// cell centres.
pub(crate) fn grid_mean(eval: impl Fn(&[Vec2], &mut [Rgb])) -> Rgb {
    const N: usize = 128;
    let mut row_uv = [Vec2::ZERO; N];
    let mut row = [Rgb::ZERO; N];
    let mut sum = [0.0f64; 3];
    for j in 0..N {
        for (i, p) in row_uv.iter_mut().enumerate() {
            *p = Vec2::new((i as f32 + 0.5) / N as f32, (j as f32 + 0.5) / N as f32);
        }
        chunked(&row_uv, &mut row, &eval);
        for c in &row {
            sum[0] += c.x as f64;
            sum[1] += c.y as f64;
            sum[2] += c.z as f64;
        }
    }
    let n = (N * N) as f64;
    Rgb::new(
        (sum[0] / n) as f32,
        (sum[1] / n) as f32,
        (sum[2] / n) as f32,
    )
}
