//! Solid-angle sampling of a sphere seen from outside: directions uniform
//! in the cone the sphere subtends (pbrt-v4's `Sphere::Sample`, with its
//! Taylor expansion for spheres smaller than 1.5° so that distant spheres
//! keep their precision). From inside, callers fall back to area sampling.

use radiant_core::Frame;
use radiant_core::glam::{BVec4A, Mat4, Vec2, Vec3, Vec4};
use std::f32::consts::{FRAC_PI_2, TAU};

/// sin² 1.5°: below it the cone is handled by its Taylor expansion.
const SMALL_SIN2: f32 = 0.000_685_23;

/// The cone a sphere subtends from a point outside it.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct Cone {
    sin2_max: f32,
    cos_max: f32,
    /// 1 − cos θmax, accurately for small cones.
    one_minus_cos_max: f32,
}

impl Cone {
    /// The cone of the sphere (`centre`, `radius`) from `origin`, or `None`
    /// if `origin` is not outside the sphere.
    #[inline]
    pub(crate) fn new(centre: Vec3, radius: f32, origin: Vec3) -> Option<Self> {
        let dist2 = (centre - origin).length_squared();
        let r2 = radius * radius;
        if dist2 <= r2 * (1.0 + 1e-4) {
            return None;
        }
        let sin2_max = r2 / dist2;
        let cos_max = (1.0 - sin2_max).max(0.0).sqrt();
        let one_minus_cos_max = if sin2_max < SMALL_SIN2 {
            0.5 * sin2_max
        } else {
            1.0 - cos_max
        };
        Some(Self {
            sin2_max,
            cos_max,
            one_minus_cos_max,
        })
    }

    /// Density of the directions in solid angle (uniform over the cone).
    #[inline]
    pub(crate) fn pdf(&self) -> f32 {
        1.0 / (TAU * self.one_minus_cos_max)
    }

    /// Samples a direction in the cone and returns the point where it meets
    /// the sphere first, and the sphere's normal there.
    #[inline]
    pub(crate) fn sample(&self, centre: Vec3, radius: f32, origin: Vec3, u: Vec2) -> (Vec3, Vec3) {
        let (sin2_theta, cos_theta) = if self.sin2_max < SMALL_SIN2 {
            let s2 = self.sin2_max * u.x;
            (s2, (1.0 - s2).sqrt())
        } else {
            let c = (self.cos_max - 1.0) * u.x + 1.0;
            (1.0 - c * c, c)
        };
        // The angle α at the centre between the axis and the hit point.
        let cos_alpha = sin2_theta / self.sin2_max.sqrt()
            + cos_theta * (1.0 - sin2_theta / self.sin2_max).max(0.0).sqrt();
        let sin_alpha = (1.0 - cos_alpha * cos_alpha).max(0.0).sqrt();
        let (sin_phi, cos_phi) = (TAU * u.y).sin_cos();
        let frame = Frame::from_normal((centre - origin).normalize());
        let w = Vec3::new(sin_alpha * cos_phi, sin_alpha * sin_phi, cos_alpha);
        let n = frame.to_world(-w);
        (centre + n * radius, n)
    }
}

/// Four reference points' cone samples of one sphere: [`Cone::new`],
/// [`Cone::sample`] and [`Cone::pdf`] one SSE lane per point, so that the
/// square roots and divisions of four samples share instructions.
/// Lane k holds the sample where `outside` has it; elsewhere the point is
/// not outside the sphere and the lane is meaningless.
pub(crate) struct ConeSamples {
    /// Whether each reference point is outside the sphere ([`Cone::new`]'s
    /// test, bit for bit).
    pub outside: BVec4A,
    /// The sampled points, as lanes of x, y and z.
    pub p: [Vec4; 3],
    /// The sphere's outward normals there.
    pub n: [Vec4; 3],
    /// The cones' solid-angle densities.
    pub pdf: Vec4,
}

