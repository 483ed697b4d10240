//! Tessellation of the scene's shapes into render-space primitives.
//!
//! The last line of defence against degenerate geometry: a triangle whose
//! render-space (single-precision) coordinates or normal are not finite,
//! or whose normal vanishes in single precision, is dropped and counted, so the
//! integrator never meets a NaN normal.

use crate::world::{Geometry, MeshRepairs};
use glam::{DMat3, DMat4, DVec3, Vec2, Vec3};

/// One primitive with its shading attributes, in render space.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) enum ShapePrim {
    /// A triangle with per-vertex normals (zero = use the face normal),
    /// texture coordinates and tangents (zero = none: shading takes ∂p/∂u
    /// of the face).
    Triangle {
        v: [Vec3; 3],
        n: [Vec3; 3],
        uv: [Vec2; 3],
        t: [Vec3; 3],
    },
    /// A sphere, with the rotation from render space to its object space
    /// (rows), where its texture coordinates are defined.
    Sphere {
        centre: Vec3,
        radius: f32,
        to_object: [Vec3; 3],
    },
}

/// The cube's faces as Mitsuba 3's `cube` lays them out: corners a, b, c,
/// d (counter-clockwise seen from outside) with texture coordinates
/// (0, 1), (1, 1), (1, 0), (0, 0), in Mitsuba's order of faces (−y, +y,
/// +x, +z, −x, −z).
const CUBE_FACES: [[[f64; 3]; 4]; 6] = [
    [
        [1.0, -1.0, -1.0],
        [1.0, -1.0, 1.0],
        [-1.0, -1.0, 1.0],
        [-1.0, -1.0, -1.0],
    ],
    [
        [1.0, 1.0, -1.0],
        [-1.0, 1.0, -1.0],
        [-1.0, 1.0, 1.0],
        [1.0, 1.0, 1.0],
    ],
    [
        [1.0, -1.0, -1.0],
        [1.0, 1.0, -1.0],
        [1.0, 1.0, 1.0],
        [1.0, -1.0, 1.0],
    ],
    [
        [1.0, -1.0, 1.0],
        [1.0, 1.0, 1.0],
        [-1.0, 1.0, 1.0],
        [-1.0, -1.0, 1.0],
    ],
    [
        [-1.0, -1.0, 1.0],
        [-1.0, 1.0, 1.0],
        [-1.0, 1.0, -1.0],
        [-1.0, -1.0, -1.0],
    ],
    [
        [1.0, 1.0, -1.0],
        [1.0, -1.0, -1.0],
        [-1.0, -1.0, -1.0],
        [-1.0, 1.0, -1.0],
    ],
];

/// The texture coordinates of a cube face's corners a, b, c, d.
const CUBE_UVS: [Vec2; 4] = [Vec2::Y, Vec2::ONE, Vec2::X, Vec2::ZERO];

/// The texture coordinates of the rectangle's corners (−1, −1), (1, −1),
/// (1, 1), (−1, 1): Mitsuba 3's ((x + 1)/2, (y + 1)/2).
const RECTANGLE_UVS: [Vec2; 4] = [Vec2::ZERO, Vec2::X, Vec2::ONE, Vec2::Y];

/// The texture coordinates of every triangle of a mesh without any: the
/// barycentric coordinates (b₁, b₂) of the hit, as in Mitsuba 3. They are
/// no parametrization of the surface: shading frames there turn about the
/// z axis ([`Frame::around_z`](radiant_core::Frame::around_z)).
pub(crate) const BARYCENTRIC_UVS: [Vec2; 3] = [Vec2::ZERO, Vec2::X, Vec2::Y];

