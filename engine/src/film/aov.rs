//! Arbitrary output variables (AOVs) and alpha: what each camera ray's
//! first hit was, filtered into planes beside the beauty image.
//!
//! Data flow: when a render asks for them (`radiant render --aov …`,
//! `--denoise`, `film.aovs:`), the wavefront records a [`FirstHit`] per
//! camera path (`integrators::path`), splats it into an [`AovTile`] with the
//! beauty's own reconstruction filter, tiles are merged into an
//! [`AovFilm`] in tile order (so the planes, like the beauty, do not depend
//! on the thread count), and [`AovFilm::develop`] gives the [`AovImage`]:
//! alpha, albedo, normal, depth, position and samples per pixel. The sums
//! live here, not in [`super::Film`]: a render that asks for none of them
//! allocates and computes nothing of this.
//!
//! Conventions: every plane is Σ w·v / Σ w over *all* the samples whose
//! filter reaches the pixel, with v = 0 for camera rays that hit nothing
//! (Mitsuba's `aov` integrator through its film). Alpha is coverage: 1 where
//! every sample hit a surface, 0 on background, fractional on edges, so the
//! other planes are premultiplied by it (divide by alpha for the mean over
//! hits). Albedo is [`radiant_core::Shader::albedo`] at the first hit;
//! normal is the first hit's shading normal in world space (unit length
//! where alpha is 1); depth is the distance from the camera ray's origin
//! to the hit (Mitsuba's `depth` AOV; the Euclidean distance, not the
//! z coordinate); position is the hit point in world space. `spp` counts
//! the samples drawn in the pixel itself (unfiltered).
//!
//! **Alpha for encoders:** [`AovImage::alpha`] is the alpha plane, row-major
//! like [`super::Image::pixels`]; `backend::cpu::render_with_aovs` returns
//! it next to the developed image.

use super::memory::{FrameTooLarge, try_filled};
use super::tile::TileBounds;
use super::{FilterTable, Reconstruction};
use glam::{Vec2, Vec3};
use radiant_core::Rgb;
use std::fmt;
use std::str::FromStr;

/// An output variable that can be written as a layer of the EXR.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum Aov {
    /// The first hit's albedo (`albedo.R/G/B`).
    Albedo,
    /// The first hit's shading normal in world space (`normal.X/Y/Z`).
    Normal,
    /// Distance from the camera to the first hit (`depth.Z`).
    Depth,
    /// The first hit's world-space position (`position.X/Y/Z`).
    Position,
    /// Samples drawn in the pixel (`spp.Y`).
    Spp,
}

impl Aov {
    /// Every output variable, in the order layers are written.
    pub const ALL: [Aov; 5] = [
        Aov::Albedo,
        Aov::Normal,
        Aov::Depth,
        Aov::Position,
        Aov::Spp,
    ];

    /// The name used on the command line, in scene files and as the EXR
    /// layer name.
    pub fn name(self) -> &'static str {
        match self {
            Aov::Albedo => "albedo",
            Aov::Normal => "normal",
            Aov::Depth => "depth",
            Aov::Position => "position",
            Aov::Spp => "spp",
        }
    }

    /// The layer's channel suffixes: `R/G/B` for colours, `X/Y/Z` for
    /// vectors, Nuke's `Z` for depth, `Y` for a scalar count.
    pub fn channels(self) -> &'static [&'static str] {
        match self {
            Aov::Albedo => &["R", "G", "B"],
            Aov::Normal | Aov::Position => &["X", "Y", "Z"],
            Aov::Depth => &["Z"],
            Aov::Spp => &["Y"],
        }
    }
}

impl fmt::Display for Aov {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

/// An output variable name that is not one of [`Aov::ALL`].
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[error("unknown output variable `{0}`; expected one of albedo, normal, depth, position, spp")]
pub struct UnknownAov(pub String);

impl FromStr for Aov {
    type Err = UnknownAov;

    fn from_str(s: &str) -> Result<Self, Self::Err> {
        Aov::ALL
            .into_iter()
            .find(|a| a.name() == s.trim())
            .ok_or_else(|| UnknownAov(s.trim().to_string()))
    }
}

/// Parses a comma-separated list of output variables
/// (`albedo,normal,depth`): each once, in [`Aov::ALL`]'s order.
pub fn parse_list(text: &str) -> Result<Vec<Aov>, UnknownAov> {
    let mut list = text
        .split(',')
        .filter(|s| !s.trim().is_empty())
        .map(Aov::from_str)
        .collect::<Result<Vec<_>, _>>()?;
    list.sort();
    list.dedup();
    Ok(list)
}

/// A set of output variables (`film.aovs`, `--aov`), listed in
/// [`Aov::ALL`]'s order.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Hash)]
pub struct AovSet(u8);

impl AovSet {
    /// Whether the set holds no variable.
    pub fn is_empty(self) -> bool {
        self.0 == 0
    }

