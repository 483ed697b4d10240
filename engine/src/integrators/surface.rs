//! Surface interactions: what the shading stages need to know about a hit.
//!
//! A hit's shading frame has the shading normal as its `n`. Its tangent
//! `s` matters only to anisotropic lobes, normal maps and bump maps, so
//! it is oriented only where the frame's effects contain
//! [`Effects::TANGENT_FRAMES`](radiant_core::Effects)
//! ([`interaction_with_derivatives`]), as Mitsuba 3 orients it:
//!
//! * meshes with texture coordinates: the MikkTSpace vertex tangent,
//!   interpolated (∂p/∂u of the face where MikkTSpace found none);
//! * rectangles and cubes: ∂p/∂u of their (Mitsuba 3) parametrization;
//! * spheres: ∂p/∂u of u = φ/2π, along the object's latitude lines;
//!
//! each made orthogonal to the shading normal (Gram–Schmidt), with
//! `t = n × s`. Where there is no usable parametrization (a mesh without
//! texture coordinates, degenerate ones, a sphere's pole) the tangent
//! turns about the primitive's z axis ([`Frame::around_z`]), continuous
//! wherever the normal is not along z. ∂p/∂u and ∂p/∂v are returned with
//! their real lengths (the unit vectors of that frame where there are
//! none). Elsewhere the tangent is whatever [`Frame::from_normal`] makes.

use crate::accel::offset::{sphere_error, triangle_point};
use crate::accel::{Hit, Placement, Primitive};
use crate::extract::{BARYCENTRIC_UVS, RenderScene};
use glam::{Vec2, Vec3};
use radiant_core::{Effects, Frame};
use std::f32::consts::{FRAC_1_PI, PI, TAU};

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

impl Default for Interaction {
    /// A hit at the origin facing +z (what a missed ray's slot holds until
    /// a hit is resolved there).
    fn default() -> Self {
        Self {
            p: Vec3::ZERO,
            err: Vec3::ZERO,
            ng: Vec3::Z,
            frame: Frame::from_normal(Vec3::Z),
            uv: Vec2::ZERO,
        }
    }
}

