//! The `diffuse` shader: an ideal one-sided Lambertian reflector.

use crate::gpu;
use crate::inputs::{fraction, half};
use crate::lobes::reflection_sample;
use radiant_core::glam::{Vec2, Vec3};
use radiant_core::params::Spanned;
use radiant_core::warp::{cosine_hemisphere_pdf, square_to_cosine_hemisphere};
use radiant_core::{
    BsdfEval, BsdfSample, BuildContext, Effects, GpuModule, GpuParams, ParamDoc, ParamError,
    Params, Registry, Rgb, ShadeContext, Shader, SurfaceBatch, TextureId, TextureInput,
};
use serde::Deserialize;
use std::f32::consts::FRAC_1_PI;

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct DiffuseParams {
    #[serde(default = "half")]
    reflectance: Spanned<TextureInput>,
}

const DOCS: &[ParamDoc] = &[ParamDoc {
    name: "reflectance",
    ty: "rgb | number | texture name, [0, 1]",
    default: "0.5",
    doc: "Albedo: the fraction of light reflected.",
}];

/// Lambertian reflection from the front side (Mitsuba 3's `diffuse`): light
/// arriving from or leaving towards the back side is absorbed.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Diffuse {
    reflectance: TextureId,
    effects: Effects,
}

impl Diffuse {
    /// A diffuse shader whose albedo is the texture `reflectance`.
    pub fn new(reflectance: TextureId, texture_effects: Effects) -> Self {
        Self {
            reflectance,
            effects: Effects::SMOOTH_LOBES | texture_effects,
        }
    }
}

impl Shader for Diffuse {
    fn uses_lobe_samples(&self) -> bool {
        false
    }

    fn sample(
        &self,
        ctx: &mut ShadeContext<'_>,
        surface: SurfaceBatch<'_>,
        u: &[Vec3],
        out: &mut [BsdfSample],
    ) {
        let [albedo] = ctx.lookup([self.reflectance], surface.uv);
        for (((wo, u), a), o) in surface.wo.iter().zip(u).zip(albedo).zip(out.iter_mut()) {
            let wi = square_to_cosine_hemisphere(Vec2::new(u.y, u.z));
            let pdf = cosine_hemisphere_pdf(wi);
            *o = if wo.z > 0.0 && pdf > 0.0 {
                reflection_sample(wi, *a, pdf)
            } else {
                BsdfSample::default()
            };
        }
    }

    fn eval(
        &self,
        ctx: &mut ShadeContext<'_>,
        surface: SurfaceBatch<'_>,
        wi: &[Vec3],
        out: &mut [BsdfEval],
    ) {
        let [albedo] = ctx.lookup([self.reflectance], surface.uv);
        for (((wo, wi), a), o) in surface.wo.iter().zip(wi).zip(albedo).zip(out.iter_mut()) {
            *o = if wo.z > 0.0 && wi.z > 0.0 {
                BsdfEval {
                    value: *a * (FRAC_1_PI * wi.z),
                    pdf: cosine_hemisphere_pdf(*wi),
                }
            } else {
                BsdfEval::default()
            };
        }
    }

    /// Exact: the reflectance seen from the front side, black from the
    /// back (what [`radiant_core::estimate_albedo`] finds, in one lookup
    /// instead of 16 samples: an `albedo` pass or `--denoise` of a diffuse
    /// scene spent most of its extra time there).
    fn albedo(&self, ctx: &mut ShadeContext<'_>, surface: SurfaceBatch<'_>, out: &mut [Rgb]) {
        let [albedo] = ctx.lookup([self.reflectance], surface.uv);
        for ((wo, a), o) in surface.wo.iter().zip(albedo).zip(out.iter_mut()) {
            *o = if wo.z > 0.0 {
                a.clamp(Rgb::ZERO, Rgb::ONE)
            } else {
                Rgb::ZERO
            };
        }
    }

    fn effects(&self) -> Effects {
        self.effects
    }

    fn gpu(&self) -> Option<GpuModule> {
        Some(gpu::module(
            "diffuse",
            &[gpu::DIFFUSE],
            GpuParams::new().texture(self.reflectance),
        ))
    }
}

fn build(params: &Params, ctx: &mut BuildContext<'_>) -> Result<Diffuse, ParamError> {
    let p: DiffuseParams = params.parse()?;
    let reflectance = fraction(ctx, &p.reflectance, "reflectance")?;
    let effects = ctx.textures.effects(reflectance);
    Ok(Diffuse::new(reflectance, effects))
}

