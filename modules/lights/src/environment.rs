//! The `environment` light: radiance arriving from infinitely far away in
//! every direction, from an equirectangular map (EXR or Radiance HDR) or a
//! constant colour.
//!
//! Conventions are Mitsuba 3's `envmap`, so references match: +y is up, a
//! light-space direction d maps to u = atan2(d.x, −d.z) / 2π,
//! v = acos(d.y) / π, pixel (x, y) sits at (u, v) = ((x + ½) / W, y / (H − 1))
//! (the first row is the zenith, the last the nadir, the map wraps in u)
//! and radiance is interpolated bilinearly between pixels (checked against
//! Mitsuba's own `eval` in `tests/lights.rs`).
//!
//! Importance sampling (as Mitsuba's `envmap` with its continuous
//! `Marginal2D`): each pixel gets the weight luminance × sin θ of its row,
//! and the density over (u, v) is the bilinear interpolation of these
//! weights between pixel centres, the same interpolation as the radiance,
//! so it follows luminance × sin θ (the solid angle per unit of u and v)
//! within a cell too. A [`Distribution2D`] picks one of the W × (H − 1)
//! cells between pixel centres by its integral (the mean of its four
//! corners); [`bilinear`] draws the point within it. The solid-angle
//! density is the (u, v) density over 2π² sin θ.
//!
//! The pole rows weigh 0 (sin θ = 0); so that a cell touching a pole never
//! has zero density where the pole's radiance is not zero, the row next to
//! a pole weighs at least half the pole's luminance (times its own sin θ).
//! Everywhere else a weight is 0 only where the luminance is.
//!
//! The GPU side (`environment.wgsl`) samples and evaluates the same way from
//! the same tables: the map's texels, the pixel weights, and the marginal
//! and conditional CDFs of the distribution itself
//! ([`Distribution1D::cdf`](radiant_core::distribution::Distribution1D::cdf);
//! a test holds the two to the same densities and samples).

mod angles;
mod bilinear;

use crate::map_file::load_map;
use crate::params::check_colour;
use bilinear::{bilinear_pdf, sample_bilinear};
use radiant_core::distribution::Distribution2D;
use radiant_core::glam::{DMat3, Mat3, UVec2, Vec2, Vec3};
use radiant_core::warp::{UNIFORM_SPHERE_PDF, square_to_uniform_sphere};
use radiant_core::{
    BoundingSphere, Color, Effects, EmitterEval, GpuModule, GpuParams, Light, LightSample,
    ModuleInfo, ParamDoc, ParamError, Params, Registry, Rgb, luminance,
};
use serde::Deserialize;
use std::f32::consts::{PI, TAU};
use std::path::PathBuf;
use std::sync::{Arc, Mutex, OnceLock, Weak};
use std::time::SystemTime;

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct EnvironmentParams {
    filename: Option<String>,
    radiance: Option<Color>,
    #[serde(default = "one")]
    scale: f32,
}

fn one() -> f32 {
    1.0
}

const DOCS: &[ParamDoc] = &[
    ParamDoc {
        name: "filename",
        ty: "path to .exr or .hdr",
        default: "none",
        doc: "Equirectangular map of linear radiance (W/(m²·sr)), zenith (+y) in the first row; relative to the scene file. Give this or `radiance`.",
    },
    ParamDoc {
        name: "radiance",
        ty: "rgb, W/(m²·sr)",
        default: "none",
        doc: "Constant radiance from every direction, instead of a map.",
    },
    ParamDoc {
        name: "scale",
        ty: "number ≥ 0",
        default: "1",
        doc: "Factor on the radiance. The light's `transform` (a rotation) turns the map.",
    },
];

/// A tabulated environment map with its sampling distribution.
#[derive(Debug, Clone, PartialEq)]
struct Map {
    size: UVec2,
    /// Radiance per pixel, row-major, scale applied.
    texels: Vec<Rgb>,
    /// Sampling weight per pixel, row-major (see [`pixel_weights`]).
    weights: Vec<f32>,
    /// Over the cells between pixel centres, by the mean of their corners'
    /// weights.
    distribution: Distribution2D,
    /// The distribution's density of each cell, row-major (a lookup
    /// instead of two through the rows' tables).
    cell_pdf: Vec<f32>,
    /// The GPU parameters of the map, made on first use.
    gpu: GpuCache,
}

