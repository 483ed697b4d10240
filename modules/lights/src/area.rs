//! The `area` light: uniform, one-sided diffuse emission from a shape.
//!
//! Next-event estimation picks a primitive in proportion to its area, then
//! a point on it: uniformly by area on triangles, and on spheres uniformly
//! in the solid angle the sphere subtends when the reference point is
//! outside it (uniformly by area from inside). `eval_hits` returns the
//! density of the same strategy for the primitive that was hit.

use crate::sphere::Cone;
use radiant_core::glam::{Vec2, Vec3};
use radiant_core::warp::{square_to_uniform_sphere, square_to_uniform_triangle};
use radiant_core::{
    Color, Effects, EmitterEval, EmitterHit, EmitterShape, Light, LightSample, ModuleInfo,
    ParamDoc, ParamError, Params, Registry, Rgb, luminance,
};
use serde::Deserialize;

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct AreaParams {
    radiance: Color,
}

const DOCS: &[ParamDoc] = &[ParamDoc {
    name: "radiance",
    ty: "rgb, W/(m²·sr)",
    default: "required",
    doc: "Emitted radiance, the same at every point and in every direction of the front side.",
}];

/// Diffuse emission from the front side (the side the normal points to) of
/// every primitive of a shape. Points are sampled uniformly by area, or by
/// solid angle on spheres seen from outside.
#[derive(Debug, Clone, PartialEq)]
pub struct AreaLight {
    radiance: Rgb,
    shape: EmitterShape,
    /// Cumulative areas of the primitives (triangles, then spheres).
    cdf: Vec<f32>,
    area: f32,
}

impl AreaLight {
    /// An area light over `shape` with constant `radiance`.
    pub fn new(radiance: Rgb, shape: EmitterShape) -> Result<Self, String> {
        let mut cdf = Vec::with_capacity(shape.triangles.len() + shape.spheres.len());
        let mut total = 0.0f64;
        for [a, b, c] in &shape.triangles {
            total += 0.5 * (*b - *a).cross(*c - *a).length() as f64;
            cdf.push(total as f32);
        }
        for (_, r) in &shape.spheres {
            total += 4.0 * std::f64::consts::PI * (*r as f64).powi(2);
            cdf.push(total as f32);
        }
        if !(total > 0.0 && total.is_finite()) {
            return Err("an area light needs a shape with a positive, finite surface area".into());
        }
        Ok(Self {
            radiance,
            shape,
            cdf,
            area: total as f32,
        })
    }

    /// Picks a primitive in proportion to its area and returns it with `u`
    /// rescaled to [0,1) for reuse.
    #[inline]
    fn pick(&self, u: f32) -> (usize, f32) {
        let target = u * self.area;
        let i = self
            .cdf
            .partition_point(|&c| c <= target)
            .min(self.cdf.len() - 1);
        let lo = if i == 0 { 0.0 } else { self.cdf[i - 1] };
        let width = self.cdf[i] - lo;
        let rescaled = if width > 0.0 {
            ((target - lo) / width).clamp(0.0, 0.999_999_94)
        } else {
            0.0
        };
        (i, rescaled)
    }

    /// Probability of picking primitive `prim`.
    #[inline]
    fn prim_probability(&self, prim: usize) -> f32 {
        let lo = if prim == 0 { 0.0 } else { self.cdf[prim - 1] };
        (self.cdf[prim] - lo) / self.area
    }

    /// The sphere primitive `prim` with its subtended cone from `origin`,
    /// if `prim` is a sphere and `origin` lies outside it.
    #[inline]
    fn cone(&self, prim: usize, origin: Vec3) -> Option<(Vec3, f32, Cone)> {
        let (centre, r) = *self
            .shape
            .spheres
            .get(prim.checked_sub(self.shape.triangles.len())?)?;
        Cone::new(centre, r, origin).map(|cone| (centre, r, cone))
    }

    /// A point and normal on primitive `prim`, uniformly by area.
    #[inline]
    fn point_on(&self, prim: usize, u: Vec2) -> (Vec3, Vec3) {
        let ntri = self.shape.triangles.len();
        if prim < ntri {
            let [a, b, c] = self.shape.triangles[prim];
            let bary = square_to_uniform_triangle(u);
            let p = a * (1.0 - bary.x - bary.y) + b * bary.x + c * bary.y;
            (p, (b - a).cross(c - a).normalize())
        } else {
            let (centre, r) = self.shape.spheres[prim - ntri];
            let n = square_to_uniform_sphere(u);
            (centre + n * r, n)
        }
    }

    /// Solid-angle density of sampling point `p` (normal `n`) of primitive
    /// `prim` from `origin`; 0 if `p` faces away. (A sphere seen from
    /// outside is only ever seen, and sampled, on its front cap, so its
    /// density does not depend on the rounding of `n` at the silhouette.)
    #[inline]
    fn pdf(&self, prim: usize, origin: Vec3, p: Vec3, n: Vec3) -> f32 {
        if let Some((_, _, cone)) = self.cone(prim, origin) {
            return self.prim_probability(prim) * cone.pdf();
        }
        let d = origin - p;
        let dist2 = d.length_squared();
        let cos_l = n.dot(d) / dist2.sqrt();
        if cos_l > 0.0 {
            dist2 / (cos_l * self.area)
        } else {
            0.0
        }
    }
}

impl Light for AreaLight {
    fn power(&self) -> f32 {
        luminance(self.radiance) * self.area * std::f32::consts::PI
    }

    fn is_delta(&self) -> bool {
        false
    }

