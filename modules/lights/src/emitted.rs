//! What the lights' emission sides ([`radiant_core::Emission`]) share:
//! cosine-weighted directions about a surface normal, and the disc that
//! rays from lights at infinity start on.

use radiant_core::glam::{Vec2, Vec3};
use radiant_core::warp::{square_to_cosine_hemisphere, square_to_disk_concentric};
use radiant_core::{BoundingSphere, Frame};
use std::f32::consts::{FRAC_1_PI, PI};

/// A cosine-weighted direction about the unit normal `n`, with its
/// solid-angle density.
#[inline]
pub(crate) fn cosine_direction(n: Vec3, u: Vec2) -> (Vec3, f32) {
    let local = square_to_cosine_hemisphere(u);
    (Frame::from_normal(n).to_world(local), local.z * FRAC_1_PI)
}

/// The origin of a ray travelling along the unit `dir` from infinitely far
/// away: a point drawn uniformly (`u`) on the disc of the scene sphere's
/// radius perpendicular to `dir`, moved upstream outside the scene, and
/// the disc's density per unit area.
#[inline]
pub(crate) fn disc_origin(sphere: &BoundingSphere, dir: Vec3, u: Vec2) -> (Vec3, f32) {
    let d = square_to_disk_concentric(u) * sphere.radius;
    let frame = Frame::from_normal(dir);
    let p = sphere.centre + frame.to_world(Vec3::new(d.x, d.y, 0.0)) - dir * (2.0 * sphere.radius);
    (p, disc_pdf(sphere))
}

/// Density per unit area of [`disc_origin`]'s points.
#[inline]
pub(crate) fn disc_pdf(sphere: &BoundingSphere) -> f32 {
    1.0 / (PI * sphere.radius * sphere.radius)
}