/// Parameters made once and kept with the map they were made from; every
/// cache equals every other (a map's equality is its data's).
#[derive(Debug, Clone, Default)]
struct GpuCache(OnceLock<GpuParams>);

impl PartialEq for GpuCache {
    fn eq(&self, _: &Self) -> bool {
        true
    }
}

#[derive(Debug, Clone, PartialEq)]
enum Emission {
    Constant(Rgb),
    /// Shared with other instances of the same map (see [`MapCache`]).
    Map(Arc<Map>),
}

/// The decoded maps and their distributions, kept while a light uses them:
/// a light rebuilt for a new frame (the scene's bounds moved) finds the
/// map its predecessor decoded instead of reading the file again. Keyed by
/// the file (path, size, modification time) and the scale.
struct MapCache {
    entries: Mutex<Vec<(MapKey, Weak<Map>, f32)>>,
}

#[derive(Debug, Clone, PartialEq)]
struct MapKey {
    path: PathBuf,
    len: u64,
    modified: Option<SystemTime>,
    scale: u32,
}

impl MapKey {
    /// The key of the map file at `path` scaled by `scale`.
    fn new(path: &std::path::Path, scale: f32) -> Self {
        let meta = std::fs::metadata(path).ok();
        MapKey {
            path: path.canonicalize().unwrap_or_else(|_| path.to_path_buf()),
            len: meta.as_ref().map_or(0, |m| m.len()),
            modified: meta.and_then(|m| m.modified().ok()),
            scale: scale.to_bits(),
        }
    }
}

static MAPS: MapCache = MapCache {
    entries: Mutex::new(Vec::new()),
};

impl MapCache {
    /// The map of `key` with its integral, made by `make` unless a live
    /// light holds it already.
    fn get(
        &self,
        key: MapKey,
        make: impl FnOnce() -> Result<(Map, f32), String>,
    ) -> Result<(Arc<Map>, f32), String> {
        let mut entries = self.entries.lock().unwrap_or_else(|e| e.into_inner());
        entries.retain(|(_, weak, _)| weak.strong_count() > 0);
        if let Some((_, weak, integral)) = entries.iter().find(|(k, ..)| *k == key)
            && let Some(map) = weak.upgrade()
        {
            return Ok((map, *integral));
        }
        let (map, integral) = make()?;
        let map = Arc::new(map);
        entries.push((key, Arc::downgrade(&map), integral));
        Ok((map, integral))
    }
}

/// Radiance from infinitely far away.
#[derive(Debug, Clone, PartialEq)]
pub struct EnvironmentLight {
    emission: Emission,
    /// Light space to render space (a rotation) and back.
    to_render: Mat3,
    to_light: Mat3,
    sphere: BoundingSphere,
    /// ∫ luminance dω over the sphere.
    integral: f32,
}

impl EnvironmentLight {
    /// A constant environment of `radiance`.
    pub fn constant(radiance: Rgb, sphere: BoundingSphere) -> Self {
        Self {
            emission: Emission::Constant(radiance),
            to_render: Mat3::IDENTITY,
            to_light: Mat3::IDENTITY,
            sphere,
            integral: 4.0 * PI * luminance(radiance),
        }
    }

