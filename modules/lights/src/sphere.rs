//! Solid-angle sampling of a sphere seen from outside: directions uniform
//! in the cone the sphere subtends (pbrt-v4's `Sphere::Sample`, with its
//! Taylor expansion for spheres smaller than 1.5° so that distant spheres
//! keep their precision). From inside, callers fall back to area sampling.

use radiant_core::Frame;
use radiant_core::glam::{Vec2, Vec3};
use std::f32::consts::TAU;

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
}
