//! Rectangles for area lights: recognising a rectangle in a pair of
//! triangles, and sampling it uniformly in the solid angle it subtends
//! (Ureña, Fajardo and King 2013, "An area-preserving parametrization for
//! spherical rectangles", in the form of pbrt-v4's
//! `SampleSphericalRectangle`).
//!
//! Area sampling of a rectangle light wastes samples on the parts seen at
//! grazing angles and gives near points a density that varies with
//! distance squared; solid-angle sampling makes the estimator's density
//! constant over the rectangle's image, which removes most of the variance
//! of direct light from large or nearby rectangles. It is used only near
//! the rectangle (within about two diagonals), where the solid angle is
//! large enough for single precision; elsewhere, and where the solid angle
//! is tiny (grazing) or nearly a hemisphere, the light falls back to area
//! sampling, and its density follows the same rule.

use radiant_core::glam::{Vec2, Vec3};

/// Solid angles (sr) between which a rectangle is sampled by solid angle;
/// outside, by area (pbrt-v4's bounds).
const MIN_SOLID_ANGLE: f32 = 3e-4;
const MAX_SOLID_ANGLE: f32 = 6.22;
/// Points farther from the rectangle's centre than √(NEAR · area) sample
/// it by area: there its image is small and nearly undistorted, area
/// sampling is almost uniform in solid angle already, and the spherical
/// construction (a few hundred cycles) would cost more than it saves.
const NEAR: f32 = 4.0;

/// A rectangle `corner + s·ex + t·ey`, s, t ∈ [0, 1], that emits from the
/// side its unit normal `n` points to.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct Rectangle {
    pub corner: Vec3,
    pub ex: Vec3,
    pub ey: Vec3,
    pub n: Vec3,
    centre: Vec3,
    area: f32,
}

impl Rectangle {
    /// The rectangle formed by triangles `t0` and `t1` as the scene's
    /// shapes tessellate quads (a, b, c) + (a, c, d), in either winding, if
    /// they form one (to a relative tolerance of 1e-5).
    pub fn from_triangles(t0: [Vec3; 3], t1: [Vec3; 3]) -> Option<Self> {
        let (a, b, c, d) = if t0[0] == t1[0] && t0[2] == t1[1] {
            (t0[0], t0[1], t0[2], t1[2])
        } else if t0[0] == t1[0] && t0[1] == t1[2] {
            (t0[0], t0[2], t0[1], t1[1])
        } else {
            return None;
        };
        let (ex, ey) = (b - a, d - a);
        let scale = ex.length().max(ey.length());
        let n = (t0[1] - t0[0]).cross(t0[2] - t0[0]).try_normalize()?;
        let closes = (a + ex + ey - c).length() <= 1e-5 * scale;
        let square = ex.dot(ey).abs() <= 1e-5 * ex.length() * ey.length();
        (closes && square).then(|| Self::new(a, ex, ey, n))
    }

    /// The rectangle `corner + s·ex + t·ey` emitting towards `n`.
    pub fn new(corner: Vec3, ex: Vec3, ey: Vec3, n: Vec3) -> Self {
        Self {
            corner,
            ex,
            ey,
            n,
            centre: corner + 0.5 * (ex + ey),
            area: ex.cross(ey).length(),
        }
    }

    /// Area.
    pub fn area(&self) -> f32 {
        self.area
    }

    /// The point at (s, t) ∈ [0, 1]².
    #[inline(always)]
    pub fn point(&self, u: Vec2) -> Vec3 {
        self.corner + self.ex * u.x + self.ey * u.y
    }

    /// Whether `origin` is on the emitting side and near enough for
    /// solid-angle sampling (the cheap first test of [`Self::spherical`]).
    #[inline(always)]
    fn is_near(&self, origin: Vec3) -> bool {
        self.n.dot(origin - self.corner) > 0.0
            && (self.centre - origin).length_squared() <= NEAR * self.area
    }