    /// An environment map of `size.x × size.y` linear-radiance pixels
    /// (row-major, zenith first), turned by the rotation `to_render`.
    pub fn from_pixels(
        pixels: Vec<Rgb>,
        size: UVec2,
        to_render: Mat3,
        sphere: BoundingSphere,
    ) -> Result<Self, String> {
        let (w, h) = (size.x as usize, size.y as usize);
        if w < 1 || h < 2 || pixels.len() != w * h {
            return Err(format!(
                "an environment map needs at least 1 × 2 pixels, found {} × {}",
                size.x, size.y
            ));
        }
        if let Some(i) = pixels
            .iter()
            .position(|p| !p.is_finite() || p.min_element() < 0.0)
        {
            return Err(format!(
                "the environment map's pixel ({}, {}) is {}; radiance must be finite and non-negative",
                i % w,
                i / w,
                pixels[i]
            ));
        }
        let weights = pixel_weights(&pixels, size);
        let distribution = Distribution2D::new(
            &cell_weights(&weights, size),
            UVec2::new(size.x, size.y - 1),
        );
        // ∫ L dω = ∫∫ L sin θ 2π² du dv, the cells' means times their area.
        let integral = (2.0 * PI * PI / (w * (h - 1)) as f32) * distribution.total() as f32;
        let cell_pdf = (0..size.y - 1)
            .flat_map(|y| (0..size.x).map(move |x| UVec2::new(x, y)))
            .map(|cell| distribution.pdf(cell))
            .collect();
        Ok(Self {
            emission: Emission::Map(Arc::new(Map {
                size,
                texels: pixels,
                weights,
                distribution,
                cell_pdf,
                gpu: GpuCache::default(),
            })),
            to_render,
            to_light: to_render.transpose(),
            sphere,
            integral,
        })
    }

    /// Radiance arriving from the light-space unit direction `d` and the
    /// density with which `sample` picks it.
    #[inline]
    fn eval_local(&self, d: Vec3) -> EmitterEval {
        let mut eval = EmitterEval::default();
        self.eval_chunk(&[d], |_, e| eval = e);
        eval
    }

    /// [`EnvironmentLight::eval_local`] for each of the light-space
    /// directions `dirs` (at most [`CHUNK`]), each handed to `each` with
    /// its index; in stages, as [`Map::sample_chunk`].
    #[inline]
    fn eval_chunk(&self, dirs: &[Vec3], mut each: impl FnMut(usize, EmitterEval)) {
        let m = match &self.emission {
            Emission::Constant(c) => {
                let eval = EmitterEval {
                    radiance: *c,
                    pdf: UNIFORM_SPHERE_PDF,
                };
                (0..dirs.len()).for_each(|i| each(i, eval));
                return;
            }
            Emission::Map(m) => m,
        };
        let mut places = [(0.0, 0.0, 0.0); CHUNK];
        for (d, place) in dirs.iter().zip(&mut places) {
            let mut u = angles::atan2(d.x, -d.z) / TAU;
            u -= u.floor();
            // θ from both its sine and cosine: accurate at the poles too,
            // where acos(y) is not (y rounds to ±1 within 3e-4 of them).
            let sin_theta = (d.x * d.x + d.z * d.z).sqrt();
            let theta = angles::atan2(sin_theta, d.y);
            *place = (u, theta / PI, sin_theta);
        }
        let mut patches = [Patch::default(); CHUNK];
        for (&(u, v, _), at) in places.iter().zip(&mut patches).take(dirs.len()) {
            *at = m.locate(u, v);
        }
        for (i, (at, (_, _, sin_theta))) in patches.iter().zip(places).take(dirs.len()).enumerate()
        {
            each(
                i,
                EmitterEval {
                    radiance: m.radiance(at),
                    pdf: m.pdf(at, sin_theta),
                },
            );
        }
    }
}

/// The sampling weight of each pixel: its luminance times sin θ of its
/// row, 0 on the pole rows; the rows next to a pole take at least half the
/// pole's luminance, so that no cell at a pole is weightless where the
/// pole's radiance is not zero.
fn pixel_weights(pixels: &[Rgb], size: UVec2) -> Vec<f32> {
    let (w, h) = (size.x as usize, size.y as usize);
    let lum = |x: usize, y: usize| luminance(pixels[y * w + x]);
    let mut weights = Vec::with_capacity(w * h);
    for y in 0..h {
        let sin_theta = if y == 0 || y == h - 1 {
            0.0
        } else {
            (PI * y as f32 / (h - 1) as f32).sin()
        };
        for x in 0..w {
            let mut l = lum(x, y);
            if y == 1 {
                l = l.max(0.5 * lum(x, 0));
            }
            if y + 2 == h {
                l = l.max(0.5 * lum(x, h - 1));
            }
            weights.push(l * sin_theta);
        }
    }
    weights
}

