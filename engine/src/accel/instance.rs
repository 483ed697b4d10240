//! Instances: a bottom-level hierarchy placed in render space.
//!
//! An instance maps its hierarchy's object space to render space: not at
//! all (the merged static geometry, already in render space), by a fixed
//! affine transform, or by a transform that moves while the shutter is
//! open (motion blur), interpolated per ray time — translation and scale
//! linearly, rotation by shortest-path slerp.
//!
//! Rays enter object space and hit points leave it with conservative
//! bounds on the rounding error of the transform (pbrt-v4's `Point3fi`
//! arithmetic): a ray's origin is moved forward along the ray by its
//! error bound, so a ray spawned from a surface cannot find that surface
//! again behind it, and a hit point's error bound grows by the
//! transform's rounding, so the next ray's offset covers it.

use crate::world::Trs;
use glam::{Affine3A, DMat4, DVec3, Mat3A, Vec3, Vec3A};
use obvhs::aabb::Aabb;

/// γ₃, the relative error bound of three roundings.
const GAMMA3: f32 = 3.0 * (f32::EPSILON * 0.5) / (1.0 - 3.0 * (f32::EPSILON * 0.5));

/// An affine transform in single precision with what its users need: the
/// inverse and the matrix for normals.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Placement {
    /// Object space to render space.
    pub to_render: Affine3A,
    /// Render space to object space.
    pub to_object: Affine3A,
    /// Transforms object-space normals to render space (the inverse
    /// transpose of the linear part).
    pub normals: Mat3A,
}

impl Placement {
    /// The placement of `m` (object to render space), computed in double
    /// precision; `None` if `m` is not invertible or not finite.
    pub fn new(m: DMat4) -> Option<Self> {
        let det = m.determinant();
        if !(det.is_finite() && det != 0.0) {
            return None;
        }
        let inv = m.inverse();
        let to_render = Affine3A::from_mat4(m.as_mat4());
        let to_object = Affine3A::from_mat4(inv.as_mat4());
        let normals = Mat3A::from(glam::DMat3::from_mat4(inv).transpose().as_mat3());
        let finite = to_render.is_finite() && to_object.is_finite() && normals.is_finite();
        finite.then_some(Self {
            to_render,
            to_object,
            normals,
        })
    }

    /// The ray `origin + t·dir` (render space) in object space, with the
    /// origin moved forward along the ray past its rounding error: returns
    /// the origin, the direction and the distance `dt` it moved, so that a
    /// hit at `t'` on the new ray lies at `t' + dt` on the old one.
    #[inline]
    pub fn ray_to_object(&self, origin: Vec3, dir: Vec3) -> (Vec3, Vec3, f32) {
        ray_to_object(&self.to_object, origin, dir)
    }

    /// Point `p` with error bound `err` (object space) in render space,
    /// with its error bound.
    #[inline]
    pub fn point_to_render(&self, p: Vec3, err: Vec3) -> (Vec3, Vec3) {
        let m = &self.to_render;
        let p = Vec3A::from(p);
        let out = m.transform_point3a(p);
        let carried = abs_mul(&m.matrix3, Vec3A::from(err)) * (GAMMA3 + 1.0);
        let rounding = (abs_mul(&m.matrix3, p.abs()) + m.translation.abs()) * GAMMA3;
        (Vec3::from(out), Vec3::from(carried + rounding))
    }

    /// Object-space normal `n` in render space, unit length (zero stays
    /// zero).
    #[inline]
    pub fn normal_to_render(&self, n: Vec3) -> Vec3 {
        Vec3::from(self.normals * Vec3A::from(n)).normalize_or_zero()
    }

    /// Object-space vector `v` (a tangent, a surface derivative) in render
    /// space, scaled by the transform.
    #[inline]
    pub fn vector_to_render(&self, v: Vec3) -> Vec3 {
        Vec3::from(self.to_render.matrix3 * Vec3A::from(v))
    }

    /// The render-space box around object-space box `b`.
    pub fn bounds(&self, b: &Aabb) -> Aabb {
        let mut out = Aabb::empty();
        for corner in corners(b) {
            out.extend(self.to_render.transform_point3a(corner));
        }
        out
    }
}