    /// The rectangle as seen from `origin` for solid-angle sampling, if
    /// `origin` is near it on its emitting side and the solid angle is
    /// within the reliable range.
    #[inline(always)]
    pub fn spherical(&self, origin: Vec3) -> Option<SphericalRectangle> {
        if !self.is_near(origin) {
            return None;
        }
        self.spherical_near(origin)
    }

    /// [`Self::spherical`] past its first test: the construction, out of
    /// line, so that the far points' cheap test stays in its caller's loop.
    fn spherical_near(&self, origin: Vec3) -> Option<SphericalRectangle> {
        SphericalRectangle::new(origin, self.corner, self.ex, self.ey)
            .filter(|s| (MIN_SOLID_ANGLE..MAX_SOLID_ANGLE).contains(&s.solid_angle))
    }
}

/// A rectangle projected onto the unit sphere around a point, prepared for
/// uniform sampling.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct SphericalRectangle {
    origin: Vec3,
    /// Local frame: x along `ex`, y along `ey`, z away from the rectangle.
    x: Vec3,
    y: Vec3,
    z: Vec3,
    x0: f32,
    x1: f32,
    y0: f32,
    y1: f32,
    z0: f32,
    b0: f32,
    b1: f32,
    /// Internal angles g0 + g1 − 2π and g2 + g3.
    k0: f32,
    k1: f32,
    /// Solid angle, steradians.
    pub solid_angle: f32,
}

/// The angle between unit vectors, precise near 0 and π.
fn angle_between(a: Vec3, b: Vec3) -> f32 {
    if a.dot(b) < 0.0 {
        std::f32::consts::PI - 2.0 * ((a + b).length() * 0.5).min(1.0).asin()
    } else {
        2.0 * ((b - a).length() * 0.5).min(1.0).asin()
    }
}

impl SphericalRectangle {
    fn new(origin: Vec3, corner: Vec3, ex: Vec3, ey: Vec3) -> Option<Self> {
        let (exl, eyl) = (ex.length(), ey.length());
        let x = ex / exl;
        let y = ey / eyl;
        let mut z = x.cross(y);
        let d = corner - origin;
        let mut z0 = d.dot(z);
        if z0 > 0.0 {
            z = -z;
            z0 = -z0;
        }
        let (x0, y0) = (d.dot(x), d.dot(y));
        let (x1, y1) = (x0 + exl, y0 + eyl);
        let v00 = Vec3::new(x0, y0, z0);
        let v01 = Vec3::new(x0, y1, z0);
        let v10 = Vec3::new(x1, y0, z0);
        let v11 = Vec3::new(x1, y1, z0);
        let n0 = v00.cross(v10).try_normalize()?;
        let n1 = v10.cross(v11).try_normalize()?;
        let n2 = v11.cross(v01).try_normalize()?;
        let n3 = v01.cross(v00).try_normalize()?;
        let g0 = angle_between(-n0, n1);
        let g1 = angle_between(-n1, n2);
        let g2 = angle_between(-n2, n3);
        let g3 = angle_between(-n3, n0);
        let two_pi = 2.0 * std::f32::consts::PI;
        let solid_angle = g0 + g1 + g2 + g3 - two_pi;
        (solid_angle > 0.0 && solid_angle.is_finite()).then_some(Self {
            origin,
            x,
            y,
            z,
            x0,
            x1,
            y0,
            y1,
            z0,
            b0: n0.z,
            b1: n2.z,
            k0: g0 + g1 - two_pi,
            k1: g2 + g3,
            solid_angle,
        })
    }