    /// Whether the set holds `aov`.
    pub fn contains(self, aov: Aov) -> bool {
        self.0 & Self::bit(aov) != 0
    }

    /// The variables, in [`Aov::ALL`]'s order.
    pub fn list(self) -> Vec<Aov> {
        Aov::ALL.into_iter().filter(|a| self.contains(*a)).collect()
    }

    /// The bit of `aov`: its place among the variant (and [`Aov::ALL`]).
    fn bit(aov: Aov) -> u8 {
        1 << aov as u8
    }
}

impl FromIterator<Aov> for AovSet {
    fn from_iter<I: IntoIterator<Item = Aov>>(iter: I) -> Self {
        Self(iter.into_iter().fold(0, |bits, a| bits | Self::bit(a)))
    }
}

/// What a camera path's first segment found: the values of the planes for
/// one sample (all zero for a ray that hit nothing).
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct FirstHit {
    /// 1 where the camera ray hit a surface, else 0.
    pub alpha: f32,
    /// The surface's albedo.
    pub albedo: Rgb,
    /// The shading normal, world space.
    pub normal: Vec3,
    /// Distance from the ray's origin to the hit.
    pub depth: f32,
    /// The hit point, world space.
    pub position: Vec3,
}

/// Filtered channels per pixel: Σ w, then Σ w·v of alpha, albedo (3),
/// normal (3), depth, position (3).
const CHANNELS: usize = 12;

impl FirstHit {
    /// The channels a sample adds, times its weight `w`.
    #[inline]
    fn weighted(&self, w: f32) -> [f32; CHANNELS] {
        let (a, n, p) = (self.albedo * w, self.normal * w, self.position * w);
        [
            w,
            self.alpha * w,
            a.x,
            a.y,
            a.z,
            n.x,
            n.y,
            n.z,
            self.depth * w,
            p.x,
            p.y,
            p.z,
        ]
    }

    /// Whether every value is finite (a sample that is not is dropped).
    fn is_finite(&self) -> bool {
        self.alpha.is_finite()
            && self.albedo.is_finite()
            && self.normal.is_finite()
            && self.depth.is_finite()
            && self.position.is_finite()
    }
}

#[inline]
fn add(sum: &mut [f32; CHANNELS], v: &[f32; CHANNELS]) {
    for (s, v) in sum.iter_mut().zip(v) {
        *s += v;
    }
}

/// The AOV sums of one render task's pixels, with a border as wide as the
/// filter (the counterpart of [`super::TileFilm`]).
#[derive(Debug, Clone)]
pub struct AovTile {
    bounds: TileBounds,
    sums: Vec<[f32; CHANNELS]>,
    spp: Vec<u32>,
}

impl AovTile {
    /// A tile for the pixels [x0, x1) × [y0, y1) of a `size` image, grown
    /// by the filter's reach and clipped to the image.
    pub fn new(x0: u32, y0: u32, x1: u32, y1: u32, size: (u32, u32), reach: f32) -> Self {
        let bounds = TileBounds::new(x0, y0, x1, y1, size, reach);
        Self {
            bounds,
            sums: vec![[0.0; CHANNELS]; bounds.len()],
            spp: vec![0; bounds.len()],
        }
    }

    /// Adds the samples `hits` of the pixels `pixels` (indices into the
    /// image, row-major), at raster positions `pos` with filter weights
    /// `weights` (importance sampling only), as `reconstruction` places
    /// them.
    pub fn add_samples(
        &mut self,
        reconstruction: &Reconstruction,
        pixels: impl Iterator<Item = u32>,
        pos: &[Vec2],
        weights: &[f32],
        hits: &[FirstHit],
    ) {
        let width = self.bounds.image_width as u32;
        for (k, pixel) in pixels.enumerate() {
            let (x, y) = ((pixel % width) as i32, (pixel / width) as i32);
            let i = self.bounds.index(x, y);
            self.spp[i] += 1;
            let hit = &hits[k];
            if !hit.is_finite() {
                continue;
            }
            match reconstruction {
                Reconstruction::Splat(table) => self.splat(pos[k], hit, table),
                Reconstruction::Importance(_) => add(&mut self.sums[i], &hit.weighted(weights[k])),
            }
        }
    }