impl ConeSamples {
    /// Samples the sphere (`centre`, `radius`) from the four `origins` (x,
    /// y, z; w unused) with the four `u`, each uniformly in the cone it
    /// subtends: the operations
    /// of [`Cone::new`] and [`Cone::sample`] lane by lane, except that the
    /// turn's sine and cosine come from [`sin_cos_turn`].
    #[inline]
    pub(crate) fn new(centre: Vec3, radius: f32, origins: [Vec4; 4], u: [Vec2; 4]) -> Self {
        // Lanes by transposing whole vectors (shuffles), not by writing
        // scalars to memory that a vector load then waits for.
        let o = Mat4::from_cols(origins[0], origins[1], origins[2], origins[3]).transpose();
        let (dx, dy, dz) = (
            Vec4::splat(centre.x) - o.x_axis,
            Vec4::splat(centre.y) - o.y_axis,
            Vec4::splat(centre.z) - o.z_axis,
        );
        let [u0, u1, u2, u3] = u;
        let (ux, uy) = (
            Vec4::new(u0.x, u1.x, u2.x, u3.x),
            Vec4::new(u0.y, u1.y, u2.y, u3.y),
        );
        let one = Vec4::ONE;
        let zero = Vec4::ZERO;
        // The cone (`Cone::new`).
        let dist2 = dx * dx + dy * dy + dz * dz;
        let r2 = radius * radius;
        let outside = dist2.cmpgt(Vec4::splat(r2 * (1.0 + 1e-4)));
        let sin2_max = Vec4::splat(r2) / dist2;
        let cos_max = (one - sin2_max).max(zero).sqrt();
        let small = sin2_max.cmplt(Vec4::splat(SMALL_SIN2));
        let one_minus_cos_max = Vec4::select(small, 0.5 * sin2_max, one - cos_max);
        // A direction in it (`Cone::sample`).
        let s2 = sin2_max * ux;
        let c = (cos_max - one) * ux + one;
        let sin2_theta = Vec4::select(small, s2, one - c * c);
        let cos_theta = Vec4::select(small, (one - s2).sqrt(), c);
        let cos_alpha = sin2_theta / sin2_max.sqrt()
            + cos_theta * (one - sin2_theta / sin2_max).max(zero).sqrt();
        let sin_alpha = (one - cos_alpha * cos_alpha).max(zero).sqrt();
        let (sin_phi, cos_phi) = sin_cos_turn(uy);
        // The frame around the axis (`Frame::from_normal` of the
        // normalised centre − origin).
        let inv_length = one / dist2.sqrt();
        let (ax, ay, az) = (dx * inv_length, dy * inv_length, dz * inv_length);
        let sign = one.copysign(az);
        let a = -one / (sign + az);
        let b = ax * ay * a;
        let (sx, sy, sz) = (one + sign * ax * ax * a, sign * b, -sign * ax);
        let (tx, ty, tz) = (b, sign + ay * ay * a, -ay);
        // n = to_world(−w), w = (sin α cos φ, sin α sin φ, cos α).
        let (wx, wy, wz) = (-(sin_alpha * cos_phi), -(sin_alpha * sin_phi), -cos_alpha);
        let n = [
            sx * wx + tx * wy + ax * wz,
            sy * wx + ty * wy + ay * wz,
            sz * wx + tz * wy + az * wz,
        ];
        let p = [
            Vec4::splat(centre.x) + n[0] * radius,
            Vec4::splat(centre.y) + n[1] * radius,
            Vec4::splat(centre.z) + n[2] * radius,
        ];
        Self {
            outside,
            p,
            n,
            pdf: one / (TAU * one_minus_cos_max),
        }
    }
}

/// sin 2πt and cos 2πt for t in [0, 1], four at a time: the quarter turn
/// by selects, the angle within it (below π/2) by its Taylor polynomials
/// to the 11th and 12th power (truncation error below 6e-8).
#[inline]
pub(crate) fn sin_cos_turn(t: Vec4) -> (Vec4, Vec4) {
    let quarters = t * 4.0;
    let q = quarters.floor();
    let x = (quarters - q) * FRAC_PI_2;
    let x2 = x * x;
    let sin = x
        * (1.0
            + x2 * (-1.0 / 6.0
                + x2 * (1.0 / 120.0
                    + x2 * (-1.0 / 5040.0 + x2 * (1.0 / 362_880.0 + x2 * (-1.0 / 39_916_800.0))))));
    let cos = 1.0
        + x2 * (-0.5
            + x2 * (1.0 / 24.0
                + x2 * (-1.0 / 720.0
                    + x2 * (1.0 / 40_320.0
                        + x2 * (-1.0 / 3_628_800.0 + x2 * (1.0 / 479_001_600.0))))));
    // Quarter q turns (sin, cos) into (cos, −sin), (−sin, −cos), (−cos, sin).
    let (one, two, three) = (Vec4::splat(1.0), Vec4::splat(2.0), Vec4::splat(3.0));
    let odd = q.cmpeq(one) | q.cmpeq(three);
    let (s, c) = (Vec4::select(odd, cos, sin), Vec4::select(odd, sin, cos));
    let negative_sin = q.cmpeq(two) | q.cmpeq(three);
    let negative_cos = q.cmpeq(one) | q.cmpeq(two);
    (
        Vec4::select(negative_sin, -s, s),
        Vec4::select(negative_cos, -c, c),
    )
}

