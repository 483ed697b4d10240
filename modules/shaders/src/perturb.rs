//! Shading with a perturbed frame, for the `normal_map` and `bump`
//! wrappers ([`Perturbed`] over their [`FrameSource`]): each point gets a
//! new normal n′ (in the local shading frame) and a frame around it whose
//! first tangent is the surface's ∂p/∂u made orthogonal to n′
//! (Gram–Schmidt), and the nested material is sampled and evaluated in
//! that frame, as Mitsuba 3's `normalmap` and `bumpmap` do.
//!
//! The shading frame the wrappers see is oriented by the texture
//! parametrisation (their effects contain `TANGENT_FRAMES`, so the engine
//! builds it from ∂p/∂u and hands them ∂p/∂u and ∂p/∂v), so a normal map
//! is read in uv tangent space and a bump map is differentiated along the
//! surface's real ∂p/∂u and ∂p/∂v. Directions below the true shading
//! normal but above the perturbed one (or the reverse) are black, which
//! loses some energy at grazing angles and breaks reciprocity slightly, as
//! in Mitsuba 3.

use radiant_core::glam::Vec3;
use radiant_core::{
    BsdfEval, BsdfSample, BuildContext, Effects, Frame, ParamError, Params, ShadeContext, Shader,
    SurfaceBatch, TextureId,
};

/// The frame around the unit normal `n` whose first tangent is `dp_du`
/// made orthogonal to it (all in local coordinates); around the local x
/// axis where `dp_du` is missing or parallel to `n`.
#[inline]
pub(crate) fn frame_along(n: Vec3, dp_du: Vec3) -> Frame {
    Frame::with_tangent(n, dp_du)
        .or_else(|| Frame::with_tangent(n, Vec3::X))
        .unwrap_or_else(|| Frame::from_normal(n))
}

/// ∂p/∂u and ∂p/∂v of point `i` of `surface` (local frame), or the unit
/// local axes where the batch carries none.
#[inline]
pub(crate) fn derivatives(surface: &SurfaceBatch<'_>, i: usize) -> (Vec3, Vec3) {
    if surface.dp_du.is_empty() {
        (Vec3::X, Vec3::Y)
    } else {
        (surface.dp_du[i], surface.dp_dv[i])
    }
}

/// Where a wrapper's perturbed frames come from (a normal map, a height
/// field).
pub(crate) trait FrameSource: Send + Sync + 'static {
    /// The perturbed frames of the batch's points (local coordinates,
    /// normals above the surface), in a buffer taken from `ctx` that the
    /// caller recycles.
    fn frames(&self, ctx: &mut ShadeContext<'_>, surface: SurfaceBatch<'_>) -> Vec<Frame>;
}

/// A nested material shaded in the frames of a [`FrameSource`].
pub(crate) struct Perturbed<N> {
    source: N,
    nested: Box<dyn Shader>,
    effects: Effects,
}

impl<N: FrameSource> Perturbed<N> {
    /// Wraps the material under the `material` key of `params`, with
    /// normals from `source`, which reads the texture `texture`.
    pub(crate) fn new(
        source: N,
        texture: TextureId,
        params: &Params,
        ctx: &mut BuildContext<'_>,
    ) -> Result<Self, ParamError> {
        let nested = ctx.material(params, "material")?;
        let effects = nested.effects() | ctx.textures.effects(texture) | Effects::TANGENT_FRAMES;
        Ok(Self {
            source,
            nested,
            effects,
        })
    }
}

impl<N: FrameSource> Shader for Perturbed<N> {
    /// Samples the nested material at every point in the frame of its
    /// perturbed normal.
    fn sample(
        &self,
        ctx: &mut ShadeContext<'_>,
        surface: SurfaceBatch<'_>,
        u: &[Vec3],
        out: &mut [BsdfSample],
    ) {
        let frames = self.source.frames(ctx, surface);
        let mut wo = ctx.take::<Vec3>(surface.len());
        for i in 0..surface.len() {
            wo[i] = frames[i].to_local(surface.wo[i]);
        }
        self.nested.sample(ctx, surface.with_wo(&wo), u, out);
        for (i, s) in out.iter_mut().enumerate() {
            let wi = frames[i].to_world(s.wi);
            if wi.z * s.wi.z <= 0.0 || s.pdf <= 0.0 {
                *s = BsdfSample::default();
            } else {
                s.wi = wi;
            }
        }
        ctx.recycle(wo);
        ctx.recycle(frames);
    }

    /// Evaluates the nested material at every point in the frame of its
    /// perturbed normal.
    fn eval(
        &self,
        ctx: &mut ShadeContext<'_>,
        surface: SurfaceBatch<'_>,
        wi: &[Vec3],
        out: &mut [BsdfEval],
    ) {
        let frames = self.source.frames(ctx, surface);
        let n = surface.len();
        let mut wo = ctx.take::<Vec3>(n);
        let mut wi_p = ctx.take::<Vec3>(n);
        for i in 0..n {
            let f = &frames[i];
            wo[i] = f.to_local(surface.wo[i]);
            wi_p[i] = f.to_local(wi[i]);
        }
        self.nested.eval(ctx, surface.with_wo(&wo), &wi_p, out);
        for i in 0..n {
            if wi[i].z * wi_p[i].z <= 0.0 {
                out[i] = BsdfEval::default();
            }
        }
        ctx.recycle(wo);
        ctx.recycle(wi_p);
        ctx.recycle(frames);
    }

    fn effects(&self) -> Effects {
        self.effects
    }
}

/// Unit normal from a tangent-space vector, falling back to +z for a
/// degenerate one or one below the surface.
#[inline]
pub(crate) fn sanitise(n: Vec3) -> Vec3 {
    match n.try_normalize() {
        Some(n) if n.z > 1e-3 => n,
        _ => Vec3::Z,
    }
}
