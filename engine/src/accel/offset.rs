//! Where spawned rays start: the hit point pushed off the surface by a
//! conservative bound on its floating-point error (pbrt-v4's
//! `OffsetRayOrigin`), then rounded away from the surface.
//!
//! The bound scales with the coordinates' magnitude, so the same code is
//! right for scenes of size 1e-4 and 1e5.

use glam::{Vec3, Vec3A};

#[inline]
fn gamma(n: i32) -> f32 {
    let e = f32::EPSILON * 0.5;
    (n as f32 * e) / (1.0 - n as f32 * e)
}

/// The point of triangle `v` with barycentrics (b0, b1, b2) and the bound
/// on its floating-point error, which shares the products of the point.
#[inline]
pub fn triangle_point(v: &[Vec3; 3], b0: f32, b1: f32, b2: f32) -> (Vec3, Vec3) {
    let [w0, w1, w2] = [
        Vec3A::from(v[0]) * b0,
        Vec3A::from(v[1]) * b1,
        Vec3A::from(v[2]) * b2,
    ];
    let err = (w0.abs() + w1.abs() + w2.abs()) * gamma(7);
    (Vec3::from(w0 + w1 + w2), Vec3::from(err))
}

/// Error bound of a point re-projected onto a sphere.
#[inline]
pub fn sphere_error(p: Vec3) -> Vec3 {
    p.abs() * gamma(5)
}

/// Error bound of a point computed by a light's sampling routine (at most
/// a few operations on coordinates of this magnitude).
#[inline]
pub fn sampled_point_error(p: Vec3) -> Vec3 {
    p.abs() * gamma(7)
}

/// The origin of a ray leaving `p` (error bound `err`, geometric normal
/// `n`) in direction `w`: on the side of the surface that `w` points to.
///
/// After adding the offset, each moved coordinate is pushed further by
/// `max(|x|·ε, MIN_POSITIVE)` in the offset's direction: at least one ulp
/// (so rounding of the sum cannot land back on the surface, as pbrt's
/// `NextFloatUp`/`NextFloatDown` ensure) and at most three, without
/// branches.
#[inline]
pub fn offset_origin(p: Vec3, err: Vec3, n: Vec3, w: Vec3) -> Vec3 {
    let (p, err, n) = (Vec3A::from(p), Vec3A::from(err), Vec3A::from(n));
    let d = n.abs().dot(err);
    let side = if Vec3A::from(w).dot(n) < 0.0 { -d } else { d };
    let offset = n * side;
    let po = p + offset;
    let step = (po.abs() * f32::EPSILON).max(Vec3A::splat(f32::MIN_POSITIVE));
    let up = offset.cmpgt(Vec3A::ZERO);
    let down = offset.cmplt(Vec3A::ZERO);
    let po = Vec3A::select(up, po + step, po);
    Vec3::from(Vec3A::select(down, po - step, po))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn offset_moves_to_the_requested_side_at_every_scale() {
        for scale in [1e-4f32, 1.0, 1e5] {
            let v = [
                Vec3::new(0.1, 0.2, 0.3) * scale,
                Vec3::new(1.3, 0.2, 0.3) * scale,
                Vec3::new(0.1, 1.7, 0.3) * scale,
            ];
            let n = Vec3::Z;
            let (b0, b1, b2) = (0.2, 0.3, 0.5);
            let (p, err) = triangle_point(&v, b0, b1, b2);
            let up = offset_origin(p, err, n, Vec3::new(0.0, 0.3, 1.0));
            let down = offset_origin(p, err, n, Vec3::new(0.0, 0.3, -1.0));
            assert!(up.z > v[0].z && down.z < v[0].z, "scale {scale}");
            // The offset is tiny relative to the scene's size.
            assert!(
                (up.z - v[0].z) < 1e-5 * scale,
                "scale {scale}: {}",
                up.z - v[0].z
            );
        }
    }

    #[test]
    fn offsets_below_one_ulp_still_leave_the_surface() {
        for z in [0.0f32, 1.0, -3.0, 1e5, -1e-30] {
            let p = Vec3::new(0.5, -2.0, z);
            let err = Vec3::splat(1e-38);
            let up = offset_origin(p, err, Vec3::Z, Vec3::Z);
            let down = offset_origin(p, err, Vec3::Z, -Vec3::Z);
            assert!(up.z > z && down.z < z, "z {z}: {} {}", up.z, down.z);
            // At most a few ulps, and x, y untouched.
            assert!(up.z - z <= 4.0 * (z.abs() * f32::EPSILON).max(f32::MIN_POSITIVE));
            assert_eq!((up.x, up.y), (p.x, p.y));
        }
    }
}