    fn sample(&self, refs: &[Vec3], u: &[Vec2], out: &mut [LightSample]) {
        for ((r, u), o) in refs.iter().zip(u).zip(out.iter_mut()) {
            let (prim, ux) = self.pick(u.x);
            let u = Vec2::new(ux, u.y);
            let (p, n) = match self.cone(prim, *r) {
                Some((centre, radius, cone)) => cone.sample(centre, radius, *r, u),
                None => self.point_on(prim, u),
            };
            let pdf = self.pdf(prim, *r, p, n);
            *o = if pdf > 0.0 && pdf.is_finite() {
                LightSample {
                    p,
                    n,
                    radiance: self.radiance,
                    pdf,
                }
            } else {
                LightSample {
                    p,
                    n,
                    radiance: Rgb::ZERO,
                    pdf: 0.0,
                }
            };
        }
    }

    fn eval_hits(&self, hits: &[EmitterHit], out: &mut [EmitterEval]) {
        let nprims = self.cdf.len();
        for (h, o) in hits.iter().zip(out.iter_mut()) {
            let prim = (h.primitive as usize).min(nprims - 1);
            let pdf = self.pdf(prim, h.origin, h.p, h.n);
            *o = if pdf > 0.0 {
                EmitterEval {
                    radiance: self.radiance,
                    pdf,
                }
            } else {
                EmitterEval::default()
            };
        }
    }

    fn effects(&self) -> Effects {
        Effects::AREA_LIGHTS
    }
}

pub(crate) fn register(registry: &mut Registry) {
    registry.register::<dyn Light>(
        ModuleInfo {
            type_name: "area",
            summary: "Uniform one-sided emission from a shape; declare it as a shape's `emitter`.",
            params: DOCS,
        },
        |params: &Params, ctx| {
            let p: AreaParams = params.parse()?;
            let shape = ctx.emitter_shape.ok_or_else(|| {
                ParamError::new(
                    "an `area` light must be attached to a shape: write it as the shape's `emitter:`",
                )
            })?;
            let light = AreaLight::new(p.radiance.0, shape.clone()).map_err(|m| ParamError {
                message: m,
                location: None,
            })?;
            Ok(Box::new(light) as Box<dyn Light>)
        },
    );
}

#[cfg(test)]
mod tests {
    use super::*;
    use radiant_core::params::check_param_docs;

    fn unit_square() -> EmitterShape {
        // The square [0,1]² at z = 0, normal +z.
        EmitterShape {
            triangles: vec![
                [Vec3::ZERO, Vec3::X, Vec3::new(1.0, 1.0, 0.0)],
                [Vec3::ZERO, Vec3::new(1.0, 1.0, 0.0), Vec3::Y],
            ],
            spheres: vec![],
        }
    }

    #[test]
    fn documented_parameters_match() {
        check_param_docs::<AreaParams>(DOCS).unwrap();
    }

    #[test]
    fn samples_agree_with_eval_hits() {
        let light = AreaLight::new(Rgb::ONE, unit_square()).unwrap();
        let refs = [Vec3::new(0.3, 0.2, 2.0); 64];
        let u: Vec<Vec2> = (0..64)
            .map(|i| Vec2::new((i % 8) as f32 / 8.0 + 0.01, (i / 8) as f32 / 8.0 + 0.03))
            .collect();
        let mut out = [LightSample::default(); 64];
        light.sample(&refs, &u, &mut out);
        for (s, r) in out.iter().zip(&refs) {
            assert!(s.pdf > 0.0 && s.p.z == 0.0 && (0.0..=1.0).contains(&s.p.x));
            let hit = EmitterHit {
                origin: *r,
                p: s.p,
                n: s.n,
                primitive: 0,
            };
            let mut e = [EmitterEval::default()];
            light.eval_hits(&[hit], &mut e);
            assert!((e[0].pdf - s.pdf).abs() < 1e-4 * s.pdf);
            assert_eq!(e[0].radiance, s.radiance);
        }
    }

    #[test]
    fn emits_only_from_the_front() {
        let light = AreaLight::new(Rgb::ONE, unit_square()).unwrap();
        let mut out = [LightSample::default()];
        light.sample(&[Vec3::new(0.5, 0.5, -1.0)], &[Vec2::splat(0.5)], &mut out);
        assert_eq!(out[0].pdf, 0.0);
        assert_eq!(out[0].radiance, Rgb::ZERO);
    }

    #[test]
    fn solid_angle_pdf_integrates_to_one() {
        // Estimate ∫ pdf dω over the light by sampling directions uniformly
        // over the hemisphere below the light: should be 1.
        let light = AreaLight::new(Rgb::ONE, unit_square()).unwrap();
        let origin = Vec3::new(0.5, 0.5, 0.5);
        let n = 400;
        let mut sum = 0.0f64;
        for i in 0..n * n {
            let u = Vec2::new(
                ((i % n) as f32 + 0.5) / n as f32,
                ((i / n) as f32 + 0.5) / n as f32,
            );
            // Uniform directions over the lower hemisphere: density 1/2π.
            let mut d = square_to_uniform_sphere(u);
            d.z = -d.z.abs();
            let t = -origin.z / d.z;
            if t <= 0.0 {
                continue;
            }
            let p = origin + d * t;
            if !(0.0..=1.0).contains(&p.x) || !(0.0..=1.0).contains(&p.y) {
                continue;
            }
            let mut e = [EmitterEval::default()];
            light.eval_hits(
                &[EmitterHit {
                    origin,
                    p,
                    n: Vec3::Z,
                    primitive: 0,
                }],
                &mut e,
            );
            sum += e[0].pdf as f64 * 2.0 * std::f64::consts::PI / (n * n) as f64;
        }
        assert!((sum - 1.0).abs() < 0.02, "∫pdf = {sum}");
    }
}
