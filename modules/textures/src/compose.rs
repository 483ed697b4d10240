//! What textures built from other textures share: resolving an input
//! (inline value or texture name) to a [`TextureRef`], evaluating in
//! fixed-size chunks on the stack (no allocation per batch), and
//! estimating a mean by evaluating a grid.

use radiant_core::glam::Vec2;
use radiant_core::params::Spanned;
use radiant_core::{BuildContext, ParamError, Rgb, TextureInput, TextureRef};

/// Lookups per chunk of a composite texture's evaluation.
pub(crate) const CHUNK: usize = 64;

/// Resolves a colour input to a texture handle.
pub(crate) fn resolve(
    ctx: &mut BuildContext<'_>,
    input: &Spanned<TextureInput>,
) -> Result<TextureRef, ParamError> {
    let id = ctx.texture(input)?;
    Ok(ctx.textures.get(id))
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
