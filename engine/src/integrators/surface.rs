//! Surface interactions: what the shading stages need to know about a hit.

use crate::accel::offset::{sphere_error, triangle_error};
use crate::accel::{Hit, Primitive};
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

/// Resolves `hit` of the ray `origin + t·dir`.
#[inline]
pub fn interaction(scene: &RenderScene, hit: &Hit, origin: Vec3, dir: Vec3) -> Interaction {
    let i = hit.prim as usize;
    match scene.accel.primitives()[i] {
        Primitive::Triangle(v) => {
            let b0 = 1.0 - hit.b1 - hit.b2;
            let p = v[0] * b0 + v[1] * hit.b1 + v[2] * hit.b2;
            let ng = (v[1] - v[0]).cross(v[2] - v[0]).normalize();
            let n = scene.surfaces.normals[i];
            let ns = if n[0] == Vec3::ZERO {
                ng
            } else {
                (n[0] * b0 + n[1] * hit.b1 + n[2] * hit.b2)
                    .try_normalize()
                    .unwrap_or(ng)
            };
            let uv = scene.surfaces.uvs[i];
            Interaction {
                p,
                err: triangle_error(&v, b0, hit.b1, hit.b2),
                ng,
                frame: Frame::from_normal(ns),
                uv: uv[0] * b0 + uv[1] * hit.b1 + uv[2] * hit.b2,
            }
        }
        Primitive::Sphere(centre, radius) => {
            let raw = origin + dir * hit.t;
            let n = (raw - centre).normalize();
            // Re-project onto the surface to shrink the error.
            let p = centre + n * radius;
            let uv = Vec2::new(
                (n.y.atan2(n.x) * std::f32::consts::FRAC_1_PI * 0.5).rem_euclid(1.0),
                n.z.clamp(-1.0, 1.0).acos() * std::f32::consts::FRAC_1_PI,
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