#[cfg(test)]
mod tests {
    // `unwrap` in this test code is the assertion: the inputs are the test's
    // own, so a failure is a bug, and the panic reports it with the error.
    use super::*;

    #[test]
    fn sampled_points_lie_on_the_visible_cap_within_the_cone() {
        let (c, r) = (Vec3::new(0.3, -0.2, 5.0), 1.5);
        for origin in [
            Vec3::ZERO,
            Vec3::new(0.3, -0.2, 3.4),
            Vec3::new(1e3, 0.0, 0.0),
        ] {
            let cone = Cone::new(c, r, origin).unwrap();
            let axis = (c - origin).normalize();
            for i in 0..64 {
                let u = Vec2::new((i % 8) as f32 / 8.0 + 0.06, (i / 8) as f32 / 8.0 + 0.01);
                let (p, n) = cone.sample(c, r, origin, u);
                assert!(
                    ((p - c).length() - r).abs() < 1e-3 * r.max((p - c).length()),
                    "{p}"
                );
                let d = (p - origin).normalize();
                assert!(n.dot(-d) > -1e-3, "back side: {}", n.dot(-d));
                assert!(d.dot(axis) >= cone.cos_max - 1e-4);
            }
        }
        assert!(Cone::new(c, r, c + Vec3::X * 0.5).is_none());
    }

    #[test]
    fn the_turn_sine_and_cosine_are_accurate() {
        let mut worst = 0.0f64;
        for i in 0..=40_000u32 {
            let t = i as f32 / 40_000.0;
            let (s, c) = sin_cos_turn(Vec4::splat(t));
            let angle = std::f64::consts::TAU * f64::from(t);
            worst = worst
                .max((f64::from(s.x) - angle.sin()).abs())
                .max((f64::from(c.x) - angle.cos()).abs());
        }
        assert!(worst < 3e-7, "worst error {worst:e}");
    }

    /// The four-lane samples are the single ones: the same outside test,
    /// and points, normals and densities to rounding (the turn's sine and
    /// cosine differ from libm's in the last bits).
    #[test]
    fn four_lanes_sample_as_one_cone_each() {
        let (c, r) = (Vec3::new(0.3, -0.2, 5.0), 1.5);
        let origins = [
            Vec3::ZERO,
            Vec3::new(0.3, -0.2, 3.4),
            Vec3::new(1e3, 0.0, 0.0),
            Vec3::new(0.3, 0.4, 5.0),
        ];
        for i in 0..64 {
            let u: [Vec2; 4] = std::array::from_fn(|k| {
                Vec2::new(
                    ((i * 7 + k * 3) % 64) as f32 / 64.0 + 0.003,
                    ((i * 13 + k * 5) % 64) as f32 / 64.0 + 0.001,
                )
            });
            let lanes = ConeSamples::new(c, r, origins.map(|o| o.extend(0.0)), u);
            for k in 0..4 {
                let cone = Cone::new(c, r, origins[k]);
                assert_eq!(lanes.outside.test(k), cone.is_some(), "lane {k}");
                let Some(cone) = cone else { continue };
                let (p, n) = cone.sample(c, r, origins[k], u[k]);
                let lane = |v: &[Vec4; 3]| Vec3::new(v[0][k], v[1][k], v[2][k]);
                assert!(
                    (lane(&lanes.p) - p).length() < 1e-4 * r,
                    "{p} {}",
                    lane(&lanes.p)
                );
                assert!(
                    (lane(&lanes.n) - n).length() < 1e-4,
                    "{n} {}",
                    lane(&lanes.n)
                );
                assert_eq!(lanes.pdf[k], cone.pdf());
            }
        }
    }
}