/// Tessellates `geometry` under `to_world`, then shifts it so that
/// `render_origin` becomes the origin, appending to `out`. With `flip`, the
/// front side of every triangle (its winding and shading normals) is turned
/// round. Returns the triangles dropped as unusable in render space; with
/// `keep_all` (the frames of a deforming mesh, which must keep their
/// triangles), none are dropped: such triangles are never hit.
pub(crate) fn tessellate(
    geometry: &Geometry,
    to_world: DMat4,
    render_origin: DVec3,
    flip: bool,
    keep_all: bool,
    out: &mut Vec<ShapePrim>,
) -> MeshRepairs {
    let point = |p: DVec3| (to_world.transform_point3(p) - render_origin).as_vec3();
    let normal_matrix = DMat3::from_mat4(to_world).inverse().transpose();
    let normal = |n: DVec3| (normal_matrix * n).normalize_or_zero().as_vec3();
    let tangent = |t: Vec3| {
        to_world
            .transform_vector3(t.as_dvec3())
            .normalize_or_zero()
            .as_vec3()
    };
    // A mirroring transform reverses the winding; swap two vertices so the
    // face normal stays the transformed normal. Flipping swaps them (back).
    let swap = (to_world.determinant() < 0.0) != flip;
    let sign = if flip { -1.0 } else { 1.0 };
    let mut dropped = MeshRepairs::default();
    let mut push = |v: [Vec3; 3], n: [Vec3; 3], uv: [Vec2; 3], t: [Vec3; 3]| {
        let normal = (v[1] - v[0]).cross(v[2] - v[0]);
        if !(keep_all || v.iter().all(|p| p.is_finite()) && normal.is_finite()) {
            dropped.non_finite += 1;
            return;
        }
        if !keep_all && normal.try_normalize().is_none() {
            dropped.degenerate += 1;
            return;
        }
        let n = n.map(|n| n * sign);
        out.push(if swap {
            ShapePrim::Triangle {
                v: [v[0], v[2], v[1]],
                n: [n[0], n[2], n[1]],
                uv: [uv[0], uv[2], uv[1]],
                t: [t[0], t[2], t[1]],
            }
        } else {
            ShapePrim::Triangle { v, n, uv, t }
        });
    };
    // A quad (a, b, c, d) as the triangles (a, b, c) and (a, c, d), the
    // pair area lights recognise as a rectangle.
    type Push<'p> = dyn FnMut([Vec3; 3], [Vec3; 3], [Vec2; 3], [Vec3; 3]) + 'p;
    let quad = |push: &mut Push<'_>, c: [DVec3; 4], uv: [Vec2; 4]| {
        let p = c.map(point);
        let none = [Vec3::ZERO; 3];
        push([p[0], p[1], p[2]], none, [uv[0], uv[1], uv[2]], none);
        push([p[0], p[2], p[3]], none, [uv[0], uv[2], uv[3]], none);
    };
    match geometry {
        Geometry::Rectangle => quad(
            &mut push,
            [
                DVec3::new(-1.0, -1.0, 0.0),
                DVec3::new(1.0, -1.0, 0.0),
                DVec3::new(1.0, 1.0, 0.0),
                DVec3::new(-1.0, 1.0, 0.0),
            ],
            RECTANGLE_UVS,
        ),
        Geometry::Cube => {
            for face in CUBE_FACES {
                quad(&mut push, face.map(DVec3::from), CUBE_UVS);
            }
        }
        Geometry::Sphere => {
            debug_assert!(!flip, "the scene loader rejects flipped spheres");
            let centre = point(DVec3::ZERO);
            let scale = to_world.transform_vector3(DVec3::X).length();
            // The transform is a similarity (the loader checks): its
            // linear part over its scale is orthogonal, and its inverse
            // is its transpose, whose rows are its columns.
            let r = DMat3::from_mat4(to_world) / scale;
            let to_object = [r.x_axis, r.y_axis, r.z_axis].map(|c| c.as_vec3());
            out.push(ShapePrim::Sphere {
                centre,
                radius: scale as f32,
                to_object,
            });
        }
        Geometry::Mesh(mesh) => {
            for (f, t) in mesh.triangles.iter().enumerate() {
                let idx = t.map(|i| i as usize);
                let v = idx.map(|i| point(mesh.positions[i].as_dvec3()));
                let n = match &mesh.normals {
                    Some(ns) if idx.iter().all(|&i| ns[i] != Vec3::ZERO) => {
                        idx.map(|i| normal(ns[i].as_dvec3()))
                    }
                    _ => [Vec3::ZERO; 3],
                };
                let uv = match &mesh.uvs {
                    Some(uvs) => idx.map(|i| uvs[i]),
                    None => BARYCENTRIC_UVS,
                };
                let t = match &mesh.tangents {
                    Some(ts) => ts[f].map(tangent),
                    None => [Vec3::ZERO; 3],
                };
                push(v, n, uv, t);
            }
        }
    }
    dropped
}

