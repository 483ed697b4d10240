//! Shading with a perturbed normal, for the `normal_map` and `bump`
//! wrappers ([`Perturbed`] over their [`NormalSource`]): each point gets a new normal n′ (in the local shading frame),
//! a frame around it whose first tangent is the local x axis made
//! orthogonal to n′ (Gram–Schmidt), and the nested material is sampled and
//! evaluated in that frame, as Mitsuba 3's `normalmap` and `bumpmap` do.
//!
//! Limits, within the batch shader interface: the wrapper sees only the
//! local shading frame and (u, v), not the surface's ∂p/∂u and ∂p/∂v, so
//! tangent space is the shading frame's (x, y) axes at unit scale rather
//! than the texture parametrisation's; maps authored in uv tangent space
//! appear rotated about the normal where the two differ. Directions below
//! the true shading normal but above the perturbed one (or the reverse)
//! are black, which loses some energy at grazing angles and breaks
//! reciprocity slightly, as in Mitsuba 3.

use radiant_core::glam::Vec3;
use radiant_core::{
    BsdfEval, BsdfSample, BuildContext, Effects, Frame, ParamError, Params, ShadeContext, Shader,
    SurfaceBatch, TextureId,
};

/// The frame around the perturbed normal `n` (unit, local coordinates).
#[inline]
pub(crate) fn perturbed_frame(n: Vec3) -> Frame {
    let s = (Vec3::X - n * n.x)
        .try_normalize()
        .unwrap_or_else(|| Frame::from_normal(n).s);
    Frame {
        s,
        t: n.cross(s),
        n,
    }
}

/// Where a wrapper's perturbed normals come from (a normal map, a height
/// field).
pub(crate) trait NormalSource: Send + Sync + 'static {
    /// The perturbed normals of the batch's points (local frame, unit,
    /// above the surface), in a buffer taken from `ctx` that the caller
    /// recycles.
    fn normals(&self, ctx: &mut ShadeContext<'_>, surface: SurfaceBatch<'_>) -> Vec<Vec3>;
}

/// A nested material shaded around the normals of a [`NormalSource`].
pub(crate) struct Perturbed<N> {
    source: N,
    nested: Box<dyn Shader>,
    effects: Effects,
}

impl<N: NormalSource> Perturbed<N> {
    /// Wraps the material under the `material` key of `params`, with
    /// normals from `source`, which reads the texture `texture`.
    pub(crate) fn new(
        source: N,
        texture: TextureId,
        params: &Params,
        ctx: &mut BuildContext<'_>,
    ) -> Result<Self, ParamError> {
        let nested = ctx.material(params, "material")?;
        let effects = nested.effects() | ctx.textures.effects(texture);
        Ok(Self {
            source,
            nested,
            effects,
        })
    }
}

impl<N: NormalSource> Shader for Perturbed<N> {
    /// Samples the nested material at every point in the frame of its
    /// perturbed normal.
    fn sample(
        &self,
        ctx: &mut ShadeContext<'_>,
        surface: SurfaceBatch<'_>,
        u: &[Vec3],
        out: &mut [BsdfSample],
    ) {
        let normals = self.source.normals(ctx, surface);
        let mut wo = ctx.take::<Vec3>(surface.len());
        for i in 0..surface.len() {
            wo[i] = perturbed_frame(normals[i]).to_local(surface.wo[i]);
        }
        self.nested.sample(
            ctx,
            SurfaceBatch {
                wo: &wo,
                uv: surface.uv,
            },
            u,
            out,
        );
        for (i, s) in out.iter_mut().enumerate() {
            let wi = perturbed_frame(normals[i]).to_world(s.wi);
            if wi.z * s.wi.z <= 0.0 || s.pdf <= 0.0 {
                *s = BsdfSample::default();
            } else {
                s.wi = wi;
            }
        }
        ctx.recycle(wo);
        ctx.recycle(normals);
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
        let normals = self.source.normals(ctx, surface);
        let n = surface.len();
        let mut wo = ctx.take::<Vec3>(n);
        let mut wi_p = ctx.take::<Vec3>(n);
        for i in 0..n {
            let f = perturbed_frame(normals[i]);
            wo[i] = f.to_local(surface.wo[i]);
            wi_p[i] = f.to_local(wi[i]);
        }
        self.nested.eval(
            ctx,
            SurfaceBatch {
                wo: &wo,
                uv: surface.uv,
            },
            &wi_p,
            out,
        );
        for i in 0..n {
            if wi[i].z * wi_p[i].z <= 0.0 {
                out[i] = BsdfEval::default();
            }
        }
        ctx.recycle(wo);
        ctx.recycle(wi_p);
        ctx.recycle(normals);
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