    /// Adds `hit`, sampled at raster position `pos`, to every pixel within
    /// the filter's radius: for a separable filter as the image's
    /// [`super::TileFilm`] splats, one row of weights times each row's.
    fn splat(&mut self, pos: Vec2, hit: &FirstHit, table: &FilterTable) {
        let (px0, px1, py0, py1) = self.bounds.footprint(pos, table.radius());
        let taps = (px1 - px0 + 1).max(0) as usize;
        let mut wx = [0.0f32; super::MAX_TAPS];
        if let Some(g) = table.separable_row(pos.x, px0, taps, &mut wx) {
            // The values are linear in the weight: weighted once.
            let v = hit.weighted(1.0);
            let mut start = self.bounds.index(px0, py0);
            for y in py0..=py1 {
                let wy = table.factor(g, y as f32 + 0.5 - pos.y);
                if wy != 0.0 {
                    for (sum, &w) in self.sums[start..start + taps].iter_mut().zip(&wx[..taps]) {
                        let w = wy * w;
                        for (s, v) in sum.iter_mut().zip(&v) {
                            *s += v * w;
                        }
                    }
                }
                start += self.bounds.width as usize;
            }
            return;
        }
        for y in py0..=py1 {
            let dy = y as f32 + 0.5 - pos.y;
            for x in px0..=px1 {
                let w = table.weight(x as f32 + 0.5 - pos.x, dy);
                if w != 0.0 {
                    let i = self.bounds.index(x, y);
                    add(&mut self.sums[i], &hit.weighted(w));
                }
            }
        }
    }
}

/// The AOV sums of a whole frame.
#[derive(Debug, Clone)]
pub struct AovFilm {
    width: u32,
    height: u32,
    sums: Vec<[f32; CHANNELS]>,
    spp: Vec<u32>,
}

impl AovFilm {
    /// An empty film, or what it needed where its memory cannot be
    /// reserved.
    pub fn try_new(width: u32, height: u32) -> Result<Self, FrameTooLarge> {
        let len = width as usize * height as usize;
        let too_large = || FrameTooLarge::new(width, height);
        Ok(Self {
            width,
            height,
            sums: try_filled(len, [0.0; CHANNELS]).ok_or_else(too_large)?,
            spp: try_filled(len, 0).ok_or_else(too_large)?,
        })
    }

    /// Adds a tile's sums.
    pub fn merge(&mut self, tile: &AovTile) {
        let b = &tile.bounds;
        for y in 0..b.height {
            let src = (y * b.width) as usize;
            let dst = ((b.y0 + y) as u32 * self.width + b.x0 as u32) as usize;
            for x in 0..b.width as usize {
                add(&mut self.sums[dst + x], &tile.sums[src + x]);
                self.spp[dst + x] += tile.spp[src + x];
            }
        }
    }

    /// The planes: Σ w·v / Σ w per pixel (zero where no weight reached it).
    pub fn develop(&self) -> AovImage {
        let len = self.sums.len();
        let mut image = AovImage {
            width: self.width,
            height: self.height,
            alpha: Vec::with_capacity(len),
            albedo: Vec::with_capacity(len),
            normal: Vec::with_capacity(len),
            depth: Vec::with_capacity(len),
            position: Vec::with_capacity(len),
            spp: self.spp.clone(),
        };
        for s in &self.sums {
            let inv = if s[0] > 0.0 { 1.0 / s[0] } else { 0.0 };
            image.alpha.push(s[1] * inv);
            image.albedo.push(Vec3::new(s[2], s[3], s[4]) * inv);
            image.normal.push(Vec3::new(s[5], s[6], s[7]) * inv);
            image.depth.push(s[8] * inv);
            image.position.push(Vec3::new(s[9], s[10], s[11]) * inv);
        }
        image
    }
}

/// The developed planes of a frame, each row-major (top row first) like
/// [`super::Image::pixels`]; see the module's conventions.
#[derive(Debug, Clone, PartialEq)]
pub struct AovImage {
    /// Width in pixels.
    pub width: u32,
    /// Height in pixels.
    pub height: u32,
    /// Coverage in [0, 1]: the share of the pixel's (filtered) camera rays
    /// that hit a surface. PNG RGBA and EXR `A` outputs take it as alpha.
    pub alpha: Vec<f32>,
    /// First-hit albedo (premultiplied by coverage).
    pub albedo: Vec<Rgb>,
    /// First-hit shading normal, world space.
    pub normal: Vec<Vec3>,
    /// Distance from the camera to the first hit.
    pub depth: Vec<f32>,
    /// First-hit position, world space.
    pub position: Vec<Vec3>,
    /// Samples drawn in each pixel.
    pub spp: Vec<u32>,
}

impl AovImage {
    /// The values of `aov`'s channels at pixel `i`, in the order of
    /// [`Aov::channels`].
    pub fn channel(&self, aov: Aov, c: usize, i: usize) -> f32 {
        match aov {
            Aov::Albedo => self.albedo[i][c],
            Aov::Normal => self.normal[i][c],
            Aov::Depth => self.depth[i],
            Aov::Position => self.position[i][c],
            Aov::Spp => self.spp[i] as f32,
        }
    }
}

#[cfg(test)]
mod tests {
    // `unwrap` in this test code is the assertion: the film sizes are the test's own, so a failure is a bug,
    // and the panic reports it.
    use super::*;
    use crate::settings::FilterSampling;
    use radiant_filters::{TentFilter, TentKernel};

