//! Smooth vertex normals for meshes whose file has none.
//!
//! The mesh loaders call [`smooth_normals`] after repair, before the
//! MikkTSpace tangents (which follow the shading normals), so that a mesh
//! without normals shades smoothly by default, as in Mitsuba 3; a shape's
//! `face_normals: true` skips it (and drops the file's normals) to keep the
//! facets. Deforming meshes get them per frame, from that frame's
//! positions.
//!
//! Weighting: each triangle adds its unit normal weighted by its angle at
//! the vertex (Thürmer and Wüthrich 1998), the scheme of Mitsuba 3's
//! `Mesh::recompute_vertex_normals`. Unlike area weighting it does not
//! depend on how a surface is split into triangles: a fan of thin slivers
//! around a vertex pulls its normal no more than one wide triangle would.

use glam::{DVec3, Vec3};

/// Angle-weighted vertex normals of the triangles `triangles` over
/// `positions` (unit vectors; zero for a vertex that no triangle with a
/// usable normal touches, which the renderer reads as "use the face
/// normal"). Triangles with zero area or non-finite vertices add nothing.
pub fn smooth_normals(positions: &[Vec3], triangles: &[[u32; 3]]) -> Vec<Vec3> {
    // Accumulated in double precision: a vertex shared by thousands of
    // triangles sums as many terms.
    let mut sums = vec![DVec3::ZERO; positions.len()];
    for t in triangles {
        let p = t.map(|i| positions[i as usize].as_dvec3());
        let Some(n) = (p[1] - p[0]).cross(p[2] - p[0]).try_normalize() else {
            continue;
        };
        for k in 0..3 {
            let e1 = p[(k + 1) % 3] - p[k];
            let e2 = p[(k + 2) % 3] - p[k];
            let angle = e1.angle_between(e2);
            if angle.is_finite() {
                sums[t[k] as usize] += n * angle;
            }
        }
    }
    sums.iter()
        .map(|s| s.try_normalize().map_or(Vec3::ZERO, DVec3::as_vec3))
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Mitsuba 3's own test of its weighting (`test04_normal_weighting_scheme`):
    /// two triangles meet at vertex 0 at right angles, with angles π/2 and
    /// acos(3/5) there; the shared vertex's normal is their angle-weighted
    /// mean, the others their face's normal.
    #[test]
    fn normals_are_weighted_by_the_angle_at_the_vertex() {
        let (a, b) = (1.0, 0.5);
        let positions = [
            Vec3::ZERO,
            Vec3::new(-a, 1.0, 0.0),
            Vec3::new(a, 1.0, 0.0),
            Vec3::new(-b, 0.0, 1.0),
            Vec3::new(b, 0.0, 1.0),
        ];
        let normals = smooth_normals(&positions, &[[0, 1, 2], [0, 3, 4]]);
        let (n0, n1) = (Vec3::new(0.0, 0.0, -1.0), Vec3::new(0.0, 1.0, 0.0));
        let shared = (n0 * std::f32::consts::FRAC_PI_2 + n1 * (3.0f32 / 5.0).acos()).normalize();
        let expected = [shared, n0, n0, n1, n1];
        for (n, e) in normals.iter().zip(expected) {
            assert!(n.abs_diff_eq(e, 1e-6), "{n} against {e}");
        }
    }

    #[test]
    fn unused_vertices_and_degenerate_triangles_give_zero() {
        let positions = [Vec3::ZERO, Vec3::X, Vec3::Y, Vec3::splat(5.0)];
        // The second triangle repeats a vertex: no area, no contribution.
        let normals = smooth_normals(&positions, &[[0, 1, 2], [0, 0, 3]]);
        assert_eq!(normals[..3], [Vec3::Z; 3]);
        assert_eq!(normals[3], Vec3::ZERO);
    }
}
