//! Shading with a perturbed normal, for the `normal_map` and `bump`
//! wrappers ([`Perturbed`] over their [`NormalSource`]), as Mitsuba 3.9's
//! `normalmap` and `bumpmap` do it:
//!
//! 1. each point gets a new normal n′ in the local shading frame;
//! 2. where the viewer is below n′ (an invalid normal), n′ is mirrored
//!    about the shading normal, (−x, −y, z), so the viewer sees the facet
//!    from the front (Schüssler et al. 2017's flip; `flip_invalid_normals`);
//! 3. the nested material is sampled and evaluated in the frame around n′
//!    whose tangent is the shading frame's (along ∂p/∂u) made orthogonal
//!    to n′, with ∂p/∂u and ∂p/∂v handed on in that frame;
//! 4. the light side is attenuated by Conty Estevez et al. 2019's
//!    microfacet shadowing term 2/(1 + √(1 + α²·tan²θi)) with
//!    α² = min(tan²θ(n′)/8, 1) (`use_shadowing_function`), which fades
//!    the shading terminator smoothly instead of cutting it.
//!
//! Directions below the true shading normal but above n′ (or the
//! reverse) stay black, as in Mitsuba 3.
//!
//! The shading frame the wrappers see is oriented by the texture
//! parametrisation (their effects contain `TANGENT_FRAMES`, so the engine
//! builds it from ∂p/∂u and hands them ∂p/∂u and ∂p/∂v), so a normal map
//! is read in uv tangent space and a bump map is differentiated along the
//! surface's real ∂p/∂u and ∂p/∂v.

use crate::gpu;
use radiant_core::glam::Vec3;
use radiant_core::{
    BsdfEval, BsdfSample, BuildContext, Effects, Frame, GpuModule, GpuParams, ParamDoc, ParamError,
    Params, ShadeContext, Shader, SurfaceBatch, TextureId,
};

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

/// Where a wrapper's perturbed normals come from (a normal map, a height
/// field).
pub(crate) trait NormalSource: Send + Sync + 'static {
    /// The perturbed unit normals of the batch's points (local
    /// coordinates, above the surface), in a buffer taken from `ctx` that
    /// the caller recycles.
    fn normals(&self, ctx: &mut ShadeContext<'_>, surface: SurfaceBatch<'_>) -> Vec<Vec3>;

    /// The GPU side: the source's name, its WGSL template defining
    /// `perturbed_normal_$SELF(p: u32, s: ShadingPoint) -> vec3f` (the
    /// normal at `s`, reading the parameters at `p`), and its parameters.
    fn gpu(&self) -> (&'static str, &'static str, GpuParams);
}

/// The options both wrappers share (Mitsuba 3's names and defaults).
#[derive(Clone, Copy)]
pub(crate) struct PerturbOptions {
    /// Mirror normals the viewer is below (see the module docs).
    pub flip_invalid_normals: bool,
    /// Attenuate the light side by the microfacet shadowing term.
    pub use_shadowing_function: bool,
}

/// Serde default of both options.
pub(crate) fn yes() -> bool {
    true
}

/// Documentation of [`PerturbOptions::flip_invalid_normals`].
pub(crate) const FLIP_DOC: ParamDoc = ParamDoc {
    name: "flip_invalid_normals",
    ty: "bool",
    default: "true",
    doc: "Mirror a perturbed normal the viewer is below about the shading normal (Schüssler et al. 2017), as Mitsuba 3 does.",
};

/// Documentation of [`PerturbOptions::use_shadowing_function`].
pub(crate) const SHADOWING_DOC: ParamDoc = ParamDoc {
    name: "use_shadowing_function",
    ty: "bool",
    default: "true",
    doc: "Fade the light side by Conty Estevez et al. 2019's microfacet shadowing term, as Mitsuba 3 does, so the terminator is smooth.",
};

/// The frame around the unit normal `n` (local coordinates) whose tangent
/// is the local x axis made orthogonal to it; any frame around `n` where
/// `n` is along x.
#[inline]
pub(crate) fn frame_around(n: Vec3) -> Frame {
    Frame::with_tangent(n, Vec3::X).unwrap_or_else(|| Frame::from_normal(n))
}

/// `n` mirrored about the shading normal where the viewer `wo` is below
/// it (Mitsuba 3's `flip_invalid_normals`).
#[inline]
pub(crate) fn flip_invalid(n: Vec3, wo: Vec3) -> Vec3 {
    if wo.z * wo.dot(n) <= 0.0 {
        Vec3::new(-n.x, -n.y, n.z)
    } else {
        n
    }
}