    /// A tent reaching 1.5 pixels.
    const TENT: TentFilter = radiant_filters::Separable(TentKernel { radius: 1.5 });

    #[test]
    fn lists_parse_in_a_fixed_order_and_unknown_names_are_refused() {
        assert_eq!(
            parse_list("spp, albedo,normal,albedo"),
            Ok(vec![Aov::Albedo, Aov::Normal, Aov::Spp])
        );
        let e = parse_list("albedo,nromal").unwrap_err();
        assert_eq!(e, UnknownAov("nromal".into()));
        assert!(
            e.to_string()
                .contains("albedo, normal, depth, position, spp")
        );
    }

    /// The separable splat's sums equal the general path's (the filter's
    /// two-dimensional table) to rounding, and a separable filter takes it.
    #[test]
    fn separable_splats_match_the_two_dimensional_table() {
        let table = FilterTable::new(&TENT);
        assert!(table.separable.is_some());
        let general = FilterTable {
            separable: None,
            ..table.clone()
        };
        let mut fast = AovTile::new(0, 0, 8, 8, (8, 8), table.radius());
        let mut slow = fast.clone();
        for (i, pos) in [(0.1, 0.2), (3.5, 3.5), (7.9, 0.4), (4.25, 6.75)]
            .into_iter()
            .enumerate()
        {
            let k = (i + 1) as f32;
            let hit = FirstHit {
                alpha: 1.0,
                albedo: Vec3::new(0.2, 0.4, 0.6) * k,
                normal: Vec3::new(0.0, 0.6, 0.8),
                depth: 3.0 * k,
                position: Vec3::new(1.0, -2.0, 3.0) * k,
            };
            let pos = Vec2::new(pos.0, pos.1);
            fast.splat(pos, &hit, &table);
            slow.splat(pos, &hit, &general);
        }
        assert!(slow.sums.iter().any(|s| s[0] > 0.0));
        for (a, b) in fast.sums.iter().zip(&slow.sums) {
            for (x, y) in a.iter().zip(b) {
                assert!(
                    (x - y).abs() <= 1e-5 * y.abs().max(1.0),
                    "{a:?} against {b:?}"
                );
            }
        }
    }

    #[test]
    fn constant_planes_develop_to_themselves_and_coverage_is_the_hit_share() {
        let (w, h) = (6u32, 5u32);
        for sampling in [FilterSampling::Splat, FilterSampling::Importance] {
            let r = Reconstruction::new(&TENT, sampling);
            let mut film = AovFilm::try_new(w, h).unwrap();
            let mut tile = AovTile::new(0, 0, w, h, (w, h), r.reach());
            let hit = FirstHit {
                alpha: 1.0,
                albedo: Vec3::new(0.2, 0.4, 0.6),
                normal: Vec3::Y,
                depth: 3.0,
                position: Vec3::new(1.0, 2.0, 3.0),
            };
            // Every pixel: 4 samples, the right half of them misses.
            let pixels: Vec<u32> = (0..w * h).flat_map(|p| [p; 4]).collect();
            let pos: Vec<Vec2> = pixels
                .iter()
                .enumerate()
                .map(|(k, &p)| {
                    let s = (k % 4) as f32;
                    Vec2::new((p % w) as f32 + 0.2 + 0.2 * s, (p / w) as f32 + 0.5)
                })
                .collect();
            let hits: Vec<FirstHit> = pixels
                .iter()
                .map(|&p| if p % w < 3 { hit } else { FirstHit::default() })
                .collect();
            tile.add_samples(
                &r,
                pixels.iter().copied(),
                &pos,
                &vec![1.0; pos.len()],
                &hits,
            );
            film.merge(&tile);
            let image = film.develop();
            assert!(image.spp.iter().all(|&n| n == 4));
            for y in 0..h {
                // Columns 0 and 1 see only hits even through the tent;
                // 4 and 5 only misses.
                for x in [0, 1] {
                    let i = (y * w + x) as usize;
                    assert!((image.alpha[i] - 1.0).abs() < 1e-6, "{sampling:?}");
                    assert!((image.albedo[i] - hit.albedo).abs().max_element() < 1e-6);
                    assert!((image.normal[i] - Vec3::Y).abs().max_element() < 1e-6);
                    assert!((image.depth[i] - 3.0).abs() < 1e-5);
                    assert!((image.position[i] - hit.position).abs().max_element() < 1e-5);
                }
                for x in [4, 5] {
                    let i = (y * w + x) as usize;
                    assert_eq!(image.alpha[i], 0.0);
                    assert_eq!(image.depth[i], 0.0);
                }
            }
        }
    }
}