    /// The point of the rectangle in the direction drawn uniformly in solid
    /// angle from `u`.
    pub fn sample(&self, u: Vec2) -> Vec3 {
        let (u0, u1) = (u.x, u.y);
        // The x coordinate: invert the solid angle swept as x grows.
        let au = u0 * self.k0 + (u0 - 1.0) * self.k1;
        let fu = (au.cos() * self.b0 - self.b1) / au.sin();
        let cu = (1.0 / (fu * fu + self.b0 * self.b0).sqrt())
            .copysign(fu)
            .clamp(-1.0 + 1e-7, 1.0 - 1e-7);
        let xu = (-(cu * self.z0) / (1.0 - cu * cu).max(0.0).sqrt()).clamp(self.x0, self.x1);
        // The y coordinate: uniform in the sine of the elevation.
        let dd = (xu * xu + self.z0 * self.z0).sqrt();
        let h0 = self.y0 / (dd * dd + self.y0 * self.y0).sqrt();
        let h1 = self.y1 / (dd * dd + self.y1 * self.y1).sqrt();
        let hv = h0 + u1 * (h1 - h0);
        let hv2 = hv * hv;
        let yv = if hv2 < 1.0 - 1e-6 {
            (hv * dd / (1.0 - hv2).sqrt()).clamp(self.y0, self.y1)
        } else {
            self.y1
        };
        self.origin + self.x * xu + self.y * yv + self.z * self.z0
    }
}

#[cfg(test)]
mod tests {
    // `unwrap` in this test code is the assertion: the inputs are the test's
    // own, so a failure is a bug, and the panic reports it with the error.
    use super::*;

    fn square() -> Rectangle {
        Rectangle::new(
            Vec3::new(-1.0, -1.0, 0.0),
            Vec3::new(2.0, 0.0, 0.0),
            Vec3::new(0.0, 2.0, 0.0),
            Vec3::Z,
        )
    }

    #[test]
    fn rectangles_are_recognised_in_both_windings() {
        let (a, b, c, d) = (
            Vec3::new(0.0, 0.0, 1.0),
            Vec3::new(2.0, 0.0, 1.0),
            Vec3::new(2.0, 3.0, 1.0),
            Vec3::new(0.0, 3.0, 1.0),
        );
        let r = Rectangle::from_triangles([a, b, c], [a, c, d]).unwrap();
        assert_eq!((r.corner, r.ex, r.ey, r.n), (a, b - a, d - a, Vec3::Z));
        let r = Rectangle::from_triangles([a, c, b], [a, d, c]).unwrap();
        assert_eq!(r.n, -Vec3::Z);
        assert!((r.area() - 6.0).abs() < 1e-6);
        // A parallelogram and two unrelated triangles are not rectangles.
        let e = Vec3::new(1.0, 3.0, 1.0);
        assert!(Rectangle::from_triangles([a, b, e + b - a], [a, e + b - a, e]).is_none());
        assert!(Rectangle::from_triangles([a, b, c], [b, c, d]).is_none());
    }

    #[test]
    fn solid_angle_matches_the_closed_form() {
        // A square of side 2 seen from height h above its centre subtends
        // 4·asin(1/(1 + h²)) sr.
        for h in [0.1f32, 1.0, 3.9] {
            let s = square().spherical(Vec3::new(0.0, 0.0, h));
            let exact = 4.0 * (1.0 / (1.0 + h * h)).asin();
            match s {
                Some(s) => assert!(
                    (s.solid_angle / exact - 1.0).abs() < 1e-5,
                    "h = {h}: {} against {exact}",
                    s.solid_angle
                ),
                None => assert!(exact >= MAX_SOLID_ANGLE, "h = {h}"),
            }
        }
        // From behind, or far away: area sampling.
        assert!(square().spherical(Vec3::new(0.0, 0.0, -1.0)).is_none());
        assert!(square().spherical(Vec3::new(0.0, 0.0, 4.1)).is_none());
    }

    #[test]
    fn samples_lie_on_the_rectangle() {
        let origin = Vec3::new(0.3, -2.0, 0.7);
        let s = square().spherical(origin).unwrap();
        for i in 0..64 {
            let u = Vec2::new((i % 8) as f32 / 7.0, (i / 8) as f32 / 7.0);
            let p = s.sample(u);
            assert!(
                p.z.abs() < 1e-5 && p.x.abs() <= 1.0 + 1e-5 && p.y.abs() <= 1.0 + 1e-5,
                "{p}"
            );
        }
    }
}