/// The sampling weight of each of the `size.x × (size.y − 1)` cells
/// between pixel centres: the integral of the bilinear patch over it, the
/// mean of its four corners' weights.
fn cell_weights(weights: &[f32], size: UVec2) -> Vec<f32> {
    let (w, h) = (size.x as usize, size.y as usize);
    let mut cells = Vec::with_capacity(w * (h - 1));
    for y in 0..h - 1 {
        for x in 0..w {
            let x1 = (x + 1) % w;
            let corners = weights[y * w + x]
                + weights[y * w + x1]
                + weights[(y + 1) * w + x]
                + weights[(y + 1) * w + x1];
            cells.push(0.25 * corners);
        }
    }
    cells
}

/// Where a (u, v) lies in the map: its cell (between the centres of
/// pixels x0 and x1 = x0 + 1 (wrapping), rows y0 and y0 + 1) and its
/// place `t` in [0, 1]² within the cell.
#[derive(Clone, Copy, Default)]
struct Patch {
    x0: usize,
    x1: usize,
    y0: usize,
    t: Vec2,
}

/// Samples or directions that [`Map::sample_chunk`] and
/// [`EnvironmentLight::eval_chunk`] take through their stages together.
const CHUNK: usize = 32;

/// The column after `x` (< `w`) in a map `w` wide, wrapping in u.
#[inline(always)]
fn next_column(x: usize, w: usize) -> usize {
    if x + 1 == w { 0 } else { x + 1 }
}

impl Map {
    /// The map's words for `environment.wgsl` (see its header): size,
    /// the offsets of the tables, then the pixel weights, the marginal CDF
    /// of the cell rows, each cell row's conditional CDF and the texels.
    fn gpu_params(&self) -> &GpuParams {
        self.gpu.0.get_or_init(|| {
            let d = &self.distribution;
            let marginal = d.marginal().cdf();
            let rows: Vec<f32> = d.rows().iter().flat_map(|r| r.cdf()).copied().collect();
            // Offsets from the light's first word: 17 words precede the tables.
            let weights_at = 17;
            let marginal_at = weights_at + self.weights.len();
            let rows_at = marginal_at + marginal.len();
            let texels_at = rows_at + rows.len();
            GpuParams::new()
                .u32(self.size.x)
                .u32(self.size.y)
                .u32(weights_at as u32)
                .u32(marginal_at as u32)
                .u32(rows_at as u32)
                .u32(texels_at as u32)
                .f32s(self.weights.iter().copied())
                .f32s(marginal.iter().copied())
                .f32s(rows)
                .f32s(self.texels.iter().flat_map(|t| t.to_array()))
        })
    }

    /// The cell of (u, v) and the place within it, as the radiance is
    /// interpolated: cell x lies between the centres of pixels x and
    /// x + 1, wrapping in u.
    #[inline]
    fn locate(&self, u: f32, v: f32) -> Patch {
        let (w, h) = (self.size.x as usize, self.size.y as usize);
        let fx = u * w as f32 - 0.5;
        let fy = v * (h - 1) as f32;
        let xf = fx.floor();
        // x0 = xf mod w, without a division for the usual −1 ≤ xf < w.
        let (x, wi) = (xf as isize, w as isize);
        let x0 = if (0..wi).contains(&x) {
            x
        } else if (-wi..0).contains(&x) {
            x + wi
        } else {
            x.rem_euclid(wi)
        } as usize;
        let y0 = (fy as usize).min(h - 2);
        Patch {
            x0,
            x1: next_column(x0, w),
            y0,
            t: Vec2::new(fx - xf, fy - y0 as f32),
        }
    }

    /// The values of `table` (one per pixel) at the corners of `at`'s
    /// cell, in [`bilinear`]'s order.
    #[inline]
    fn corners<T: Copy>(&self, table: &[T], at: &Patch) -> [T; 4] {
        let w = self.size.x as usize;
        let (top, bottom) = (at.y0 * w, (at.y0 + 1) * w);
        [
            table[top + at.x0],
            table[top + at.x1],
            table[bottom + at.x0],
            table[bottom + at.x1],
        ]
    }