/// α² of the shadowing term for the perturbed normal `n`.
#[inline]
pub(crate) fn shadowing_alpha2(n: Vec3) -> f32 {
    (0.125 * tan2_theta(n)).min(1.0)
}

/// Conty Estevez et al. 2019's shadowing of the light direction `wi`
/// (unperturbed local frame) for a surface of roughness² `alpha2`.
#[inline]
pub(crate) fn shadowing(alpha2: f32, wi: Vec3) -> f32 {
    if alpha2 <= 0.0 {
        // An unperturbed normal shadows nothing, even at the horizon.
        return 1.0;
    }
    2.0 / (1.0 + (1.0 + alpha2 * tan2_theta(wi)).sqrt())
}

/// tan²θ of a unit vector (infinite along the horizon).
#[inline]
fn tan2_theta(v: Vec3) -> f32 {
    let cos2 = v.z * v.z;
    (1.0 - cos2).max(0.0) / cos2
}

/// A nested material shaded around the normals of a [`NormalSource`].
pub(crate) struct Perturbed<N> {
    source: N,
    options: PerturbOptions,
    nested: Box<dyn Shader>,
    effects: Effects,
}

impl<N: NormalSource> Perturbed<N> {
    /// Wraps the material under the `material` key of `params`, with
    /// normals from `source`, which reads the texture `texture`.
    pub(crate) fn new(
        source: N,
        texture: TextureId,
        options: PerturbOptions,
        params: &Params,
        ctx: &mut BuildContext<'_>,
    ) -> Result<Self, ParamError> {
        let nested = ctx.material(params, "material")?;
        let effects = nested.effects() | ctx.textures.effects(texture) | Effects::TANGENT_FRAMES;
        Ok(Self {
            source,
            options,
            nested,
            effects,
        })
    }

    /// The perturbed frames of the batch's points and their shadowing α²
    /// (zero without shadowing), in buffers taken from `ctx`.
    fn frames(
        &self,
        ctx: &mut ShadeContext<'_>,
        surface: SurfaceBatch<'_>,
    ) -> (Vec<Frame>, Vec<f32>) {
        let normals = self.source.normals(ctx, surface);
        let mut frames = ctx.take::<Frame>(surface.len());
        let mut alpha2 = ctx.take::<f32>(surface.len());
        for (i, &n) in normals.iter().enumerate() {
            let n = if self.options.flip_invalid_normals {
                flip_invalid(n, surface.wo[i])
            } else {
                n
            };
            frames[i] = frame_around(n);
            if self.options.use_shadowing_function {
                alpha2[i] = shadowing_alpha2(n);
            }
        }
        ctx.recycle(normals);
        (frames, alpha2)
    }

    /// Runs `shade` on the batch seen in `frames`: its outgoing directions
    /// and derivatives in those frames.
    fn in_frames<R>(
        ctx: &mut ShadeContext<'_>,
        surface: SurfaceBatch<'_>,
        frames: &[Frame],
        shade: impl FnOnce(&mut ShadeContext<'_>, SurfaceBatch<'_>) -> R,
    ) -> R {
        let n = surface.len();
        let mut wo = ctx.take::<Vec3>(n);
        for i in 0..n {
            wo[i] = frames[i].to_local(surface.wo[i]);
        }
        let has_derivatives = !surface.dp_du.is_empty();
        let m = if has_derivatives { n } else { 0 };
        let mut dp_du = ctx.take::<Vec3>(m);
        let mut dp_dv = ctx.take::<Vec3>(m);
        for i in 0..m {
            dp_du[i] = frames[i].to_local(surface.dp_du[i]);
            dp_dv[i] = frames[i].to_local(surface.dp_dv[i]);
        }
        let seen = SurfaceBatch {
            wo: &wo,
            uv: surface.uv,
            dp_du: &dp_du,
            dp_dv: &dp_dv,
        };
        let result = shade(ctx, seen);
        ctx.recycle(wo);
        ctx.recycle(dp_du);
        ctx.recycle(dp_dv);
        result
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
        let (frames, alpha2) = self.frames(ctx, surface);
        Self::in_frames(ctx, surface, &frames, |ctx, seen| {
            self.nested.sample(ctx, seen, u, out)
        });
        for (i, s) in out.iter_mut().enumerate() {
            let wi = frames[i].to_world(s.wi);
            if wi.z * s.wi.z <= 0.0 || s.pdf <= 0.0 {
                *s = BsdfSample::default();
            } else {
                s.wi = wi;
                if self.options.use_shadowing_function {
                    s.weight *= shadowing(alpha2[i], wi);
                }
            }
        }
        ctx.recycle(frames);
        ctx.recycle(alpha2);
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
        let (frames, alpha2) = self.frames(ctx, surface);
        let mut wi_p = ctx.take::<Vec3>(surface.len());
        for (i, w) in wi_p.iter_mut().enumerate() {
            *w = frames[i].to_local(wi[i]);
        }
        Self::in_frames(ctx, surface, &frames, |ctx, seen| {
            self.nested.eval(ctx, seen, &wi_p, out)
        });
        for (i, e) in out.iter_mut().enumerate() {
            if wi[i].z * wi_p[i].z <= 0.0 {
                *e = BsdfEval::default();
            } else if self.options.use_shadowing_function {
                e.value *= shadowing(alpha2[i], wi[i]);
            }
        }
        ctx.recycle(wi_p);
        ctx.recycle(frames);
        ctx.recycle(alpha2);
    }