/// The surface's derivatives at a hit, in render space with their real
/// lengths (scene units per unit of u or v).
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct Derivatives {
    /// ∂p/∂u.
    pub dp_du: Vec3,
    /// ∂p/∂v.
    pub dp_dv: Vec3,
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

/// Hits ahead of the one being resolved whose records [`prefetch`] asks
/// for: far enough that a miss to memory is over when the hit's turn
/// comes, near enough that the lines are still cached then.
pub const PREFETCH_AHEAD: usize = 8;

/// Bytes of hit records (primitives, their shading records, instance
/// records) above which [`prefetch`] pays where hits go through a top
/// level: each record is then reached through its instance's, a chain of
/// two loads that asking ahead takes apart (the field of 10,000 bunnies,
/// 9 MB of records, renders 6 % faster). Below about half a core's
/// second-level cache asking only costs instructions (6 % of the Cornell
/// box's time).
const PREFETCH_ABOVE: usize = 1 << 20;

/// [`PREFETCH_ABOVE`] for hits in one bottom level, whose records are
/// reached in one load: asking ahead costs about 80 instructions a hit,
/// which pay only where the records are far larger than the caches. Of
/// the one-level scenes measured, the 2.4 million triangles of the
/// 25-mesh grid (270 MB of records) render 4 % faster with it, the
/// plastic-pane ogre (124,000 triangles, 14 MB) 2–4 % slower and the
/// bunny (7.8 MB) no faster (`engine/benches/SUITE.md`, stop 29).
const PREFETCH_ABOVE_ONE_LEVEL: usize = 64 << 20;

/// Whether a batch stage should [`prefetch`] the records of `scene`'s
/// hits: whether they take more than [`PREFETCH_ABOVE`], or
/// [`PREFETCH_ABOVE_ONE_LEVEL`] where there is no top level.
pub fn prefetch_pays(scene: &RenderScene) -> bool {
    use std::mem::{size_of, size_of_val};
    let per_primitive = size_of::<Primitive>() + size_of::<[Vec3; 3]>() + size_of::<Frame>();
    let bytes = scene.surfaces.normals.len() * per_primitive + size_of_val(scene.accel.instances());
    let above = if scene.accel.has_top_level() {
        PREFETCH_ABOVE
    } else {
        PREFETCH_ABOVE_ONE_LEVEL
    };
    bytes > above
}

/// Starts loading what resolving `hit` reads, in two steps: `far` is hit
/// 2 × [`PREFETCH_AHEAD`] ahead, whose instance record is asked for;
/// `near` is [`PREFETCH_AHEAD`] ahead, whose primitive (addressed through
/// that record) and shading records are. A batch stage calls this once
/// per hit it resolves; misses (and `None`) are skipped.
#[inline(always)]
pub fn prefetch(scene: &RenderScene, far: Option<&Hit>, near: Option<&Hit>) {
    use crate::accel::prefetch::prefetch;
    if let Some(hit) = far {
        scene.accel.prefetch_instance(hit);
    }
    let Some(hit) = near else { return };
    scene.accel.prefetch_primitive(hit);
    let i = hit.prim as usize;
    let surfaces = &scene.surfaces;
    if let Some(n) = surfaces.normals.get(i) {
        prefetch(n);
    }
    if let Some(f) = surfaces.face_frames.get(i)
        && scene.accel.in_render_space(hit)
    {
        prefetch(f);
    }
}

/// Resolves `hit` of the ray `origin + t·dir` at shutter time `tau`, with
/// a shading frame whose tangent is arbitrary.
#[inline]
pub fn interaction(
    scene: &RenderScene,
    hit: &Hit,
    origin: Vec3,
    dir: Vec3,
    tau: f32,
) -> Interaction {
    resolve::<false>(scene, hit, origin, dir, tau).0
}

/// Resolves `hit` as [`interaction`] does, with the shading frame's
/// tangent oriented by the surface's parametrization, and the surface's
/// derivatives.
#[inline]
pub fn interaction_with_derivatives(
    scene: &RenderScene,
    hit: &Hit,
    origin: Vec3,
    dir: Vec3,
    tau: f32,
) -> (Interaction, Derivatives) {
    resolve::<true>(scene, hit, origin, dir, tau)
}

/// The interaction and, with `TANGENTS`, an oriented frame and the
/// derivatives (zero without).
#[inline(always)]
fn resolve<const TANGENTS: bool>(
    scene: &RenderScene,
    hit: &Hit,
    origin: Vec3,
    dir: Vec3,
    tau: f32,
) -> (Interaction, Derivatives) {
    let (prim, placement) = scene.accel.primitive(hit, tau);
    let Some(place) = placement else {
        return local_interaction::<TANGENTS>(scene, &prim, hit, origin, dir, None);
    };
    // In the instance's space (the ray as the query saw it: only a
    // sphere's hit point reads it), then out to render space with the
    // transform's rounding error.
    let (o, d) = match *prim {
        Primitive::Sphere(..) => {
            let (o, d, _) = place.ray_to_object(origin, dir);
            (o, d)
        }
        Primitive::Triangle(_) => (origin, dir),
    };
    let (it, dp) = local_interaction::<TANGENTS>(scene, &prim, hit, o, d, Some(&place));
    let (p, err) = place.point_to_render(it.p, it.err);
    let ng = place.normal_to_render(it.ng);
    let ns = place.normal_to_render(it.frame.n);
    let ns = above_tangent_plane(if ns == Vec3::ZERO { ng } else { ns }, ng);
    let (frame, dp) = if TANGENTS {
        let to_render = |v: Vec3| place.vector_to_render(v);
        let dp = Derivatives {
            dp_du: to_render(dp.dp_du),
            dp_dv: to_render(dp.dp_dv),
        };
        let frame =
            Frame::with_tangent(ns, to_render(it.frame.s)).unwrap_or_else(|| Frame::around_z(ns));
        (frame, dp)
    } else {
        (Frame::from_normal(ns), dp)
    };
    let it = Interaction {
        p,
        err,
        ng,
        frame,
        uv: it.uv,
    };
    (it, dp)
}

/// The interaction with `prim` in its own space. Face frames are stored
/// for primitives in render space only; a placed primitive's frame is
/// made from its normal (its tangents are turned by the placement anyway).
#[inline(always)]
fn local_interaction<const TANGENTS: bool>(
    scene: &RenderScene,
    prim: &Primitive,
    hit: &Hit,
    origin: Vec3,
    dir: Vec3,
    placed: Option<&Placement>,
) -> (Interaction, Derivatives) {
    let i = hit.prim as usize;
    match prim {
        Primitive::Triangle(v) => {
            let b = [1.0 - hit.b1 - hit.b2, hit.b1, hit.b2];
            let (p, err) = triangle_point(v, b[0], b[1], b[2]);
            let face = match placed {
                None => scene.surfaces.face_frames[i],
                Some(_) => Frame::from_normal((v[1] - v[0]).cross(v[2] - v[0]).normalize_or_zero()),
            };
            let ng = face.n;
            let n = scene.surfaces.normals[i];
            let ns = (n[0] != Vec3::ZERO).then(|| {
                let ns = (n[0] * b[0] + n[1] * b[1] + n[2] * b[2]).try_normalize();
                above_tangent_plane(ns.unwrap_or(ng), ng)
            });
            let uvs = scene.surfaces.uvs[i];
            let uv = if textured(scene) {
                uvs[0] * b[0] + uvs[1] * b[1] + uvs[2] * b[2]
            } else {
                Vec2::ZERO
            };
            let (frame, dp) = if TANGENTS {
                let ns = ns.unwrap_or(ng);
                let tangent = scene
                    .surfaces
                    .tangents
                    .get(i)
                    .map(|t| t[0] * b[0] + t[1] * b[1] + t[2] * b[2]);
                triangle_frame(ns, v, &uvs, tangent)
            } else {
                (ns.map_or(face, Frame::from_normal), Derivatives::default())
            };
            let it = Interaction {
                p,
                err,
                ng,
                frame,
                uv,
            };
            (it, dp)
        }
        &Primitive::Sphere(centre, radius) => {
            let raw = origin + dir * hit.t;
            let n = (raw - centre).normalize();
            // Re-project onto the surface to shrink the error.
            let p = centre + n * radius;
            // Texture coordinates in the sphere's object space (Mitsuba 3's).
            let rows = scene.surfaces.normals[i];
            let local = Vec3::new(rows[0].dot(n), rows[1].dot(n), rows[2].dot(n));
            let uv = if textured(scene) {
                Vec2::new(
                    (local.y.atan2(local.x) * FRAC_1_PI * 0.5).rem_euclid(1.0),
                    local.z.clamp(-1.0, 1.0).acos() * FRAC_1_PI,
                )
            } else {
                Vec2::ZERO
            };
            let (frame, dp) = if TANGENTS {
                sphere_frame(n, local, &rows, radius)
            } else {
                (Frame::from_normal(n), Derivatives::default())
            };
            let it = Interaction {
                p,
                err: sphere_error(p) + sphere_error(centre),
                ng: n,
                frame,
                uv,
            };
            (it, dp)
        }
    }
}

/// Whether hits need texture coordinates: only where a module of the
/// frame declares [`Effects::TEXTURES`] (a sphere's take an `atan2` and
/// an `acos`); elsewhere they are zero.
#[inline(always)]
fn textured(scene: &RenderScene) -> bool {
    scene.effects.contains(Effects::TEXTURES)
}

/// The shading frame around `ns` of a point of triangle `v` with vertex
/// texture coordinates `uvs` and interpolated vertex tangent `tangent`
/// (if the mesh has tangents), and the triangle's derivatives.
#[inline]
fn triangle_frame(
    ns: Vec3,
    v: &[Vec3; 3],
    uvs: &[Vec2; 3],
    tangent: Option<Vec3>,
) -> (Frame, Derivatives) {
    // A mesh without texture coordinates has the placeholder uvs and no
    // tangents; a real triangle that happens to have the same uvs has
    // MikkTSpace tangents.
    let uvless = *uvs == BARYCENTRIC_UVS && tangent.is_none_or(|t| t == Vec3::ZERO);
    let dp = if uvless {
        None
    } else {
        triangle_derivatives(v, uvs)
    };
    let frame = tangent
        .and_then(|t| Frame::with_tangent(ns, t))
        .or_else(|| dp.and_then(|d| Frame::with_tangent(ns, d.dp_du)))
        .unwrap_or_else(|| Frame::around_z(ns));
    let dp = dp.unwrap_or(Derivatives {
        dp_du: frame.s,
        dp_dv: frame.t,
    });
    (frame, dp)
}

/// ∂p/∂u and ∂p/∂v of triangle `v` under its texture coordinates `uvs`
/// (Mitsuba 3's formula); `None` where the coordinates are degenerate.
#[inline]
fn triangle_derivatives(v: &[Vec3; 3], uvs: &[Vec2; 3]) -> Option<Derivatives> {
    let (dp0, dp1) = (v[1] - v[0], v[2] - v[0]);
    let (duv0, duv1) = (uvs[1] - uvs[0], uvs[2] - uvs[0]);
    let det = duv0.perp_dot(duv1);
    let usable = det.abs() > 1e-9 * duv0.length() * duv1.length();
    if !usable {
        return None;
    }
    let inv = 1.0 / det;
    let dp = Derivatives {
        dp_du: (dp0 * duv1.y - dp1 * duv0.y) * inv,
        dp_dv: (dp1 * duv0.x - dp0 * duv1.x) * inv,
    };
    (dp.dp_du.is_finite() && dp.dp_dv.is_finite()).then_some(dp)
}

/// The shading frame and derivatives at unit normal `n` of a sphere of
/// radius `radius`, where `local` is `n` in the sphere's object space and
/// `rows` the rows of the rotation into it (Mitsuba 3's: u = φ/2π,
/// v = θ/π).
#[inline]
fn sphere_frame(n: Vec3, local: Vec3, rows: &[Vec3; 3], radius: f32) -> (Frame, Derivatives) {
    let out = |v: Vec3| rows[0] * v.x + rows[1] * v.y + rows[2] * v.z;
    let rd = local.x.hypot(local.y);
    let dp_dv = if rd > 0.0 {
        Vec3::new(local.z * local.x / rd, local.z * local.y / rd, -rd)
    } else {
        // At the poles, as Mitsuba 3.
        Vec3::X
    };
    let dp = Derivatives {
        dp_du: out(Vec3::new(-local.y, local.x, 0.0)) * (TAU * radius),
        dp_dv: out(dp_dv) * (PI * radius),
    };
    // At a pole ∂p/∂u vanishes: the frame there is its limit along φ = 0,
    // the object's +y at both poles.
    let frame = Frame::with_tangent(n, dp.dp_du)
        .or_else(|| Frame::with_tangent(n, out(Vec3::Y)))
        .unwrap_or_else(|| Frame::around_z(n));
    (frame, dp)
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

    /// A triangle of a textured mesh whose uvs happen to equal the
    /// placeholder of uv-less meshes keeps its real derivatives; a uv-less
    /// one gets its frame's unit vectors.
    #[test]
    fn placeholder_uvs_with_tangents_are_real_uvs() {
        let v = [
            Vec3::ZERO,
            Vec3::new(2.0, 0.0, 0.0),
            Vec3::new(0.0, 3.0, 0.0),
        ];
        let (frame, dp) = triangle_frame(Vec3::Z, &v, &BARYCENTRIC_UVS, Some(Vec3::X));
        assert_eq!(frame.s, Vec3::X);
        assert_eq!((dp.dp_du, dp.dp_dv), (v[1], v[2]));
        let (frame, dp) = triangle_frame(Vec3::Z, &v, &BARYCENTRIC_UVS, None);
        assert_eq!((dp.dp_du, dp.dp_dv), (frame.s, frame.t));
    }

    /// At either pole the sphere's tangent is the limit of ∂p/∂u along
    /// φ = 0, the object's +y; elsewhere it runs along ∂p/∂u.
    #[test]
    fn sphere_tangents_at_the_poles_are_the_limit_along_phi_zero() {
        let rows = [Vec3::X, Vec3::Y, Vec3::Z];
        for n in [Vec3::Z, Vec3::NEG_Z] {
            let (frame, _) = sphere_frame(n, n, &rows, 1.0);
            assert!((frame.s - Vec3::Y).length() < 1e-6, "{n}: {}", frame.s);
            let near = Vec3::new(1e-3, 0.0, n.z).normalize();
            let (f, dp) = sphere_frame(near, near, &rows, 1.0);
            assert!(f.s.dot(Vec3::Y) > 0.999, "{near}: {}", f.s);
            assert!(dp.dp_du.normalize().dot(f.s) > 0.999);
        }
    }
}