    /// Radiance at `at`: bilinear between pixels.
    #[inline]
    fn radiance(&self, at: &Patch) -> Rgb {
        let [a, b, c, d] = self.corners(&self.texels, at);
        let t = at.t;
        let top = a * (1.0 - t.x) + b * t.x;
        let bottom = c * (1.0 - t.x) + d * t.x;
        top * (1.0 - t.y) + bottom * t.y
    }

    /// Solid-angle density at `at`, where sin θ is `sin_theta`: the
    /// cell's density over (u, v) times the bilinear patch's within it,
    /// over 2π² sin θ.
    #[inline]
    fn pdf(&self, at: &Patch, sin_theta: f32) -> f32 {
        if sin_theta <= 0.0 {
            return 0.0;
        }
        let cell = self.cell_pdf[at.y0 * self.size.x as usize + at.x0];
        let patch = bilinear_pdf(at.t, self.corners(&self.weights, at));
        cell * patch / (2.0 * PI * PI * sin_theta)
    }

    /// A light-space direction for the sample `u`, with its radiance and
    /// density.
    #[inline]
    fn sample(&self, u: Vec2) -> (Vec3, Rgb, f32) {
        let mut sample = None;
        self.sample_chunk(&[u], |_, s| sample = Some(s));
        sample.expect("one sample for one u")
    }

    /// [`Map::sample`] for each of `u` (at most [`CHUNK`] of them), each
    /// result handed to `each` with its index.
    ///
    /// The work goes in stages, each a loop over the chunk: the cells'
    /// rows, their columns, the places within the cells, the directions,
    /// then radiance and density. Each stage of one sample is a chain of
    /// dependent steps (loads in the searches, square roots and divisions
    /// after them); loops this short let the CPU run the chains of many
    /// samples at once, where one sample at a time would wait for each.
    #[inline]
    fn sample_chunk(&self, u: &[Vec2], mut each: impl FnMut(usize, (Vec3, Rgb, f32))) {
        let d = &self.distribution;
        let (w, h) = (self.size.x as usize, self.size.y as usize);
        let mut patches = [Patch::default(); CHUNK];
        let patches = &mut patches[..u.len()];
        // Per sample, its place within the cell's row and column as the
        // distribution drew it, before the patch's bilinear warp.
        let mut rest = [Vec2::ZERO; CHUNK];
        for ((p, r), u) in patches.iter_mut().zip(&mut rest).zip(u) {
            (p.y0, r.y) = d.marginal().sample(u.y);
        }
        for ((p, r), u) in patches.iter_mut().zip(&mut rest).zip(u) {
            (p.x0, r.x) = d.rows()[p.y0].sample(u.x);
            p.x1 = next_column(p.x0, w);
        }
        for (p, r) in patches.iter_mut().zip(rest) {
            p.t = sample_bilinear(r, self.corners(&self.weights, p));
        }
        let mut dirs = [(Vec3::ZERO, 0.0); CHUNK];
        for (p, dir) in patches.iter().zip(&mut dirs) {
            // Cells start at the first pixel centre, half a pixel into the map.
            let mut u = (p.x0 as f32 + 0.5 + p.t.x) / w as f32;
            if u >= 1.0 {
                u -= 1.0;
            }
            let v = (p.y0 as f32 + p.t.y) / (h - 1) as f32;
            let (sin_t, cos_t) = angles::sin_cos(PI * v);
            let (sin_p, cos_p) = angles::sin_cos(TAU * u);
            *dir = (Vec3::new(sin_p * sin_t, cos_t, -cos_p * sin_t), sin_t);
        }
        for (i, (p, (dir, sin_t))) in patches.iter().zip(dirs).enumerate() {
            each(i, (dir, self.radiance(p), self.pdf(p, sin_t)));
        }
    }
}

impl Light for EnvironmentLight {
    /// π r² ∫ L dω: the power through a disc covering the scene.
    fn power(&self) -> f32 {
        PI * self.sphere.radius * self.sphere.radius * self.integral
    }

    fn is_delta(&self) -> bool {
        false
    }

