//! Ray–sphere intersection with the precision fix of Haines et al. (Ray
//! Tracing Gems, ch. 7): the discriminant is computed from the distance of
//! the centre to the ray, not from a difference of large squares.

use glam::Vec3;

/// Smallest t in (0, `tmax`) where `origin + t·dir` meets the sphere.
#[inline]
pub fn intersect(origin: Vec3, dir: Vec3, centre: Vec3, radius: f32, tmax: f32) -> Option<f32> {
    let f = origin - centre;
    let a = dir.length_squared();
    let b = -f.dot(dir);
    // |f + (b/a)·dir|² is the squared distance from the centre to the line.
    let l = f + dir * (b / a);
    let disc = radius * radius - l.length_squared();
    if disc < 0.0 {
        return None;
    }
    let c = f.length_squared() - radius * radius;
    let q = b + b.signum() * (a * disc).sqrt();
    if q == 0.0 {
        return None;
    }
    let (t0, t1) = (c / q, q / a);
    let (near, far) = if t0 < t1 { (t0, t1) } else { (t1, t0) };
    if near > 0.0 && near < tmax {
        Some(near)
    } else if far > 0.0 && far < tmax {
        Some(far)
    } else {
        None
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn near_and_far_roots() {
        let t = intersect(
            Vec3::new(0.0, 0.0, -5.0),
            Vec3::Z,
            Vec3::ZERO,
            1.0,
            f32::INFINITY,
        );
        assert!((t.unwrap() - 4.0).abs() < 1e-6);
        let inside = intersect(Vec3::ZERO, Vec3::Z, Vec3::ZERO, 1.0, f32::INFINITY);
        assert!((inside.unwrap() - 1.0).abs() < 1e-6);
        assert!(
            intersect(
                Vec3::new(0.0, 2.0, -5.0),
                Vec3::Z,
                Vec3::ZERO,
                1.0,
                f32::INFINITY
            )
            .is_none()
        );
    }

    #[test]
    fn small_sphere_far_away_is_precise() {
        let centre = Vec3::new(0.0, 0.0, 1.0e4);
        let t = intersect(Vec3::ZERO, Vec3::Z, centre, 1e-2, f32::INFINITY).unwrap();
        assert!((t - (1.0e4 - 1e-2)).abs() < 2e-3, "{t}");
    }
}
