//! Where spawned rays start: the hit point pushed off the surface by a
//! conservative bound on its floating-point error (pbrt-v4's
//! `OffsetRayOrigin`), then rounded away from the surface.
//!
//! The bound scales with the coordinates' magnitude, so the same code is
//! right for scenes of size 1e-4 and 1e5.

use glam::Vec3;

#[inline]
fn gamma(n: i32) -> f32 {
    let e = f32::EPSILON * 0.5;
    (n as f32 * e) / (1.0 - n as f32 * e)
}

/// Error bound of a point interpolated from triangle vertices `v` with
/// barycentrics (b0, b1, b2).
#[inline]
pub fn triangle_error(v: &[Vec3; 3], b0: f32, b1: f32, b2: f32) -> Vec3 {
    ((v[0] * b0).abs() + (v[1] * b1).abs() + (v[2] * b2).abs()) * gamma(7)
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

#[inline]
fn next_up(x: f32) -> f32 {
    if x.is_infinite() && x > 0.0 {
        return x;
    }
    let x = if x == -0.0 { 0.0 } else { x };
    let bits = x.to_bits();
    f32::from_bits(if x >= 0.0 { bits + 1 } else { bits - 1 })
}

#[inline]
fn next_down(x: f32) -> f32 {
    if x.is_infinite() && x < 0.0 {
        return x;
    }
    let x = if x == 0.0 { -0.0 } else { x };
    let bits = x.to_bits();
    f32::from_bits(if x > 0.0 { bits - 1 } else { bits + 1 })
}

/// The origin of a ray leaving `p` (error bound `err`, geometric normal
/// `n`) in direction `w`: on the side of the surface that `w` points to.
#[inline]
pub fn offset_origin(p: Vec3, err: Vec3, n: Vec3, w: Vec3) -> Vec3 {
    let d = n.abs().dot(err);
    let mut offset = n * d;
    if w.dot(n) < 0.0 {
        offset = -offset;
    }
    let mut po = p + offset;
    for i in 0..3 {
        if offset[i] > 0.0 {
            po[i] = next_up(po[i]);
        } else if offset[i] < 0.0 {
            po[i] = next_down(po[i]);
        }
    }
    po
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
            let p = v[0] * b0 + v[1] * b1 + v[2] * b2;
            let err = triangle_error(&v, b0, b1, b2);
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
    fn next_float_steps() {
        assert!(next_up(1.0) > 1.0 && next_down(1.0) < 1.0);
        assert!(next_up(0.0) > 0.0 && next_down(0.0) < 0.0);
        assert!(next_up(-1.0) > -1.0);
    }
}