    fn sample(&self, refs: &[Vec3], u: &[Vec2], out: &mut [LightSample]) {
        let reach = 2.0 * self.sphere.radius;
        let to_sample = |r: Vec3, (local, radiance, pdf): (Vec3, Rgb, f32)| {
            let wi = self.to_render * local;
            LightSample {
                p: r + wi * reach,
                n: Vec3::ZERO,
                radiance: if pdf > 0.0 { radiance } else { Rgb::ZERO },
                pdf,
            }
        };
        let samples = refs.iter().zip(u).zip(out.iter_mut());
        match &self.emission {
            Emission::Constant(c) => {
                for ((r, u), o) in samples {
                    *o = to_sample(*r, (square_to_uniform_sphere(*u), *c, UNIFORM_SPHERE_PDF));
                }
            }
            Emission::Map(m) => {
                for ((refs, u), out) in refs
                    .chunks(CHUNK)
                    .zip(u.chunks(CHUNK))
                    .zip(out.chunks_mut(CHUNK))
                {
                    m.sample_chunk(u, |i, s| out[i] = to_sample(refs[i], s));
                }
            }
        }
    }

    fn eval_escaped(&self, dirs: &[Vec3], out: &mut [EmitterEval]) {
        for (dirs, out) in dirs.chunks(CHUNK).zip(out.chunks_mut(CHUNK)) {
            let mut local = [Vec3::ZERO; CHUNK];
            for (l, d) in local.iter_mut().zip(dirs) {
                *l = self.to_light * *d;
            }
            self.eval_chunk(&local[..dirs.len()], |i, e| out[i] = e);
        }
    }

    fn gpu(&self) -> Option<GpuModule> {
        let m = self.to_render;
        let head = GpuParams::new()
            .f32(2.0 * self.sphere.radius)
            .vec3(m.x_axis)
            .vec3(m.y_axis)
            .vec3(m.z_axis);
        let params = match &self.emission {
            Emission::Constant(c) => head.u32(0).rgb(*c),
            Emission::Map(map) => head.u32(1).append(map.gpu_params()),
        };
        Some(GpuModule::new(
            "environment",
            include_str!("environment.wgsl"),
            params,
        ))
    }

    fn effects(&self) -> Effects {
        Effects::ENVIRONMENT
    }

    fn emission(&self) -> Option<&dyn radiant_core::Emission> {
        Some(self)
    }
}

/// Emitted rays: a direction towards the light drawn as next-event
/// estimation draws it (the map's luminance), travelling against it from a
/// point drawn uniformly on the disc that covers the scene.
impl radiant_core::Emission for EnvironmentLight {
    fn kind(&self) -> radiant_core::EmissionKind {
        radiant_core::EmissionKind::Infinite
    }

    fn sample_emission(
        &self,
        u_pos: &[Vec2],
        u_dir: &[Vec2],
        out: &mut [radiant_core::EmissionSample],
    ) {
        for ((up, ud), o) in u_pos.iter().zip(u_dir).zip(out.iter_mut()) {
            let (local, radiance, pdf_dir) = match &self.emission {
                Emission::Constant(c) => (square_to_uniform_sphere(*ud), *c, UNIFORM_SPHERE_PDF),
                Emission::Map(m) => m.sample(*ud),
            };
            let dir = -(self.to_render * local);
            let (p, pdf_pos) = crate::emitted::disc_origin(&self.sphere, dir, *up);
            *o = radiant_core::EmissionSample {
                p,
                n: Vec3::ZERO,
                dir,
                radiance,
                pdf_pos: if pdf_dir > 0.0 { pdf_pos } else { 0.0 },
                pdf_dir,
                kind: radiant_core::EmissionKind::Infinite,
                primitive: 0,
            };
        }
    }

    fn emission_pdf(
        &self,
        rays: &[radiant_core::EmittedRay],
        out: &mut [radiant_core::EmissionPdf],
    ) {
        let pdf_pos = crate::emitted::disc_pdf(&self.sphere);
        for (r, o) in rays.iter().zip(out.iter_mut()) {
            *o = radiant_core::EmissionPdf {
                pdf_pos,
                pdf_dir: self.eval_local(self.to_light * -r.dir).pdf,
            };
        }
    }
}