/// The ray `origin + t·dir` through `m` (render to object space), its
/// origin moved forward past the transform's rounding error; see
/// [`Placement::ray_to_object`].
#[inline(always)]
pub(super) fn ray_to_object(m: &Affine3A, origin: Vec3, dir: Vec3) -> (Vec3, Vec3, f32) {
    let o = Vec3A::from(origin);
    let po = m.transform_point3a(o);
    let d = m.transform_vector3a(Vec3A::from(dir));
    let err = (abs_mul(&m.matrix3, o.abs()) + m.translation.abs()) * GAMMA3;
    let l2 = d.length_squared();
    let dt = if l2 > 0.0 { d.abs().dot(err) / l2 } else { 0.0 };
    (Vec3::from(po + d * dt), Vec3::from(d), dt)
}

/// |m|·v: each entry of `m` by its absolute value.
#[inline]
fn abs_mul(m: &Mat3A, v: Vec3A) -> Vec3A {
    m.x_axis.abs() * v.x + m.y_axis.abs() * v.y + m.z_axis.abs() * v.z
}

/// The eight corners of `b`.
fn corners(b: &Aabb) -> [Vec3A; 8] {
    std::array::from_fn(|i| {
        Vec3A::new(
            if i & 1 == 0 { b.min.x } else { b.max.x },
            if i & 2 == 0 { b.min.y } else { b.max.y },
            if i & 4 == 0 { b.min.z } else { b.max.z },
        )
    })
}

/// A placement that changes while the shutter is open: `outer · T·R·S(τ)
/// · inner`, where the pose moves from `open` (τ = 0) to `close` (τ = 1),
/// translation and scale linearly, rotation by slerp.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Motion {
    /// Applied after the pose (e.g. an instance's own transform and the
    /// shift to render space).
    pub outer: DMat4,
    /// The pose when the shutter opens.
    pub open: Trs,
    /// The pose when it closes.
    pub close: Trs,
    /// Applied before the pose (the shape's static `transform`).
    pub inner: DMat4,
}

/// Subintervals of the shutter at which [`Motion::bounds`] samples the
/// motion.
const MOTION_BOUND_STEPS: u32 = 32;

impl Motion {
    /// The object-to-render matrix at shutter time `tau` in [0, 1].
    pub fn matrix(&self, tau: f64) -> DMat4 {
        self.outer * Trs::lerp(&self.open, &self.close, tau).matrix() * self.inner
    }

    /// The placement at shutter time `tau` (`None` where it is singular).
    #[inline]
    pub fn at(&self, tau: f32) -> Option<Placement> {
        Placement::new(self.matrix(f64::from(tau)))
    }

    /// A render-space box that contains object-space box `b` at every
    /// time the shutter is open. The box is sampled at the ends of
    /// [`MOTION_BOUND_STEPS`] subintervals and grown by half the farthest
    /// any point of `b` can travel within one of them, a bound on the
    /// speed of T·R·S(τ) (translation, turning and scaling) times the
    /// subinterval's length — conservative however the pose turns.
    pub fn bounds(&self, b: &Aabb) -> Aabb {
        let mut out = Aabb::empty();
        for i in 0..=MOTION_BOUND_STEPS {
            let m = self.matrix(f64::from(i) / f64::from(MOTION_BOUND_STEPS));
            for c in corners(b) {
                let p = m.transform_point3(c.as_dvec3());
                out.extend(p.as_vec3a());
            }
        }
        // The object box's farthest point from the pose's origin after
        // `inner`.
        let reach = corners(b)
            .iter()
            .map(|c| self.inner.transform_point3(c.as_dvec3()).length())
            .fold(0.0f64, f64::max);
        let scale = |t: &Trs| t.scale.abs().max_element();
        let turn = {
            let dot = self.open.rotate.dot(self.close.rotate).abs().min(1.0);
            2.0 * dot.acos()
        };
        let dt = (self.close.translate - self.open.translate).length();
        let ds = (self.close.scale - self.open.scale).abs().max_element();
        let speed = dt + turn * scale(&self.open).max(scale(&self.close)) * reach + ds * reach;
        let stretch = norm_bound(&self.outer);
        let grow = 0.5 * speed * stretch / f64::from(MOTION_BOUND_STEPS);
        // Plus a relative margin for the rounding of the samples.
        let margin = DVec3::splat(grow) + out.diagonal().abs().as_dvec3() * 1e-6;
        let m = margin.as_vec3a();
        Aabb::new(out.min - m, out.max + m)
    }
}

