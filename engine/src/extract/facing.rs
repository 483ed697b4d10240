//! Which one-sided surfaces the camera sees from behind.
//!
//! Most shaders reflect from the front of a surface only (the side its
//! normal points to: the winding's side for triangles, outside for
//! spheres), as in Mitsuba; seen from behind they are black, with no error.
//! A rectangle turned the wrong way then renders as a black hole. After
//! extract, [`back_facing`] traces a coarse grid of camera rays and names
//! the materials whose visible surface the camera sees mostly from behind,
//! so that `radiant info` and `radiant render` can warn about them.

use super::RenderScene;
use crate::integrators::surface::interaction;
use glam::{Vec2, Vec3};
use radiant_core::{CameraRays, Effects};
use std::fmt;

/// Camera rays per side of the grid [`back_facing`] traces.
const GRID: u32 = 32;

/// Least share of the grid's rays that must see a material's back before
/// it is reported: a sliver seen edge-on is no mistake.
const MIN_SHARE: f32 = 0.01;

/// A one-sided material that the camera sees mostly from behind.
#[derive(Debug, Clone, PartialEq)]
pub struct BackFacing {
    /// The material's name in the scene.
    pub material: String,
    /// Its shader type (`diffuse`, …).
    pub module: String,
    /// The share of the camera's view where its back is seen (0–1).
    pub back: f32,
    /// The share of the camera's view where its front is seen (0–1).
    pub front: f32,
}

impl fmt::Display for BackFacing {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(
            f,
            "the camera sees the back of surfaces with material `{}` ({}, one-sided) over {:.0} % \
             of the image and their front over {:.0} %; one-sided surfaces are black from behind: \
             turn them to face the camera (or set `flip_normals: true` on the shape)",
            self.material,
            self.module,
            100.0 * self.back,
            100.0 * self.front
        )
    }
}

/// The one-sided materials of `scene` whose surfaces the camera sees
/// more from behind than from the front, over a grid of camera rays
/// through pixel centres at the frame's start.
pub fn back_facing(scene: &RenderScene) -> Vec<BackFacing> {
    let (w, h) = (scene.settings.width as f32, scene.settings.height as f32);
    let film: Vec<Vec2> = (0..GRID * GRID)
        .map(|i| {
            let (x, y) = ((i % GRID) as f32 + 0.5, (i / GRID) as f32 + 0.5);
            Vec2::new(x * w / GRID as f32, y * h / GRID as f32)
        })
        .collect();
    let n = film.len();
    let lens = vec![Vec2::splat(0.5); n];
    let (mut origins, mut directions, mut weights) =
        (vec![Vec3::ZERO; n], vec![Vec3::ZERO; n], vec![0.0; n]);
    scene.camera.generate(
        &film,
        &lens,
        CameraRays {
            origins: &mut origins,
            directions: &mut directions,
            weights: &mut weights,
        },
    );
    // (front, back) hits per material.
    let mut seen = vec![(0u32, 0u32); scene.shaders.len()];
    for ((&o, &d), &weight) in origins.iter().zip(&directions).zip(&weights) {
        if weight <= 0.0 {
            continue;
        }
        let Some(hit) = scene.accel.intersect(o, d, f32::INFINITY) else {
            continue;
        };
        let m = scene.material(&hit) as usize;
        let Some(count) = seen.get_mut(m) else {
            continue;
        };
        if interaction(scene, &hit, o, d, 0.0).ng.dot(d) > 0.0 {
            count.1 += 1;
        } else {
            count.0 += 1;
        }
    }
    let rays = n as f32;
    seen.iter()
        .enumerate()
        .filter(|&(m, &(front, back))| {
            let two_sided = scene.shaders[m]
                .effects()
                .intersects(Effects::TRANSMISSION | Effects::NULL_INTERFACE);
            !two_sided && back > front && back as f32 >= MIN_SHARE * rays
        })
        .map(|(m, &(front, back))| BackFacing {
            material: scene.material_names[m].clone(),
            module: scene.material_types[m].clone(),
            back: back as f32 / rays,
            front: front as f32 / rays,
        })
        .collect()
}