#[cfg(test)]
mod tests {
    use super::*;

    fn face_normal(p: &ShapePrim) -> Vec3 {
        match p {
            ShapePrim::Triangle { v, .. } => (v[1] - v[0]).cross(v[2] - v[0]).normalize(),
            ShapePrim::Sphere { .. } => unreachable!(),
        }
    }

    #[test]
    fn cube_faces_point_outwards() {
        let mut prims = Vec::new();
        tessellate(
            &Geometry::Cube,
            DMat4::IDENTITY,
            DVec3::ZERO,
            false,
            false,
            &mut prims,
        );
        assert_eq!(prims.len(), 12);
        for p in &prims {
            let ShapePrim::Triangle { v, .. } = p else {
                unreachable!()
            };
            let centre = (v[0] + v[1] + v[2]) / 3.0;
            assert!(face_normal(p).dot(centre) > 0.0);
        }
    }

    #[test]
    fn rectangle_keeps_its_normal_under_mirroring() {
        for m in [
            DMat4::IDENTITY,
            DMat4::from_scale(DVec3::new(-1.0, 1.0, 1.0)),
        ] {
            let mut prims = Vec::new();
            tessellate(
                &Geometry::Rectangle,
                m,
                DVec3::ZERO,
                false,
                false,
                &mut prims,
            );
            for p in &prims {
                assert!((face_normal(p) - Vec3::Z).length() < 1e-6);
            }
        }
    }

    #[test]
    fn flipped_cube_faces_point_inwards_and_mirroring_composes() {
        for m in [
            DMat4::IDENTITY,
            DMat4::from_scale(DVec3::new(1.0, -1.0, 1.0)),
        ] {
            let mut prims = Vec::new();
            let dropped = tessellate(&Geometry::Cube, m, DVec3::ZERO, true, false, &mut prims);
            assert_eq!((prims.len(), dropped), (12, MeshRepairs::default()));
            for p in &prims {
                let ShapePrim::Triangle { v, .. } = p else {
                    unreachable!()
                };
                let centre = (v[0] + v[1] + v[2]) / 3.0;
                assert!(face_normal(p).dot(centre) < 0.0);
            }
        }
    }

    #[test]
    fn triangles_unusable_in_render_space_are_dropped_and_counted() {
        let mesh = crate::world::MeshData {
            positions: vec![
                Vec3::ZERO,
                Vec3::X,
                Vec3::Y,
                // A needle whose height vanishes once scaled by 1e-30.
                Vec3::new(2.0, 0.0, 0.0),
                Vec3::new(3.0, 1e-7, 0.0),
                Vec3::new(4.0, 0.0, 0.0),
            ],
            triangles: vec![[0, 1, 2], [3, 4, 5]],
            ..Default::default()
        };
        let geometry = Geometry::Mesh(std::sync::Arc::new(mesh));
        let mut prims = Vec::new();
        let dropped = tessellate(
            &geometry,
            DMat4::from_scale(DVec3::splat(1e-30)),
            DVec3::ZERO,
            false,
            false,
            &mut prims,
        );
        assert_eq!((prims.len(), dropped.degenerate), (0, 2), "{dropped:?}");
        prims.clear();
        let dropped = tessellate(
            &geometry,
            DMat4::from_scale(DVec3::splat(1e38)),
            DVec3::ZERO,
            false,
            false,
            &mut prims,
        );
        assert_eq!((prims.len(), dropped.non_finite), (0, 2), "{dropped:?}");
        prims.clear();
        let dropped = tessellate(
            &geometry,
            DMat4::IDENTITY,
            DVec3::ZERO,
            false,
            false,
            &mut prims,
        );
        assert_eq!((prims.len(), dropped), (2, MeshRepairs::default()));
    }

    #[test]
    fn render_origin_is_subtracted_in_double_precision() {
        let mut prims = Vec::new();
        let far = DVec3::splat(1e6);
        tessellate(
            &Geometry::Rectangle,
            DMat4::from_translation(far) * DMat4::from_scale(DVec3::splat(1e-3)),
            far,
            false,
            false,
            &mut prims,
        );
        let ShapePrim::Triangle { v, .. } = prims[0] else {
            unreachable!()
        };
        assert_eq!(v[0], Vec3::new(-1e-3, -1e-3, 0.0));
    }
}