/// An upper bound on how much the linear part of `m` stretches a vector
/// (the Frobenius norm).
fn norm_bound(m: &DMat4) -> f64 {
    let l = glam::DMat3::from_mat4(*m);
    (l.x_axis.length_squared() + l.y_axis.length_squared() + l.z_axis.length_squared()).sqrt()
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::DQuat;

    use crate::accel::tests::lcg;

    #[test]
    fn rays_and_points_round_trip_within_their_error_bounds() {
        let m = DMat4::from_scale_rotation_translation(
            DVec3::new(2.0, 0.5, 3.0),
            DQuat::from_euler(glam::EulerRot::XYZ, 0.3, -1.1, 2.0),
            DVec3::new(1e3, -20.0, 0.25),
        );
        let x = Placement::new(m).expect("invertible");
        let mut s = 5;
        for _ in 0..1000 {
            let p = Vec3::new(lcg(&mut s), lcg(&mut s), lcg(&mut s)) * 4.0 - 2.0;
            let (q, err) = x.point_to_render(p, Vec3::ZERO);
            let exact = m.transform_point3(p.as_dvec3());
            let off = (q.as_dvec3() - exact).abs();
            assert!(off.cmple(err.as_dvec3()).all(), "{off} > {err}");
            // The ray from far away towards `q`: in object space it still
            // passes `p` (its origin moved forward a little).
            let origin = Vec3::new(5.0, 7.0, -3.0);
            let (o, d, dt) = x.ray_to_object(origin, q - origin);
            assert!((0.0..1e-5).contains(&dt), "{dt}");
            let at = o + d * (1.0 - dt);
            assert!((at - p).length() < 1e-3, "{at} vs {p}");
        }
        let n = x.normal_to_render(Vec3::Z);
        let tangent = m.transform_vector3(DVec3::X).as_vec3();
        assert!(n.dot(tangent).abs() < 1e-5 && (n.length() - 1.0).abs() < 1e-6);
        assert!(Placement::new(DMat4::from_scale(DVec3::new(1.0, 0.0, 1.0))).is_none());
    }

    #[test]
    fn motion_bounds_contain_every_time_of_the_shutter() {
        let b = Aabb::new(Vec3A::new(-1.0, -0.5, -2.0), Vec3A::new(1.5, 0.5, 0.3));
        let motions = [
            // A half turn with a slide and a growth.
            Motion {
                outer: DMat4::from_translation(DVec3::new(0.0, 1.0, 0.0)),
                open: Trs::IDENTITY,
                close: Trs {
                    translate: DVec3::new(3.0, 0.0, 0.0),
                    rotate: DQuat::from_rotation_y(179f64.to_radians()),
                    scale: DVec3::splat(2.0),
                },
                inner: DMat4::from_translation(DVec3::new(2.0, 0.0, 0.0)),
            },
            // A spin about a far axis (the box sweeps far outside both ends).
            Motion {
                outer: DMat4::IDENTITY,
                open: Trs::IDENTITY,
                close: Trs {
                    rotate: DQuat::from_rotation_z(120f64.to_radians()),
                    ..Trs::IDENTITY
                },
                inner: DMat4::from_translation(DVec3::new(10.0, 0.0, 0.0)),
            },
        ];
        let mut s = 11;
        for motion in motions {
            let bounds = motion.bounds(&b);
            for _ in 0..20_000 {
                let tau = lcg(&mut s);
                let p = Vec3A::new(lcg(&mut s), lcg(&mut s), lcg(&mut s));
                let p = b.min + (b.max - b.min) * p;
                let q = motion.matrix(f64::from(tau)).transform_point3(p.as_dvec3());
                assert!(
                    bounds.contains_point(q.as_vec3a()),
                    "{q} at τ {tau} outside {bounds:?}"
                );
            }
        }
    }
}
