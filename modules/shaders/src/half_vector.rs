//! The shader shared by `ward` and `ashikhmin_shirley`: a glossy lobe
//! sampled through a half-vector warp over a diffuse base sampled by the
//! cosine, both one-sided, with each point's lobes made from four textures
//! (diffuse and specular reflectance, two anisotropic roughness values).
//! The models differ only in their [`HalfVectorLobes`].

use crate::inputs::{anisotropy, texture_effects};
use crate::lobes::reflection_sample;
use radiant_core::glam::{Vec2, Vec3};
use radiant_core::warp::square_to_cosine_hemisphere;
use radiant_core::{
    BsdfEval, BsdfSample, BuildContext, Effects, GpuLibrary, GpuModule, GpuParams, Rgb,
    ShadeContext, Shader, SurfaceBatch, TextureId, luminance,
};
use std::marker::PhantomData;

/// The lobes of one model at one surface point.
pub(crate) trait HalfVectorLobes {
    /// The model's shader type identifier on the GPU.
    const GPU_IDENT: &'static str;

    /// The library holding the model's WGSL (see [`crate::gpu`]), which
    /// reads the four textures in the shader's order.
    const GPU_CODE: &'static [GpuLibrary];

    /// The lobes from the texture values at the point: diffuse and specular
    /// reflectance and the two roughness parameters.
    fn new(diffuse: Rgb, specular: Rgb, u: Rgb, v: Rgb) -> Self;

    /// Probability of sampling the glossy lobe.
    fn specular_probability(&self) -> f32;

    /// A half-vector (upper hemisphere) from `u`.
    fn sample_half(&self, u: Vec2) -> Vec3;

    /// (f·cos θi, pdf) of the whole model.
    fn eval(&self, wo: Vec3, wi: Vec3) -> (Rgb, f32);
}

/// Glossy-lobe probability from the albedos: in proportion to their
/// luminances (even when both are black).
#[inline]
pub(crate) fn specular_probability(diffuse: Rgb, specular: Rgb) -> f32 {
    let (s, d) = (luminance(specular), luminance(diffuse));
    if s + d > 0.0 { s / (s + d) } else { 0.5 }
}

/// A shader over the lobes `L`.
pub(crate) struct HalfVectorShader<L> {
    /// Diffuse reflectance, specular reflectance, roughness u and v.
    textures: [TextureId; 4],
    effects: Effects,
    lobes: PhantomData<fn() -> L>,
}

impl<L> HalfVectorShader<L> {
    /// A shader reading its lobes' parameters from `textures` (diffuse,
    /// specular, roughness u, roughness v).
    pub(crate) fn new(ctx: &BuildContext<'_>, textures: [TextureId; 4]) -> Self {
        Self {
            textures,
            effects: Effects::SMOOTH_LOBES
                | Effects::GLOSSY
                | texture_effects(ctx, &textures)
                | anisotropy(ctx, textures[2], textures[3]),
            lobes: PhantomData,
        }
    }
}

impl<L: HalfVectorLobes> Shader for HalfVectorShader<L> {
    fn sample(
        &self,
        ctx: &mut ShadeContext<'_>,
        surface: SurfaceBatch<'_>,
        u: &[Vec3],
        out: &mut [BsdfSample],
    ) {
        let [rd, rs, au, av] = ctx.lookup(self.textures, surface.uv);
        for (i, o) in out.iter_mut().enumerate() {
            let wo = surface.wo[i];
            *o = BsdfSample::default();
            if wo.z <= 0.0 {
                continue;
            }
            let lobes = L::new(rd[i], rs[i], au[i], av[i]);
            let u2 = Vec2::new(u[i].y, u[i].z);
            let wi = if u[i].x < lobes.specular_probability() {
                let h = lobes.sample_half(u2);
                2.0 * wo.dot(h) * h - wo
            } else {
                square_to_cosine_hemisphere(u2)
            };
            let (value, pdf) = lobes.eval(wo, wi);
            if pdf > 0.0 {
                *o = reflection_sample(wi, value / pdf, pdf);
            }
        }
    }

    fn eval(
        &self,
        ctx: &mut ShadeContext<'_>,
        surface: SurfaceBatch<'_>,
        wi: &[Vec3],
        out: &mut [BsdfEval],
    ) {
        let [rd, rs, au, av] = ctx.lookup(self.textures, surface.uv);
        for (i, o) in out.iter_mut().enumerate() {
            let (value, pdf) = L::new(rd[i], rs[i], au[i], av[i]).eval(surface.wo[i], wi[i]);
            *o = BsdfEval { value, pdf };
        }
    }

    fn effects(&self) -> Effects {
        self.effects
    }

    fn gpu(&self) -> Option<GpuModule> {
        let params = self
            .textures
            .iter()
            .fold(GpuParams::new(), |p, &t| p.texture(t));
        Some(crate::gpu::module(L::GPU_IDENT, L::GPU_CODE, params))
    }
}
