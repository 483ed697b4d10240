//! Orthonormal shading frames: world ↔ local (z = normal) conversion.

use glam::Vec3;

/// An orthonormal basis whose `n` axis is the local +z direction.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Frame {
    /// Local +x.
    pub s: Vec3,
    /// Local +y.
    pub t: Vec3,
    /// Local +z, the normal.
    pub n: Vec3,
}

impl Default for Frame {
    /// The local frame itself: x, y, z.
    fn default() -> Self {
        Self {
            s: Vec3::X,
            t: Vec3::Y,
            n: Vec3::Z,
        }
    }
}

impl Frame {
    /// Builds a frame around the unit vector `n` (Duff et al. 2017, branchless).
    #[inline]
    pub fn from_normal(n: Vec3) -> Self {
        let sign = 1.0f32.copysign(n.z);
        let a = -1.0 / (sign + n.z);
        let b = n.x * n.y * a;
        let s = Vec3::new(1.0 + sign * n.x * n.x * a, sign * b, -sign * n.x);
        let t = Vec3::new(b, sign + n.y * n.y * a, -n.y);
        Self { s, t, n }
    }

    /// The frame around the unit vector `n` whose first tangent is `s` made
    /// orthogonal to `n` (Gram–Schmidt); `None` where `s` is zero, not
    /// finite, or (nearly) parallel to `n`.
    #[inline]
    pub fn with_tangent(n: Vec3, s: Vec3) -> Option<Self> {
        let perp = s - n * n.dot(s);
        let l2 = perp.length_squared();
        let usable = l2 > 1e-10 * s.length_squared() && l2.is_finite();
        if !usable {
            return None;
        }
        let s = perp / l2.sqrt();
        Some(Self {
            s,
            t: n.cross(s),
            n,
        })
    }

    /// The frame around the unit vector `n` for a surface without a usable
    /// parametrization: its tangent runs around the z axis (along ẑ × n,
    /// as a sphere's ∂p/∂u does), which turns continuously with `n`
    /// everywhere but near ±z, where it is the x axis made orthogonal to
    /// `n`.
    #[inline]
    pub fn around_z(n: Vec3) -> Self {
        Self::with_tangent(n, Vec3::new(-n.y, n.x, 0.0))
            .filter(|_| n.x * n.x + n.y * n.y > 1e-6)
            .or_else(|| Self::with_tangent(n, Vec3::X))
            .unwrap_or_else(|| Self::from_normal(n))
    }

    /// Expresses the world-space vector `v` in this frame.
    #[inline]
    pub fn to_local(&self, v: Vec3) -> Vec3 {
        Vec3::new(v.dot(self.s), v.dot(self.t), v.dot(self.n))
    }

    /// Expresses the local vector `v` in world space.
    #[inline]
    pub fn to_world(&self, v: Vec3) -> Vec3 {
        self.s * v.x + self.t * v.y + self.n * v.z
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn frames_are_orthonormal_and_invertible() {
        let normals = [
            Vec3::Z,
            -Vec3::Z,
            Vec3::X,
            Vec3::new(0.3, -0.4, 0.866).normalize(),
            Vec3::new(1e-7, 0.0, -1.0).normalize(),
        ];
        for n in normals {
            let f = Frame::from_normal(n);
            assert!((f.s.length() - 1.0).abs() < 1e-5);
            assert!((f.t.length() - 1.0).abs() < 1e-5);
            assert!(f.s.dot(f.t).abs() < 1e-5 && f.s.dot(n).abs() < 1e-5);
            assert!((f.s.cross(f.t) - n).length() < 1e-5, "right-handed");
            let v = Vec3::new(0.2, 0.5, -0.7);
            assert!((f.to_world(f.to_local(v)) - v).length() < 1e-5);
        }
    }

    #[test]
    fn frames_along_a_tangent_keep_its_direction_and_fall_back_without_one() {
        let n = Vec3::new(0.3, -0.4, 0.866).normalize();
        let along = Vec3::new(2.0, 1.0, 0.5);
        let f = Frame::with_tangent(n, along).expect("a usable tangent");
        assert!((f.s.length() - 1.0).abs() < 1e-5 && f.s.dot(n).abs() < 1e-5);
        assert!((f.s.cross(f.t) - n).length() < 1e-5, "right-handed");
        // s is the part of the tangent in the plane, so it points its way.
        let perp = along - n * n.dot(along);
        assert!(f.s.dot(perp.normalize()) > 0.99999);
        for bad in [Vec3::ZERO, n * 3.0, Vec3::NAN, Vec3::INFINITY] {
            assert!(Frame::with_tangent(n, bad).is_none(), "{bad}");
        }
        // Around z: continuous over the sphere away from the poles, and a
        // frame at the poles too.
        let a = Frame::around_z(Vec3::new(1.0, 0.0, 0.0));
        let b = Frame::around_z(Vec3::new(1.0, 0.0, 1e-3).normalize());
        let c = Frame::around_z(Vec3::new(1.0, 0.0, -1e-3).normalize());
        assert!((a.s - b.s).length() < 1e-2 && (a.s - c.s).length() < 1e-2);
        assert!((a.s - Vec3::Y).length() < 1e-6, "{:?}", a.s);
        for pole in [Vec3::Z, -Vec3::Z] {
            let f = Frame::around_z(pole);
            assert!((f.s.cross(f.t) - pole).length() < 1e-5);
        }
    }
}
