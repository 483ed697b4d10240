//! The `area` light: uniform, one-sided diffuse emission from a shape.
//!
//! Next-event estimation picks a part of the shape in proportion to its
//! area, then a point on it: on spheres uniformly in the solid angle the
//! sphere subtends when the reference point is outside it, on rectangles
//! (pairs of triangles that form one, as `rectangle` and `cube` shapes
//! tessellate) uniformly in the solid angle of the spherical rectangle
//! ([`crate::rectangle`]), and otherwise uniformly by area. `eval_hits`
//! returns the density of the same strategy for the part that was hit.

use crate::params::check_colour;
use crate::rectangle::Rectangle;
use crate::sphere::{Cone, ConeSamples};
use radiant_core::glam::{Vec2, Vec3, Vec4};
use radiant_core::warp::{square_to_uniform_sphere, square_to_uniform_triangle};
use radiant_core::{
    Color, Effects, EmitterEval, EmitterHit, EmitterShape, GpuModule, GpuParams, Light,
    LightBounds, LightSample, ModuleInfo, ParamDoc, ParamError, Params, Registry, Rgb, luminance,
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

/// What next-event estimation samples as one unit.
#[derive(Debug, Clone, Copy, PartialEq)]
enum Part {
    /// A triangle, by area, with its unit normal (by winding).
    Triangle([Vec3; 3], Vec3),
    /// Two triangles forming a rectangle, by solid angle where reliable.
    Rectangle(Rectangle),
    /// A sphere (centre, radius), by solid angle from outside.
    Sphere(Vec3, f32),
}

impl Part {
    fn area(&self) -> f64 {
        match *self {
            Part::Triangle([a, b, c], _) => 0.5 * (b - a).cross(c - a).length() as f64,
            Part::Rectangle(r) => r.area() as f64,
            Part::Sphere(_, r) => 4.0 * std::f64::consts::PI * (r as f64).powi(2),
        }
    }
}

/// Diffuse emission from the front side (the side the normal points to) of
/// every primitive of a shape. Points are sampled by solid angle on
/// spheres seen from outside and on rectangles, by area elsewhere.
#[derive(Debug, Clone, PartialEq)]
pub struct AreaLight {
    radiance: Rgb,
    parts: Vec<Part>,
    /// The part of each primitive of the shape (triangles, then spheres).
    part_of: Vec<u32>,
    /// Cumulative areas of the parts.
    cdf: Vec<f32>,
    /// Probability of picking each part (its share of the area).
    probability: Vec<f32>,
    area: f32,
    /// Box, normal cone and power, for spatial light selection.
    bounds: LightBounds,
}

impl AreaLight {
    /// An area light over `shape` with constant `radiance`.
    pub fn new(radiance: Rgb, shape: EmitterShape) -> Result<Self, String> {
        let mut parts = Vec::with_capacity(shape.triangles.len() + shape.spheres.len());
        let mut part_of = Vec::with_capacity(parts.capacity());
        let mut i = 0;
        while i < shape.triangles.len() {
            let pair = shape
                .triangles
                .get(i + 1)
                .and_then(|t1| Rectangle::from_triangles(shape.triangles[i], *t1));
            part_of.push(parts.len() as u32);
            match pair {
                Some(rect) => {
                    part_of.push(parts.len() as u32);
                    parts.push(Part::Rectangle(rect));
                    i += 2;
                }
                None => {
                    let [a, b, c] = shape.triangles[i];
                    parts.push(Part::Triangle([a, b, c], (b - a).cross(c - a).normalize()));
                    i += 1;
                }
            }
        }
        for &(centre, r) in &shape.spheres {
            part_of.push(parts.len() as u32);
            parts.push(Part::Sphere(centre, r));
        }
        let mut cdf = Vec::with_capacity(parts.len());
        let mut total = 0.0f64;
        for part in &parts {
            total += part.area();
            cdf.push(total as f32);
        }
        if !(total > 0.0 && total.is_finite()) {
            return Err("an area light needs a shape with a positive, finite surface area".into());
        }
        let probability = parts.iter().map(|p| (p.area() / total) as f32).collect();
        let bounds = shape_bounds(&shape, luminance(radiance) * total as f32);
        Ok(Self {
            radiance,
            parts,
            part_of,
            cdf,
            probability,
            area: total as f32,
            bounds,
        })
    }

    /// Picks a part in proportion to its area and returns it with `u`
    /// rescaled to [0,1) for reuse.
    #[inline]
    fn pick(&self, u: f32) -> (usize, f32) {
        if self.parts.len() == 1 {
            return (0, u);
        }
        let target = u * self.area;
        let i = self
            .cdf
            .partition_point(|&c| c <= target)
            .min(self.cdf.len() - 1);
        let lo = if i == 0 { 0.0 } else { self.cdf[i - 1] };
        let width = self.cdf[i] - lo;
        let rescaled = if width > 0.0 {
            ((target - lo) / width).clamp(0.0, radiant_core::ONE_MINUS_EPSILON)
        } else {
            0.0
        };
        (i, rescaled)
    }

    /// Probability of picking part `part`.
    #[inline]
    fn part_probability(&self, part: usize) -> f32 {
        self.probability[part]
    }

    /// A point on part `part` (with its normal) for `origin`, and the
    /// solid-angle density of the whole strategy for it.
    #[inline(always)]
    fn sample_part(&self, part: usize, origin: Vec3, u: Vec2) -> (Vec3, Vec3, f32) {
        let probability = self.part_probability(part);
        match &self.parts[part] {
            Part::Rectangle(rect) => {
                if let Some(s) = rect.spherical(origin) {
                    return (s.sample(u), rect.n, probability / s.solid_angle);
                }
                let p = rect.point(u);
                (p, rect.n, self.area_pdf(origin, p, rect.n))
            }
            &Part::Sphere(centre, r) => self.sample_sphere(centre, r, probability, origin, u),
            Part::Triangle(..) => {
                let (p, n) = self.point_by_area(part, u);
                (p, n, self.area_pdf(origin, p, n))
            }
        }
    }

    /// A point on the sphere (`centre`, `r`), picked with `probability`,
    /// for `origin`, its normal and the solid-angle density of the whole
    /// strategy for it: in the cone the sphere subtends from outside, by
    /// area from inside.
    #[inline(always)]
    fn sample_sphere(
        &self,
        centre: Vec3,
        r: f32,
        probability: f32,
        origin: Vec3,
        u: Vec2,
    ) -> (Vec3, Vec3, f32) {
        match Cone::new(centre, r, origin) {
            Some(cone) => {
                let (p, n) = cone.sample(centre, r, origin, u);
                (p, n, probability * cone.pdf())
            }
            None => {
                let n = square_to_uniform_sphere(u);
                let p = centre + n * r;
                (p, n, self.area_pdf(origin, p, n))
            }
        }
    }

    /// Samples a light of one rectangle in two tight passes over the
    /// batch: by area for every reference point, then by solid angle for
    /// the few near it (what [`Self::sample_part`] does in one).
    fn sample_rectangle(
        &self,
        rect: &Rectangle,
        refs: &[Vec3],
        u: &[Vec2],
        out: &mut [LightSample],
    ) {
        for ((r, u), o) in refs.iter().zip(u).zip(out.iter_mut()) {
            let p = rect.point(*u);
            *o = self.light_sample(p, rect.n, self.area_pdf(*r, p, rect.n));
        }
        let probability = self.part_probability(0);
        for ((r, u), o) in refs.iter().zip(u).zip(out.iter_mut()) {
            if let Some(s) = rect.spherical(*r) {
                *o = self.light_sample(s.sample(*u), rect.n, probability / s.solid_angle);
            }
        }
    }

    /// Samples a light of one sphere, four reference points at a time
    /// ([`ConeSamples`]); points not outside the sphere take
    /// [`Self::sample_sphere`]'s area sampling one by one.
    fn sample_one_sphere(
        &self,
        centre: Vec3,
        r: f32,
        refs: &[Vec3],
        u: &[Vec2],
        out: &mut [LightSample],
    ) {
        let probability = self.part_probability(0);
        let n = refs.len().min(u.len()).min(out.len());
        for start in (0..n).step_by(4) {
            let end = (start + 4).min(n);
            // The last group repeats its last point in the lanes past `n`.
            let at = |k: usize| (start + k).min(end - 1);
            let origins = [0, 1, 2, 3].map(|k| refs[at(k)].extend(0.0));
            let lanes = ConeSamples::new(centre, r, origins, [0, 1, 2, 3].map(|k| u[at(k)]));
            for (k, o) in out[start..end].iter_mut().enumerate() {
                *o = if lanes.outside.test(k) {
                    let lane = |v: &[Vec4; 3]| Vec3::new(v[0][k], v[1][k], v[2][k]);
                    let pdf = probability * lanes.pdf[k];
                    self.light_sample(lane(&lanes.p), lane(&lanes.n), pdf)
                } else {
                    let (i, ui) = (start + k, u[start + k]);
                    let (p, n, pdf) = self.sample_sphere(centre, r, probability, refs[i], ui);
                    self.light_sample(p, n, pdf)
                };
            }
        }
    }

    /// The sample at `p` (normal `n`) of density `pdf`; a failed one
    /// (radiance and density 0) where `pdf` is not positive and finite.
    #[inline(always)]
    fn light_sample(&self, p: Vec3, n: Vec3, pdf: f32) -> LightSample {
        let ok = pdf > 0.0 && pdf.is_finite();
        LightSample {
            p,
            n,
            radiance: if ok { self.radiance } else { Rgb::ZERO },
            pdf: if ok { pdf } else { 0.0 },
        }
    }

    /// A point of part `part` (with its normal), uniform by area.
    #[inline(always)]
    fn point_by_area(&self, part: usize, u: Vec2) -> (Vec3, Vec3) {
        match self.parts[part] {
            Part::Triangle([a, b, c], n) => {
                let bary = square_to_uniform_triangle(u);
                (a * (1.0 - bary.x - bary.y) + b * bary.x + c * bary.y, n)
            }
            Part::Rectangle(rect) => (rect.point(u), rect.n),
            Part::Sphere(centre, r) => {
                let n = square_to_uniform_sphere(u);
                (centre + n * r, n)
            }
        }
    }

    /// Solid-angle density of sampling point `p` (normal `n`) of part
    /// `part` from `origin`; 0 if `p` faces away. (A sphere seen from
    /// outside is only ever seen, and sampled, on its front cap, so its
    /// density does not depend on the rounding of `n` at the silhouette.)
    #[inline(always)]
    fn pdf(&self, part: usize, origin: Vec3, p: Vec3, n: Vec3) -> f32 {
        match self.parts[part] {
            Part::Sphere(centre, r) => {
                if let Some(cone) = Cone::new(centre, r, origin) {
                    return self.part_probability(part) * cone.pdf();
                }
            }
            Part::Rectangle(rect) => {
                if let Some(s) = rect.spherical(origin) {
                    return self.part_probability(part) / s.solid_angle;
                }
            }
            Part::Triangle(..) => {}
        }
        self.area_pdf(origin, p, n)
    }

    /// Solid-angle density of point `p` (normal `n`) from `origin` when
    /// its part is sampled by area; 0 if `p` faces away.
    #[inline(always)]
    fn area_pdf(&self, origin: Vec3, p: Vec3, n: Vec3) -> f32 {
        // dist² / (cos θ · area) with cos θ = n·d / dist: one division.
        let d = origin - p;
        let dist2 = d.length_squared();
        let n_dot_d = n.dot(d);
        if n_dot_d > 0.0 {
            dist2 * dist2.sqrt() / (n_dot_d * self.area)
        } else {
            0.0
        }
    }
}

/// The box of `shape`, the cone of its normals (every direction where it
/// has a sphere) and its power `phi`.
fn shape_bounds(shape: &EmitterShape, phi: f32) -> LightBounds {
    let (mut min, mut max) = (Vec3::splat(f32::INFINITY), Vec3::splat(f32::NEG_INFINITY));
    let mut normal_sum = Vec3::ZERO;
    for [a, b, c] in &shape.triangles {
        min = min.min(a.min(b.min(*c)));
        max = max.max(a.max(b.max(*c)));
        normal_sum += (*b - *a).cross(*c - *a);
    }
    for &(centre, r) in &shape.spheres {
        min = min.min(centre - Vec3::splat(r));
        max = max.max(centre + Vec3::splat(r));
    }
    let normals = shape
        .triangles
        .iter()
        .map(|[a, b, c]| (*b - *a).cross(*c - *a).normalize_or_zero());
    let sum = if shape.spheres.is_empty() {
        normal_sum
    } else {
        Vec3::ZERO
    };
    LightBounds::surface(min, max, phi, sum, normals)
}

impl Light for AreaLight {
    fn power(&self) -> f32 {
        luminance(self.radiance) * self.area * std::f32::consts::PI
    }

    fn bounds(&self) -> Option<LightBounds> {
        Some(self.bounds)
    }

    fn is_delta(&self) -> bool {
        false
    }

    fn sample(&self, refs: &[Vec3], u: &[Vec2], out: &mut [LightSample]) {
        // One part (the usual `rectangle` or `sphere` emitter): a loop
        // without picking or dispatch per sample.
        match self.parts.as_slice() {
            [Part::Rectangle(rect)] => self.sample_rectangle(rect, refs, u, out),
            &[Part::Sphere(centre, r)] => self.sample_one_sphere(centre, r, refs, u, out),
            _ => {
                for ((r, u), o) in refs.iter().zip(u).zip(out.iter_mut()) {
                    let (part, ux) = self.pick(u.x);
                    let (p, n, pdf) = self.sample_part(part, *r, Vec2::new(ux, u.y));
                    *o = self.light_sample(p, n, pdf);
                }
            }
        }
    }

    fn eval_hits(&self, hits: &[EmitterHit], out: &mut [EmitterEval]) {
        let last = self.part_of.len() - 1;
        for (h, o) in hits.iter().zip(out.iter_mut()) {
            let part = self.part_of[(h.primitive as usize).min(last)] as usize;
            let pdf = self.pdf(part, h.origin, h.p, h.n);
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

    fn emission(&self) -> Option<&dyn radiant_core::Emission> {
        Some(self)
    }

    fn gpu(&self) -> Option<GpuModule> {
        let mut params = GpuParams::new()
            .rgb(self.radiance)
            .u32(self.parts.len() as u32)
            .u32(self.part_of.len() as u32);
        for (i, part) in self.parts.iter().enumerate() {
            let head = |kind: u32| {
                GpuParams::new()
                    .u32(kind)
                    .f32(self.probability[i])
                    .f32(self.cdf[i])
            };
            let record = match *part {
                Part::Triangle([a, b, c], n) => head(0).vec3(a).vec3(b).vec3(c).vec3(n),
                Part::Rectangle(r) => head(1).vec3(r.corner).vec3(r.ex).vec3(r.ey).vec3(r.n),
                Part::Sphere(centre, radius) => head(2).vec3(centre).f32(radius).f32s([0.0; 8]),
            };
            debug_assert_eq!(record.len(), 15);
            params = params.append(&record).f32(0.0);
        }
        for &part in &self.part_of {
            params = params.u32(part);
        }
        Some(GpuModule::new("area", include_str!("area.wgsl"), params))
    }
}

use crate::emitted::cosine_direction;
use radiant_core::{Emission, EmissionKind, EmissionPdf, EmissionSample, EmittedRay};

/// Emitted rays: a part in proportion to its area, a point uniformly on
/// it (density 1 / total area), a cosine-weighted direction about its
/// normal.
impl Emission for AreaLight {
    fn kind(&self) -> EmissionKind {
        EmissionKind::Surface
    }

    fn sample_emission(&self, u_pos: &[Vec2], u_dir: &[Vec2], out: &mut [EmissionSample]) {
        for ((up, ud), o) in u_pos.iter().zip(u_dir).zip(out.iter_mut()) {
            let (part, ux) = self.pick(up.x);
            let (p, n) = self.point_by_area(part, Vec2::new(ux, up.y));
            let (dir, pdf_dir) = cosine_direction(n, *ud);
            // The first primitive of the part (parts are consecutive).
            let primitive = self.part_of.partition_point(|&q| (q as usize) < part) as u32;
            *o = EmissionSample {
                p,
                n,
                dir,
                radiance: self.radiance,
                pdf_pos: if pdf_dir > 0.0 { 1.0 / self.area } else { 0.0 },
                pdf_dir,
                kind: EmissionKind::Surface,
                primitive,
            };
        }
    }

    fn emission_pdf(&self, rays: &[EmittedRay], out: &mut [EmissionPdf]) {
        for (r, o) in rays.iter().zip(out.iter_mut()) {
            let cos = r.n.dot(r.dir);
            *o = if cos > 0.0 {
                EmissionPdf {
                    pdf_pos: 1.0 / self.area,
                    pdf_dir: cos * std::f32::consts::FRAC_1_PI,
                }
            } else {
                EmissionPdf::default()
            };
        }
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
            check_colour(params, "radiance", p.radiance.0)?;
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
