//! Watertight ray–triangle intersection (Woop, Benthin and Wald 2013, as in
//! pbrt-v4): rays through shared edges and vertices hit exactly one of the
//! triangles that meet there, and hits closer than the computation's
//! rounding error are rejected.

use glam::{DVec3, Vec3};

/// Per-ray constants of the watertight test.
#[derive(Debug, Clone, Copy)]
pub struct RayPrep {
    origin: Vec3,
    kx: usize,
    ky: usize,
    kz: usize,
    shear: Vec3,
}

impl RayPrep {
    /// Prepares the ray `origin + t·dir`.
    #[inline]
    pub fn new(origin: Vec3, dir: Vec3) -> Self {
        let a = dir.abs();
        let kz = if a.x > a.y {
            if a.x > a.z { 0 } else { 2 }
        } else if a.y > a.z {
            1
        } else {
            2
        };
        let kx = if kz == 2 { 0 } else { kz + 1 };
        let ky = if kx == 2 { 0 } else { kx + 1 };
        let dz = dir[kz];
        Self {
            origin,
            kx,
            ky,
            kz,
            shear: Vec3::new(-dir[kx] / dz, -dir[ky] / dz, 1.0 / dz),
        }
    }
}

#[inline]
fn gamma(n: i32) -> f32 {
    let e = f32::EPSILON * 0.5;
    (n as f32 * e) / (1.0 - n as f32 * e)
}

/// Intersects a prepared ray with triangle `v`; returns (t, b1, b2) for a
/// hit with 0 < t < `tmax`.
#[inline]
pub fn intersect(ray: &RayPrep, v: &[Vec3; 3], tmax: f32) -> Option<(f32, f32, f32)> {
    let (kx, ky, kz) = (ray.kx, ray.ky, ray.kz);
    let p0 = v[0] - ray.origin;
    let p1 = v[1] - ray.origin;
    let p2 = v[2] - ray.origin;
    let mut p0t = Vec3::new(p0[kx], p0[ky], p0[kz]);
    let mut p1t = Vec3::new(p1[kx], p1[ky], p1[kz]);
    let mut p2t = Vec3::new(p2[kx], p2[ky], p2[kz]);
    let s = ray.shear;
    p0t.x += s.x * p0t.z;
    p0t.y += s.y * p0t.z;
    p1t.x += s.x * p1t.z;
    p1t.y += s.y * p1t.z;
    p2t.x += s.x * p2t.z;
    p2t.y += s.y * p2t.z;

    let mut e0 = p1t.x * p2t.y - p1t.y * p2t.x;
    let mut e1 = p2t.x * p0t.y - p2t.y * p0t.x;
    let mut e2 = p0t.x * p1t.y - p0t.y * p1t.x;
    if e0 == 0.0 || e1 == 0.0 || e2 == 0.0 {
        // Fall back to double precision on edges.
        let (a, b, c) = (p0t.as_dvec3(), p1t.as_dvec3(), p2t.as_dvec3());
        let cross = |p: DVec3, q: DVec3| (p.x * q.y - p.y * q.x) as f32;
        e0 = cross(b, c);
        e1 = cross(c, a);
        e2 = cross(a, b);
    }
    if (e0 < 0.0 || e1 < 0.0 || e2 < 0.0) && (e0 > 0.0 || e1 > 0.0 || e2 > 0.0) {
        return None;
    }
    let det = e0 + e1 + e2;
    if det == 0.0 {
        return None;
    }
    p0t.z *= s.z;
    p1t.z *= s.z;
    p2t.z *= s.z;
    let t_scaled = e0 * p0t.z + e1 * p1t.z + e2 * p2t.z;
    if det < 0.0 && (t_scaled >= 0.0 || t_scaled < tmax * det) {
        return None;
    }
    if det > 0.0 && (t_scaled <= 0.0 || t_scaled > tmax * det) {
        return None;
    }
    let inv_det = 1.0 / det;
    let t = t_scaled * inv_det;

    // Reject hits within the rounding error of t = 0 (pbrt-v4 §6.8.7).
    let max_zt = p0t.z.abs().max(p1t.z.abs()).max(p2t.z.abs());
    let delta_z = gamma(3) * max_zt;
    let max_xt = p0t.x.abs().max(p1t.x.abs()).max(p2t.x.abs());
    let max_yt = p0t.y.abs().max(p1t.y.abs()).max(p2t.y.abs());
    let delta_x = gamma(5) * (max_xt + max_zt);
    let delta_y = gamma(5) * (max_yt + max_zt);
    let delta_e = 2.0 * (gamma(2) * max_xt * max_yt + delta_y * max_xt + delta_x * max_yt);
    let max_e = e0.abs().max(e1.abs()).max(e2.abs());
    let delta_t =
        3.0 * (gamma(3) * max_e * max_zt + delta_e * max_zt + delta_z * max_e) * inv_det.abs();
    if t <= delta_t {
        return None;
    }
    Some((t, e1 * inv_det, e2 * inv_det))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn hits_inside_and_misses_outside() {
        let tri = [Vec3::ZERO, Vec3::X, Vec3::Y];
        let ray = RayPrep::new(Vec3::new(0.25, 0.25, 1.0), -Vec3::Z);
        let (t, b1, b2) = intersect(&ray, &tri, f32::INFINITY).unwrap();
        assert!((t - 1.0).abs() < 1e-6 && (b1 - 0.25).abs() < 1e-6 && (b2 - 0.25).abs() < 1e-6);
        assert!(intersect(&ray, &tri, 0.5).is_none(), "beyond tmax");
        let miss = RayPrep::new(Vec3::new(0.75, 0.75, 1.0), -Vec3::Z);
        assert!(intersect(&miss, &tri, f32::INFINITY).is_none());
        let behind = RayPrep::new(Vec3::new(0.25, 0.25, 1.0), Vec3::Z);
        assert!(intersect(&behind, &tri, f32::INFINITY).is_none());
    }

    #[test]
    fn shared_edges_and_vertices_are_watertight() {
        // A fan of triangles around the origin; rays straight at the shared
        // vertex and along shared edges must hit at least one of them.
        let n = 7;
        let tris: Vec<[Vec3; 3]> = (0..n)
            .map(|i| {
                let a0 = i as f32 / n as f32 * std::f32::consts::TAU;
                let a1 = (i + 1) as f32 / n as f32 * std::f32::consts::TAU;
                [
                    Vec3::ZERO,
                    Vec3::new(a0.cos(), a0.sin(), 0.0),
                    Vec3::new(a1.cos(), a1.sin(), 0.0),
                ]
            })
            .collect();
        let mut targets = vec![Vec3::ZERO];
        targets.extend(tris.iter().map(|t| t[1] * 0.37));
        for target in targets {
            for o in [
                Vec3::new(0.3, -0.2, 2.0),
                Vec3::new(-1.0, 0.5, 0.7),
                Vec3::new(0.0, 0.0, 5.0),
            ] {
                let d = (target - o).normalize();
                let ray = RayPrep::new(o, d);
                let hits = tris
                    .iter()
                    .filter(|t| intersect(&ray, t, f32::INFINITY).is_some())
                    .count();
                assert!(hits >= 1, "ray through {target} leaked through the mesh");
            }
        }
    }
}