pub(crate) fn register(registry: &mut Registry) {
    crate::register_shader(
        registry,
        "diffuse",
        "Ideal one-sided Lambertian reflector.",
        DOCS,
        build,
    );
}

#[cfg(test)]
mod tests {
    use super::*;
    use radiant_core::TextureTable;
    use radiant_core::params::check_param_docs;

    #[test]
    fn documented_parameters_match() {
        check_param_docs::<DiffuseParams>(DOCS).unwrap();
    }

    #[test]
    fn sample_weight_matches_eval_over_pdf_and_furnace_is_one() {
        let mut textures = TextureTable::default();
        let white = textures.add_constant(Rgb::ONE);
        let shader = Diffuse::new(white, Effects::empty());
        let mut ctx = ShadeContext::new(&textures);
        let n = 64usize;
        let wo = vec![Vec3::new(0.6, 0.0, 0.8); n * n];
        let uv = vec![Vec2::ZERO; n * n];
        let u: Vec<Vec3> = (0..n * n)
            .map(|i| {
                Vec3::new(
                    0.5,
                    ((i % n) as f32 + 0.5) / n as f32,
                    ((i / n) as f32 + 0.5) / n as f32,
                )
            })
            .collect();
        let surface = SurfaceBatch::new(&wo, &uv);
        let mut samples = vec![BsdfSample::default(); n * n];
        shader.sample(&mut ctx, surface, &u, &mut samples);
        let wi: Vec<Vec3> = samples.iter().map(|s| s.wi).collect();
        let mut evals = vec![BsdfEval::default(); n * n];
        shader.eval(&mut ctx, surface, &wi, &mut evals);
        let mut mean = 0.0f64;
        for (s, e) in samples.iter().zip(&evals) {
            if s.pdf > 0.0 {
                assert!((e.value / e.pdf - s.weight).abs().max_element() < 1e-4);
                assert!((e.pdf - s.pdf).abs() < 1e-5);
            }
            mean += s.weight.x as f64;
        }
        mean /= (n * n) as f64;
        assert!((mean - 1.0).abs() < 1e-3, "white furnace: {mean}");
    }

    /// The closed-form albedo is the estimate every shader has by default
    /// (16 samples' mean weight), front and back.
    #[test]
    fn albedo_is_the_sampled_estimate() {
        let mut textures = TextureTable::default();
        let colour = textures.add_constant(Rgb::new(0.2, 0.5, 0.9));
        let shader = Diffuse::new(colour, Effects::empty());
        let mut ctx = ShadeContext::new(&textures);
        let wo = [
            Vec3::Z,
            Vec3::new(0.6, 0.0, 0.8),
            Vec3::new(0.0, -0.28, 0.96),
            Vec3::new(0.0, 0.0, -1.0),
        ];
        let uv = [Vec2::ZERO; 4];
        let surface = SurfaceBatch::new(&wo, &uv);
        let (mut exact, mut estimate) = ([Rgb::ZERO; 4], [Rgb::ZERO; 4]);
        shader.albedo(&mut ctx, surface, &mut exact);
        radiant_core::estimate_albedo(&shader, &mut ctx, surface, &mut estimate);
        assert_eq!(exact[0], Rgb::new(0.2, 0.5, 0.9));
        assert_eq!(exact[3], Rgb::ZERO);
        for (a, b) in exact.iter().zip(&estimate) {
            assert!((*a - *b).abs().max_element() < 1e-6, "{a} against {b}");
        }
    }

    #[test]
    fn back_side_is_black() {
        let mut textures = TextureTable::default();
        let white = textures.add_constant(Rgb::ONE);
        let shader = Diffuse::new(white, Effects::empty());
        let mut ctx = ShadeContext::new(&textures);
        let (wo, uv) = ([Vec3::new(0.0, 0.0, -1.0)], [Vec2::ZERO]);
        let surface = SurfaceBatch::new(&wo, &uv);
        let mut e = [BsdfEval::default()];
        shader.eval(&mut ctx, surface, &[Vec3::Z], &mut e);
        assert_eq!(e[0].value, Rgb::ZERO);
        let mut s = [BsdfSample::default()];
        shader.sample(&mut ctx, surface, &[Vec3::splat(0.3)], &mut s);
        assert_eq!(s[0].weight, Rgb::ZERO);
    }
}
