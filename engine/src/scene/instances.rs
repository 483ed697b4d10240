//! `instances:` of a shape: copies that share its geometry, each with its
//! own transform (applied after the shape's) and optionally its own
//! material.
//!
//! ```yaml
//! instances:                         # a list …
//!   - {transform: {translate: [1, 0, 0]}, material: red}
//!   - transform: [{translate: [2, 0, 0]}, {rotate: {axis: [0, 1, 0], angle: 30}}]
//! instances:                         # … a grid …
//!   grid: {count: [10, 1, 10], spacing: [1, 0, 1]}
//!   materials: [red, green]          # instance i takes materials[i % n]
//! instances:                         # … or a scatter
//!   scatter: {count: 10000, min: [-50, 0, -50], max: [50, 0, 50], seed: 1,
//!             rotate: [0, 360], scale: [0.8, 1.2]}
//! ```
//!
//! A grid starts at the origin and steps by `spacing`; a scatter places
//! copies uniformly in the box from `min` to `max`, turned about +y by an
//! angle uniform in `rotate` (degrees) and scaled uniformly by a factor
//! uniform in `scale`, from a hash of `seed` (the same seed, the same
//! scatter).

use super::SceneError;
use super::transform::parse_transform;
use super::yaml::{Mapping, loc, parse_node};
use crate::world::{InstanceSpec, MaterialRef};
use glam::{DMat4, DQuat, DVec3};
use marked_yaml::Node;
use radiant_core::Numbers;
use radiant_core::hash;
use serde::Deserialize;
use std::path::Path;

/// Copies at most (a grid or scatter larger than this is an error).
pub const MAX_INSTANCES: u64 = 1 << 24;

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct Grid {
    count: Numbers<3>,
    spacing: Numbers<3>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct Scatter {
    count: u64,
    min: Numbers<3>,
    max: Numbers<3>,
    #[serde(default)]
    seed: u64,
    #[serde(default)]
    rotate: Option<Numbers<2>>,
    #[serde(default)]
    scale: Option<Numbers<2>>,
}

/// Reads `instances:` at `node`; `material` resolves a material name or
/// inline material to its index.
pub(crate) fn parse_instances(
    file: &Path,
    node: &Node,
    material: &mut dyn FnMut(&Node) -> Result<MaterialRef, SceneError>,
) -> Result<Vec<InstanceSpec>, SceneError> {
    let at = |n: &Node, message: String| SceneError::new(file, loc(n.span()), message);
    if let Some(list) = node.as_sequence() {
        let mut out = Vec::with_capacity(list.len());
        for item in list.iter() {
            let mut map = Mapping::new(file, item, "instance")?;
            let transform = match map.get("transform") {
                Some(t) => parse_transform(file, t)?,
                None => DMat4::IDENTITY,
            };
            let m = map.get("material").map(&mut *material).transpose()?;
            map.finish(&["transform", "material"])?;
            out.push(InstanceSpec {
                transform,
                material: m,
            });
        }
        if out.is_empty() {
            return Err(at(node, "`instances` lists no instance".into()));
        }
        return Ok(out);
    }
    let mut map = Mapping::new(file, node, "instances")?;
    let (grid, scatter) = (map.get("grid"), map.get("scatter"));
    let materials = match map.get("materials") {
        None => Vec::new(),
        Some(list) => {
            let seq = list
                .as_sequence()
                .filter(|s| !s.is_empty())
                .ok_or_else(|| {
                    at(
                        list,
                        "`materials` must be a list of materials (names or inline)".into(),
                    )
                })?;
            seq.iter().map(&mut *material).collect::<Result<_, _>>()?
        }
    };
    map.finish(&["grid", "scatter", "materials"])?;
    let transforms = match (grid, scatter) {
        (Some(g), None) => grid_transforms(file, g)?,
        (None, Some(s)) => scatter_transforms(file, s)?,
        _ => {
            return Err(at(
                node,
                "`instances` is a list of instances, or a mapping with either `grid` or `scatter`"
                    .into(),
            ));
        }
    };
    Ok(transforms
        .into_iter()
        .enumerate()
        .map(|(i, transform)| InstanceSpec {
            transform,
            material: (!materials.is_empty()).then(|| materials[i % materials.len()]),
        })
        .collect())
}

fn grid_transforms(file: &Path, node: &Node) -> Result<Vec<DMat4>, SceneError> {
    let g: Grid = parse_node(file, node)?;
    let counts = g.count.0;
    if counts.iter().any(|&c| !(c >= 1.0 && c.fract() == 0.0)) {
        return Err(SceneError::new(
            file,
            loc(node.span()),
            "a grid's `count` is three whole numbers of at least 1",
        ));
    }
    let total = counts.iter().product::<f64>();
    check_count(file, node, total)?;
    let spacing = DVec3::from(g.spacing);
    let [nx, ny, nz] = counts.map(|c| c as u64);
    let mut out = Vec::with_capacity(total as usize);
    for z in 0..nz {
        for y in 0..ny {
            for x in 0..nx {
                let offset = DVec3::new(x as f64, y as f64, z as f64) * spacing;
                out.push(DMat4::from_translation(offset));
            }
        }
    }
    Ok(out)
}

fn scatter_transforms(file: &Path, node: &Node) -> Result<Vec<DMat4>, SceneError> {
    let s: Scatter = parse_node(file, node)?;
    check_count(file, node, s.count as f64)?;
    let (min, max) = (DVec3::from(s.min), DVec3::from(s.max));
    let rotate = s.rotate.map_or([0.0, 0.0], |r| r.0);
    let scale = s.scale.map_or([1.0, 1.0], |r| r.0);
    let usable =
        min.cmple(max).all() && (min - max).is_finite() && scale[0] > 0.0 && scale[1] >= scale[0];
    if !usable {
        return Err(SceneError::new(
            file,
            loc(node.span()),
            "a scatter needs `min` ≤ `max` (finite), and a `scale` range [a, b] with 0 < a ≤ b",
        ));
    }
    let (lo, hi) = (s.seed as u32, (s.seed >> 32) as u32);
    let u = |i: u64, k: u32| f64::from(hash::hash4(lo, hi, i as u32, k)) / 4294967296.0;
    let lerp = |[a, b]: [f64; 2], t: f64| a + (b - a) * t;
    Ok((0..s.count)
        .map(|i| {
            let p = min + (max - min) * DVec3::new(u(i, 0), u(i, 1), u(i, 2));
            let angle = lerp(rotate, u(i, 3)).to_radians();
            let k = lerp(scale, u(i, 4));
            DMat4::from_scale_rotation_translation(
                DVec3::splat(k),
                DQuat::from_rotation_y(angle),
                p,
            )
        })
        .collect())
}

fn check_count(file: &Path, node: &Node, count: f64) -> Result<(), SceneError> {
    if !(1.0..=MAX_INSTANCES as f64).contains(&count) {
        return Err(SceneError::new(
            file,
            loc(node.span()),
            format!("between 1 and {MAX_INSTANCES} instances, found {count}"),
        ));
    }
    Ok(())
}