/// The rotation part of a light transform, or an error if it is not one.
fn rotation(m: DMat3) -> Result<Mat3, ParamError> {
    let orthonormal = (m.transpose() * m - DMat3::IDENTITY)
        .to_cols_array()
        .iter()
        .all(|e| e.abs() < 1e-6);
    if orthonormal && m.determinant() > 0.0 {
        Ok(m.as_mat3())
    } else {
        Err(ParamError::new(
            "an `environment` light's `transform` must be a rotation (no scale, shear, mirror or translation matters)",
        ))
    }
}

pub(crate) fn register(registry: &mut Registry) {
    registry.register::<dyn Light>(
        ModuleInfo {
            type_name: "environment",
            summary: "Light from infinitely far away: an equirectangular map (importance-sampled) or a constant.",
            params: DOCS,
        },
        |params: &Params, ctx| {
            crate::not_on_a_shape("environment", ctx)?;
            let p: EnvironmentParams = params.parse()?;
            if !(p.scale >= 0.0 && p.scale.is_finite()) {
                return Err(ParamError {
                    message: format!("`scale` must be finite and non-negative, found {}", p.scale),
                    location: params.location_of("scale"),
                });
            }
            let to_render = rotation(DMat3::from_mat4(ctx.to_world))?;
            let light = match (p.filename, p.radiance) {
                (Some(_), Some(_)) | (None, None) => {
                    return Err(ParamError {
                        message: "give the environment either a `filename` (an .exr or .hdr map) or a constant `radiance`".into(),
                        location: params.location_of("radiance"),
                    });
                }
                (None, Some(c)) => {
                    check_colour(params, "radiance", c.0)?;
                    EnvironmentLight::constant(c.0 * p.scale, ctx.scene_sphere)
                }
                (Some(f), None) => {
                    let at = |message: String| ParamError {
                        message,
                        location: params.location_of("filename"),
                    };
                    let path = ctx.scene_dir.join(&f);
                    let (map, integral) = MAPS
                        .get(MapKey::new(&path, p.scale), || {
                            let (mut pixels, size) = load_map(&path)?;
                            for px in &mut pixels {
                                *px *= p.scale;
                            }
                            let light = EnvironmentLight::from_pixels(
                                pixels,
                                size,
                                to_render,
                                ctx.scene_sphere,
                            )
                            .map_err(|m| format!("{f}: {m}"))?;
                            match light.emission {
                                Emission::Map(m) => Ok((Arc::unwrap_or_clone(m), light.integral)),
                                Emission::Constant(_) => unreachable!("from_pixels makes a map"),
                            }
                        })
                        .map_err(at)?;
                    EnvironmentLight {
                        emission: Emission::Map(map),
                        to_render,
                        to_light: to_render.transpose(),
                        sphere: ctx.scene_sphere,
                        integral,
                    }
                }
            };
            Ok(Box::new(EnvironmentLight { to_render, to_light: to_render.transpose(), ..light })
                as Box<dyn Light>)
        },
    );
}

#[cfg(test)]
mod tests {
    use super::*;
    use radiant_core::{BuildContext, TextureTable};
    use std::collections::HashMap;
    use std::path::Path;

    /// Builds the scene's sky map light with a scene sphere of `radius`.
    fn sky(registry: &Registry, radius: f32) -> Box<dyn Light> {
        let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../scenes");
        let mut textures = TextureTable::default();
        let named = HashMap::new();
        let mut ctx = BuildContext::standalone(&dir, &mut textures, &named);
        ctx.scene_sphere.radius = radius;
        let params =
            Params::from_yaml("{filename: environment-sky.exr, scale: 2}").expect("valid YAML");
        // `expect` is the assertion: the committed map builds.
        registry
            .build::<dyn Light>("environment", &params, &mut ctx)
            .expect("the sky map builds")
    }

