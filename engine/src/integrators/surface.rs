//! Surface interactions: what the shading stages need to know about a hit.

use crate::accel::offset::{sphere_error, triangle_point};
use crate::accel::{Hit, Placement, Primitive};
use crate::extract::RenderScene;
use glam::{Vec2, Vec3};
use radiant_core::Frame;

/// A ray's hit, resolved into geometry and shading data.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Interaction {
    /// The hit point.
    pub p: Vec3,
    /// Bound on the floating-point error of `p`.
    pub err: Vec3,
    /// Unit geometric normal (by winding; outward for spheres).
    pub ng: Vec3,
    /// Shading frame (its `n` is the shading normal).
    pub frame: Frame,
    /// Texture coordinates.
    pub uv: Vec2,
}

/// Least cosine between a shading normal and the geometric normal.
const MIN_SHADING_COS: f32 = 0.01;

/// Bends shading normal `ns` back above the tangent plane of the geometric
/// normal `ng` when it lies at or below it (vertex normals that lean over,
/// or that face the other way): it keeps its tangential direction and gets
/// a normal component of [`MIN_SHADING_COS`], so that the shading and the
/// geometric sides of the surface agree and the surface is neither black
/// nor lit from behind.
#[inline]
fn above_tangent_plane(ns: Vec3, ng: Vec3) -> Vec3 {
    let c = ns.dot(ng);
    if c >= MIN_SHADING_COS {
        ns
    } else {
        (ns + ng * (MIN_SHADING_COS - c)).normalize()
    }
}

/// Resolves `hit` of the ray `origin + t·dir` at shutter time `tau`.
#[inline]
pub fn interaction(
    scene: &RenderScene,
    hit: &Hit,
    origin: Vec3,
    dir: Vec3,
    tau: f32,
) -> Interaction {
    let (prim, placement) = scene.accel.primitive(hit, tau);
    match placement {
        None => local_interaction(scene, prim, hit, origin, dir, None),
        Some(place) => {
            // In the instance's space (the ray as the query saw it), then
            // out to render space with the transform's rounding error.
            let (o, d, _) = place.ray_to_object(origin, dir);
            let it = local_interaction(scene, prim, hit, o, d, Some(&place));
            let (p, err) = place.point_to_render(it.p, it.err);
            let ng = place.normal_to_render(it.ng);
            let ns = place.normal_to_render(it.frame.n);
            let ns = if ns == Vec3::ZERO { ng } else { ns };
            Interaction {
                p,
                err,
                ng,
                frame: Frame::from_normal(above_tangent_plane(ns, ng)),
                uv: it.uv,
            }
        }
    }
}

/// The interaction with `prim` in its own space. Face frames are stored
/// for primitives in render space only; a placed primitive's frame is
/// made from its normal (its tangents are turned by the placement anyway).
#[inline(always)]
fn local_interaction(
    scene: &RenderScene,
    prim: Primitive,
    hit: &Hit,
    origin: Vec3,
    dir: Vec3,
    placed: Option<&Placement>,
) -> Interaction {
    let i = hit.prim as usize;
    match prim {
        Primitive::Triangle(v) => {
            let b0 = 1.0 - hit.b1 - hit.b2;
            let (p, err) = triangle_point(&v, b0, hit.b1, hit.b2);
            let face = match placed {
                None => scene.surfaces.face_frames[i],
                Some(_) => Frame::from_normal((v[1] - v[0]).cross(v[2] - v[0]).normalize_or_zero()),
            };
            let ng = face.n;
            let n = scene.surfaces.normals[i];
            let frame = if n[0] == Vec3::ZERO {
                face
            } else {
                Frame::from_normal(above_tangent_plane(
                    (n[0] * b0 + n[1] * hit.b1 + n[2] * hit.b2)
                        .try_normalize()
                        .unwrap_or(ng),
                    ng,
                ))
            };
            let uv = scene.surfaces.uvs[i];
            Interaction {
                p,
                err,
                ng,
                frame,
                uv: uv[0] * b0 + uv[1] * hit.b1 + uv[2] * hit.b2,
            }
        }
        Primitive::Sphere(centre, radius) => {
            let raw = origin + dir * hit.t;
            let n = (raw - centre).normalize();
            // Re-project onto the surface to shrink the error.
            let p = centre + n * radius;
            // Texture coordinates in the sphere's object space (Mitsuba 3's).
            let [r0, r1, r2] = scene.surfaces.normals[i];
            let local = Vec3::new(r0.dot(n), r1.dot(n), r2.dot(n));
            let uv = Vec2::new(
                (local.y.atan2(local.x) * std::f32::consts::FRAC_1_PI * 0.5).rem_euclid(1.0),
                local.z.clamp(-1.0, 1.0).acos() * std::f32::consts::FRAC_1_PI,
            );
            Interaction {
                p,
                err: sphere_error(p) + sphere_error(centre),
                ng: n,
                frame: Frame::from_normal(n),
                uv,
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn shading_normals_below_the_surface_are_bent_above_it() {
        let ng = Vec3::Z;
        // Above the plane: untouched.
        let ns = Vec3::new(0.6, 0.0, 0.8);
        assert_eq!(above_tangent_plane(ns, ng), ns);
        // In the plane and below it: just above, same azimuth.
        for ns in [Vec3::X, Vec3::new(0.8, 0.0, -0.6)] {
            let b = above_tangent_plane(ns, ng);
            assert!((b.length() - 1.0).abs() < 1e-6, "{b}");
            assert!(b.dot(ng) > 0.0 && b.dot(ng) < 2.0 * MIN_SHADING_COS, "{b}");
            assert!(b.y.abs() < 1e-6 && b.x > 0.99, "{b}");
        }
        // Reversed: the geometric normal.
        assert!((above_tangent_plane(-Vec3::Z, ng) - ng).length() < 1e-6);
    }
}
