//! Round trips: every camera's rays land where its projection maths says,
//! for a rotated and translated pose on a non-square film.

// `unwrap` in this test code is the assertion: the inputs are the test's
// own, so a failure is a bug, and the panic reports it with the error.

use super::*;
use radiant_core::glam::{Mat4, Quat, Vec2, Vec3};
use radiant_core::{Camera, CameraRays};

const RES: Vec2 = Vec2::new(64.0, 40.0);

fn pose() -> Mat4 {
    Mat4::from_rotation_translation(
        Quat::from_euler(radiant_core::glam::EulerRot::YXZ, 0.7, -0.3, 0.2),
        Vec3::new(1.5, -2.0, 0.25),
    )
}

/// Film positions spread over the whole image (a Halton-like lattice).
fn film_points() -> Vec<Vec2> {
    (0..200)
        .map(|i| {
            let fx = (i as f32 * 0.618_034).fract();
            let fy = (i as f32 * 0.754_878).fract();
            Vec2::new(fx * RES.x, fy * RES.y)
        })
        .collect()
}

fn lens_points() -> Vec<Vec2> {
    (0..200)
        .map(|i| Vec2::new((i as f32 * 0.569_84).fract(), (i as f32 * 0.323_14).fract()))
        .collect()
}

/// Rays of `camera`, in camera space.
fn rays(camera: &dyn Camera, film: &[Vec2]) -> Vec<(Vec3, Vec3, f32)> {
    let n = film.len();
    let (mut o, mut d, mut w) = (vec![Vec3::ZERO; n], vec![Vec3::ZERO; n], vec![0.0; n]);
    camera.generate(
        film,
        &lens_points()[..n],
        CameraRays {
            origins: &mut o,
            directions: &mut d,
            weights: &mut w,
        },
    );
    let inv = pose().inverse();
    (0..n)
        .map(|i| {
            assert!((d[i].length() - 1.0).abs() < 1e-5, "unit directions");
            (
                inv.transform_point3(o[i]),
                inv.transform_vector3(d[i]),
                w[i],
            )
        })
        .collect()
}

/// Raster position of the camera-space image-plane point (x, y) at z = 1
/// for a horizontal field of view `fov` (degrees).
fn raster_of_plane_point(x: f32, y: f32, fov: f32) -> Vec2 {
    let tx = (fov.to_radians() * 0.5).tan();
    let ty = tx * RES.y / RES.x;
    let ndc = Vec2::new(-x / tx, y / ty);
    Vec2::new((ndc.x + 1.0) * 0.5 * RES.x, (1.0 - ndc.y) * 0.5 * RES.y)
}

#[test]
fn perspective_rays_project_back_to_their_film_position() {
    let cam = Perspective::new(pose(), RES, 50.0, FovAxis::X).unwrap();
    for (p, (o, d, w)) in film_points().iter().zip(rays(&cam, &film_points())) {
        assert!(o.length() < 1e-5 && w == 1.0);
        let back = raster_of_plane_point(d.x / d.z, d.y / d.z, 50.0);
        assert!((back - *p).length() < 2e-3, "{p} → {back}");
    }
}

#[test]
fn thin_lens_rays_start_on_the_aperture_and_meet_in_the_focal_plane() {
    let (radius, focus) = (0.3, 4.0);
    let cam = ThinLens::new(pose(), RES, 50.0, FovAxis::X, radius, focus).unwrap();
    let mut off_centre = 0;
    for (p, (o, d, w)) in film_points().iter().zip(rays(&cam, &film_points())) {
        assert!(o.z.abs() < 1e-5 && o.truncate().length() <= radius * (1.0 + 1e-5) && w == 1.0);
        off_centre += usize::from(o.truncate().length() > 0.1 * radius);
        // Where the ray crosses z = focus, the pinhole ray of p crosses too.
        let q = o + d * ((focus - o.z) / d.z);
        let back = raster_of_plane_point(q.x / focus, q.y / focus, 50.0);
        assert!((back - *p).length() < 2e-3, "{p} → {back}");
    }
    assert!(off_centre > 150, "the aperture is used");
}

#[test]
fn orthographic_rays_are_parallel_and_start_on_the_window() {
    let cam = Orthographic::new(pose(), RES, 3.0).unwrap();
    let half = Vec2::new(1.5, 1.5 * RES.y / RES.x);
    for (p, (o, d, _)) in film_points().iter().zip(rays(&cam, &film_points())) {
        assert!((d - Vec3::Z).length() < 1e-5 && o.z.abs() < 1e-5);
        let ndc = Vec2::new(-o.x / half.x, o.y / half.y);
        let back = Vec2::new((ndc.x + 1.0) * 0.5 * RES.x, (1.0 - ndc.y) * 0.5 * RES.y);
        assert!((back - *p).length() < 2e-3, "{p} → {back}");
    }
}

#[test]
fn spherical_rays_map_back_through_longitude_and_latitude() {
    let cam = Spherical::new(pose(), RES);
    for (p, (o, d, _)) in film_points().iter().zip(rays(&cam, &film_points())) {
        assert!(o.length() < 1e-5);
        let phi = (-d.x).atan2(d.z);
        let lambda = d.y.clamp(-1.0, 1.0).asin();
        let back = Vec2::new(
            (phi / std::f32::consts::TAU + 0.5) * RES.x,
            (0.5 - lambda / std::f32::consts::PI) * RES.y,
        );
        // Longitude wraps at the image's left and right edges and is
        // undefined at the poles.
        let dx = (back.x - p.x).abs();
        let dx = if lambda.cos() > 1e-3 {
            dx.min(RES.x - dx)
        } else {
            0.0
        };
        assert!(dx < 2e-3 && (back.y - p.y).abs() < 2e-3, "{p} → {back}");
    }
}