    /// Distribution1D::sample on the CDF `cdf` (n + 1 entries), as
    /// `env_sample_1d` in environment.wgsl.
    fn sample_cdf(cdf: &[f32], u: f32) -> (usize, f32) {
        let n = cdf.len() - 1;
        let i = cdf.partition_point(|&c| c <= u).clamp(1, n) - 1;
        let width = cdf[i + 1] - cdf[i];
        let rest = if width > 0.0 {
            ((u - cdf[i]) / width).clamp(0.0, radiant_core::ONE_MINUS_EPSILON)
        } else {
            0.5
        };
        (i, rest)
    }

    #[test]
    fn gpu_tables_give_the_distributions_densities_and_samples() {
        // Two black rows make a cell row of weight zero, two black columns
        // a zero cell in every row.
        let (w, h) = (7u32, 6u32);
        let pixels = (0..w * h)
            .map(|i| {
                let (x, y) = (i % w, i / w);
                if y == 2 || y == 3 || x == 3 || x == 4 {
                    Rgb::ZERO
                } else {
                    Rgb::new(0.3 * x as f32 + 0.1, y as f32, 0.01 * (x * y) as f32 + 0.5)
                }
            })
            .collect();
        let sphere = BoundingSphere {
            centre: Vec3::ZERO,
            radius: 1.0,
        };
        // `expect` in this test code is the assertion: the map is valid.
        let light = EnvironmentLight::from_pixels(pixels, UVec2::new(w, h), Mat3::IDENTITY, sphere)
            .expect("a valid map");
        let Emission::Map(map) = &light.emission else {
            panic!("from_pixels makes a map")
        };
        // The map's words start at the light's word 11; the offsets count
        // from the light's first word.
        let words = map.gpu_params().words();
        let table = |k: usize, len: usize| -> Vec<f32> {
            let at = words[k] as usize - 11;
            words[at..at + len]
                .iter()
                .map(|&b| f32::from_bits(b))
                .collect()
        };
        let (wu, rows) = (w as usize, h as usize - 1);
        assert_eq!(table(2, (w * h) as usize), map.weights);
        let marginal = table(3, rows + 1);
        let conditional = table(4, rows * (wu + 1));
        for y in 0..rows {
            let row = &conditional[y * (wu + 1)..(y + 1) * (wu + 1)];
            for x in 0..wu {
                let pdf = (marginal[y + 1] - marginal[y])
                    * (row[x + 1] - row[x])
                    * (w * rows as u32) as f32;
                let cell = UVec2::new(x as u32, y as u32);
                assert_eq!(
                    pdf.to_bits(),
                    map.distribution.pdf(cell).to_bits(),
                    "{cell}"
                );
            }
        }
        for i in 0..4096 {
            let u = Vec2::new(
                ((i % 64) as f32 + 0.37) / 64.0,
                ((i / 64) as f32 + 0.61) / 64.0,
            );
            let (y, ry) = sample_cdf(&marginal, u.y);
            let (x, rx) = sample_cdf(&conditional[y * (wu + 1)..(y + 1) * (wu + 1)], u.x);
            let p = Vec2::new((x as f32 + rx) / w as f32, (y as f32 + ry) / rows as f32);
            let expected = map.distribution.sample(u);
            assert_eq!((p, UVec2::new(x as u32, y as u32)), expected, "u = {u}");
        }
        let texels = table(5, (w * h * 3) as usize);
        assert_eq!(
            texels,
            map.texels
                .iter()
                .flat_map(|t| t.to_array())
                .collect::<Vec<_>>()
        );
    }

    #[test]
    fn a_map_is_decoded_once_while_a_light_holds_it() {
        let mut registry = Registry::new();
        register(&mut registry);
        let first = sky(&registry, 1.0);
        let second = sky(&registry, 5.0);
        // The same map seen from a sphere five times as large.
        assert!((second.power() / first.power() - 25.0).abs() < 1e-3);
        let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../scenes/environment-sky.exr");
        let cached = MAPS.get(MapKey::new(&path, 2.0), || {
            panic!("the map was decoded again")
        });
        assert!(cached.is_ok());
        drop((first, second, cached));
        // Once no light holds it, the map is freed.
        let fresh = MAPS.get(MapKey::new(&path, 2.0), || Err("decoded".into()));
        assert_eq!(fresh.err().as_deref(), Some("decoded"));
    }
}