    fn uses_lobe_samples(&self) -> bool {
        self.nested.uses_lobe_samples()
    }

    fn effects(&self) -> Effects {
        self.effects
    }

    /// `perturb.wgsl` around the source's normals, where the nested
    /// material has a GPU side whose code is in libraries or is a
    /// composite's (see [`crate::gpu::Composite`]).
    fn gpu(&self) -> Option<GpuModule> {
        let nested = self.nested.gpu()?;
        let (name, normals, source) = self.source.gpu();
        let ident = format!(
            "{}{name}_{}_{}",
            gpu::PERTURBED_PREFIX,
            nested.ident.len(),
            nested.ident
        );
        let mut code = gpu::Composite::new(ident, &[gpu::PERTURB]);
        let m = code.part(&nested, "__m")?;
        code.template(normals, &[]);
        code.template(PERTURBED_WGSL, &[("$M", &m)]);
        let flags = u32::from(self.options.flip_invalid_normals)
            | u32::from(self.options.use_shadowing_function) << 1;
        let params = GpuParams::new()
            .u32(2 + source.len() as u32)
            .u32(flags)
            .append(&source)
            .append(&nested.params);
        Some(code.finish(params))
    }
}

/// The template of a wrapper's WGSL (`$M`: the nested material).
const PERTURBED_WGSL: &str = include_str!("perturb.wgsl");

/// Unit normal from a tangent-space vector, falling back to +z for a
/// degenerate one or one below the surface.
#[inline]
pub(crate) fn sanitise(n: Vec3) -> Vec3 {
    match n.try_normalize() {
        Some(n) if n.z > 1e-3 => n,
        _ => Vec3::Z,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The viewer sees every flipped normal from the front, and normals it
    /// already sees are kept.
    #[test]
    fn flipped_normals_face_the_viewer() {
        let n = Vec3::new(0.6, 0.2, 0.77).normalize();
        let behind = Vec3::new(-0.9, -0.1, 0.2).normalize();
        assert!(behind.dot(n) < 0.0);
        let flipped = flip_invalid(n, behind);
        assert!(behind.dot(flipped) > 0.0);
        assert_eq!(flipped, Vec3::new(-n.x, -n.y, n.z));
        let front = Vec3::new(0.3, 0.1, 0.9).normalize();
        assert_eq!(flip_invalid(n, front), n);
    }

    /// The shadowing term is 1 for an unperturbed normal and overhead
    /// light, and matches Mitsuba 3.9.1's `normalmap`: its `eval` of a
    /// diffuse (0.7) under the normal map colour (183, 161, 238)/255 for
    /// the light direction (6.1, 1.8, 1.2) is 0.114888, 0.805 of
    /// 0.7/π·cos θ′.
    #[test]
    fn shadowing_matches_mitsuba() {
        assert_eq!(shadowing(shadowing_alpha2(Vec3::Z), Vec3::X), 1.0);
        let n = (2.0 * Vec3::new(183.0, 161.0, 238.0) / 255.0 - Vec3::ONE).normalize();
        assert_eq!(shadowing(shadowing_alpha2(n), Vec3::Z), 1.0);
        let wi = Vec3::new(6.1, 1.8, 1.2).normalize();
        let eval = 0.7 / std::f32::consts::PI * n.dot(wi) * shadowing(shadowing_alpha2(n), wi);
        assert!((eval - 0.114888).abs() < 2e-5, "{eval}");
    }
}
