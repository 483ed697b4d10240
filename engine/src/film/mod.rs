//! The film: filtered accumulation of samples, and image output.
//!
//! Each render task splats its samples into a [`TileFilm`] that covers its
//! pixels plus the filter's border; the splats of one block of sample
//! indices are added in `f32` in a fixed order and then converted into
//! exact fixed-point sums ([`exact`]), which tiles add into the [`Film`].
//! Integer addition is associative, so a render is bit-identical whatever
//! the thread count, and whatever block-aligned sample ranges (passes,
//! partitions, resumed renders) its samples were rendered in.
//! A pixel's value is Σ w·L / Σ w over the samples whose filter footprint
//! covers it (Mitsuba 3 and pbrt semantics). [`Reconstruction`] chooses
//! how samples get their weights: splatted into every pixel in the
//! filter's reach ([`FilterTable`]), or placed by filter importance
//! sampling and added to one pixel ([`FilterSampler`], pbrt-v4).

pub mod alpha;
pub mod aov;
pub mod band;
pub mod denoise;
pub mod encode;
pub mod encoding;
pub mod exact;
pub mod layers;
pub mod memory;
pub mod output;
pub mod rgbe;
pub mod sheet;
mod tile;
pub mod tonemap;

use crate::accel::InstructionSet;
use crate::settings::FilterSampling;
use exact::Sums;
use glam::{Vec2, Vec4};
use radiant_core::{Filter, FilterSampler, Rgb};
use tile::TileBounds;

/// Entries per axis of the tabulated filter quadrant.
const TABLE_RES: usize = 64;

/// Pixels per axis a separable splat handles with its fast path (a filter
/// radius up to 7.5 pixels); wider filters take the general path.
const MAX_TAPS: usize = 16;

/// A separable filter's factor g: [`TABLE_RES`] cells over [0, r], then 0.
type Factor = [f32; TABLE_RES + 1];

/// A filter tabulated over one quadrant [0, r]² (filters are symmetric).
#[derive(Debug, Clone, PartialEq)]
pub struct FilterTable {
    radius: f32,
    scale: f32,
    values: Vec<f32>,
    /// For a separable filter f(x, y) = g(x)·g(y): g tabulated over [0, r]
    /// and a zero beyond (the factor outside the support), so a splat
    /// computes one row and one column of weights.
    separable: Option<Box<Factor>>,
}

impl FilterTable {
    /// Tabulates `filter` at the centres of a 64×64 grid over [0, r]².
    pub fn new(filter: &dyn Filter) -> Self {
        let radius = filter.radius();
        let step = radius / TABLE_RES as f32;
        let mut values = Vec::with_capacity(TABLE_RES * TABLE_RES);
        for y in 0..TABLE_RES {
            for x in 0..TABLE_RES {
                values.push(filter.eval((x as f32 + 0.5) * step, (y as f32 + 0.5) * step));
            }
        }
        let separable = separable_factor(&values);
        Self {
            radius,
            scale: TABLE_RES as f32 / radius,
            values,
            separable,
        }
    }

    /// The filter's radius in pixels.
    pub fn radius(&self) -> f32 {
        self.radius
    }

    /// The filter's weight at offset (`dx`, `dy`).
    #[inline]
    pub fn weight(&self, dx: f32, dy: f32) -> f32 {
        match (self.index(dx), self.index(dy)) {
            (Some(ix), Some(iy)) => self.values[iy * TABLE_RES + ix],
            _ => 0.0,
        }
    }

    /// The table cell of offset `d` along one axis, if inside the support.
    #[inline]
    fn index(&self, d: f32) -> Option<usize> {
        let x = d.abs() * self.scale;
        // SAFETY: 0 ≤ x < TABLE_RES (so not NaN) where it is converted, so
        // the truncation is in range (and needs none of the checks of a
        // saturating `as`).
        (x < TABLE_RES as f32).then(|| unsafe { x.to_int_unchecked::<u32>() } as usize)
    }

    /// The separable factor g at offset `d` (0 outside the support);
    /// `factor` is `separable`.
    #[inline(always)]
    fn factor(&self, factor: &Factor, d: f32) -> f32 {
        // The cell, or the zero past the end for |d| beyond the radius (and
        // NaN, which `min` turns into TABLE_RES): the same as
        // `index(d).map_or(0.0, …)` without a branch.
        let x = (d.abs() * self.scale).min(TABLE_RES as f32);
        // SAFETY: 0 ≤ x ≤ TABLE_RES (not NaN), so the truncation is in range.
        factor[unsafe { x.to_int_unchecked::<u32>() } as usize]
    }

    /// [`Self::factor`] of the four consecutive pixels from `first` along
    /// one axis, at offsets `pixel + 0.5 − pos`: lane k is bit for bit
    /// `factor(factor, (first + k) as f32 + 0.5 − pos)` (the pixel's
    /// coordinate and its half are exact in `f32` either way), the cells
    /// found by one vector truncation.
    #[inline(always)]
    fn factor4(&self, factor: &Factor, first: i32, pos: f32) -> Vec4 {
        let d = (Vec4::splat(first as f32) + Vec4::new(0.5, 1.5, 2.5, 3.5)) - Vec4::splat(pos);
        // As in `factor`: NaN and |d| past the radius become TABLE_RES
        // (`min` returns its argument where the lane is NaN).
        let x = (d.abs() * self.scale).min(Vec4::splat(TABLE_RES as f32));
        let cells = truncate4(x);
        // SAFETY: 0 ≤ x ≤ TABLE_RES in every lane, so each cell is at most
        // TABLE_RES, the factor's last index.
        cells
            .map(|c| unsafe { *factor.get_unchecked(c as usize) })
            .into()
    }

    /// The fast path of a splat at `pos` whose footprint's columns start
    /// at `px0` and number `taps`: for a separable filter and at most
    /// [`MAX_TAPS`] columns, fills `wx` with g of each column and returns g
    /// (a row's weights are then g(row) times them); `None` where the
    /// general path applies. [`TileFilm`] and [`aov::AovTile`] share it.
    #[inline(always)]
    fn separable_row(
        &self,
        pos_x: f32,
        px0: i32,
        taps: usize,
        wx: &mut [f32; MAX_TAPS],
    ) -> Option<&Factor> {
        let g = self.separable.as_deref().filter(|_| taps <= MAX_TAPS)?;
        for (x, w) in (px0..).zip(&mut wx[..taps]) {
            *w = self.factor(g, x as f32 + 0.5 - pos_x);
        }
        Some(g)
    }
}

/// Each lane of `x` (0 ≤ x ≤ [`TABLE_RES`]) truncated to an integer, as
/// `to_int_unchecked` does lane by lane.
#[inline(always)]
fn truncate4(x: Vec4) -> [u32; 4] {
    #[cfg(target_arch = "x86_64")]
    {
        use std::arch::x86_64::{__m128i, _mm_cvttps_epi32};
        // SAFETY: SSE2 is part of x86_64; the lanes are in range, so the
        // conversion is exact truncation (no 0x80000000 sentinel).
        let cells: __m128i = unsafe { _mm_cvttps_epi32(x.into()) };
        // SAFETY: `__m128i` and `[u32; 4]` have the same size, and every
        // bit pattern is a valid `u32`.
        unsafe { std::mem::transmute::<__m128i, [u32; 4]>(cells) }
    }
    #[cfg(not(target_arch = "x86_64"))]
    {
        // SAFETY: in range and not NaN, so the truncation is in range.
        x.to_array().map(|x| unsafe { x.to_int_unchecked::<u32>() })
    }
}

/// If the table is the outer product g(x)·g(y) of one function with itself
/// (box, tent, gaussian and the usual windowed filters are), returns g.
fn separable_factor(values: &[f32]) -> Option<Box<Factor>> {
    let centre = values[0];
    if centre <= 0.0 {
        return None;
    }
    let norm = centre.sqrt();
    let g: Box<Factor> = Box::new(std::array::from_fn(|i| {
        if i < TABLE_RES { values[i] / norm } else { 0.0 }
    }));
    let max = values.iter().fold(0.0f32, |m, v| m.max(v.abs()));
    let tolerance = 1e-5 * max;
    let product_matches = (0..TABLE_RES).all(|iy| {
        (0..TABLE_RES).all(|ix| (values[iy * TABLE_RES + ix] - g[ix] * g[iy]).abs() <= tolerance)
    });
    product_matches.then_some(g)
}

/// A linear-RGB image.
#[derive(Debug, Clone, PartialEq)]
pub struct Image {
    /// Width in pixels.
    pub width: u32,
    /// Height in pixels.
    pub height: u32,
    /// Row-major pixels, top row first.
    pub pixels: Vec<Rgb>,
}

impl Image {
    /// Mean over all pixels and channels.
    pub fn mean(&self) -> f64 {
        self.pixels
            .iter()
            .map(|p| (p.x + p.y + p.z) as f64)
            .sum::<f64>()
            / (3 * self.pixels.len().max(1)) as f64
    }
}

/// How samples reach the pixels through the pixel filter, prepared once per
/// render.
#[derive(Debug, Clone, PartialEq)]
pub enum Reconstruction {
    /// Samples uniform in their pixel, splatted with the tabulated filter.
    Splat(FilterTable),
    /// Sample offsets drawn in proportion to |f|, each added to its own
    /// pixel with weight f/pdf.
    Importance(FilterSampler),
}

impl Reconstruction {
    /// Prepares `filter` for `sampling`.
    pub fn new(filter: &dyn Filter, sampling: FilterSampling) -> Self {
        match sampling {
            FilterSampling::Splat => Self::Splat(FilterTable::new(filter)),
            FilterSampling::Importance => Self::Importance(FilterSampler::new(
                filter,
                FilterSampler::DEFAULT_RESOLUTION,
            )),
        }
    }

    /// How far, in pixels, a sample reaches beyond its own pixel.
    pub fn reach(&self) -> f32 {
        match self {
            Self::Splat(table) => table.radius(),
            Self::Importance(_) => 0.0,
        }
    }
}

/// The weighted sums of one render task's pixels, with a border as wide as
/// the filter.
#[derive(Debug, Clone)]
pub struct TileFilm {
    bounds: TileBounds,
    /// (Σ w·r, Σ w·g, Σ w·b, Σ w) per pixel of the splats since the last
    /// [`TileFilm::end_block`], in `f32`.
    current: Vec<Vec4>,
    /// The exact sums of the blocks ended so far.
    sums: Vec<Sums>,
    /// Samples whose value was NaN or infinite (recorded as zero).
    pub invalid_samples: u64,
    /// Whether [`TileFilm::end_block`] converts with AVX-512
    /// ([`Sums::add_f32_avx512`]): where the CPU has F, DQ and VL and
    /// `--max-isa` allows AVX-512.
    wide_sums: bool,
    /// The weight of the samples added next, value and filter weight both
    /// (1 unless set): under adaptive sampling 1 / the samples their pixel
    /// takes, so that every pixel weighs as much in a splat neighbourhood
    /// however many samples it took.
    scale: f32,
}

/// Whether tiles end their blocks with AVX-512 ([`Sums::add_f32_avx512`]):
/// the CPU has F, DQ and VL, and the instruction sets in use
/// ([`InstructionSet::detected`], which `--max-isa` limits) reach AVX-512.
fn wide_sums() -> bool {
    #[cfg(target_arch = "x86_64")]
    {
        InstructionSet::detected() == InstructionSet::Avx512
            && std::arch::is_x86_feature_detected!("avx512dq")
    }
    #[cfg(not(target_arch = "x86_64"))]
    {
        false
    }
}

/// [`TileFilm::end_block`]'s loop with [`Sums::add_f32_avx512`].
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx512f,avx512dq,avx512vl")]
fn end_block_avx512(sums: &mut [Sums], current: &mut [Vec4]) {
    for (sum, current) in sums.iter_mut().zip(current) {
        if *current != Vec4::ZERO {
            sum.add_f32_avx512(*current);
            *current = Vec4::ZERO;
        }
    }
}

impl TileFilm {
    /// A tile for the pixels [x0, x1) × [y0, y1) of a `size` image, grown by
    /// the filter radius and clipped to the image.
    pub fn new(x0: u32, y0: u32, x1: u32, y1: u32, size: (u32, u32), radius: f32) -> Self {
        let bounds = TileBounds::new(x0, y0, x1, y1, size, radius);
        Self {
            bounds,
            current: vec![Vec4::ZERO; bounds.len()],
            sums: vec![Sums::ZERO; bounds.len()],
            invalid_samples: 0,
            wide_sums: wide_sums(),
            scale: 1.0,
        }
    }

    /// Weighs the samples added from now on by `scale` (see the field).
    pub fn set_scale(&mut self, scale: f32) {
        self.scale = scale;
    }

    /// Adds row `y` of this tile (its own row index) to `row`, the film's
    /// row it covers.
    #[inline]
    fn add_row(&self, y: usize, row: &mut [Sums]) {
        let (width, x0) = (self.bounds.width as usize, self.bounds.x0 as usize);
        let src = y * width;
        let sums = &self.sums[src..src + width];
        let current = &self.current[src..src + width];
        for ((sum, exact), partial) in row[x0..x0 + width].iter_mut().zip(sums).zip(current) {
            sum.add(exact);
            // Zero where every block was ended (`end_block`): nothing to
            // convert.
            if *partial != Vec4::ZERO {
                sum.add_f32(*partial);
            }
        }
    }

    /// Ends a block of sample indices ([`exact::BLOCK`]): the `f32` sums
    /// of its splats are converted into the exact sums. A render splats
    /// the block's sample indices in order, each over all the tile's
    /// pixels in order, between calls, so the exact sums do not depend on
    /// how the samples were cut into batches.
    pub fn end_block(&mut self) {
        #[cfg(target_arch = "x86_64")]
        if self.wide_sums {
            // SAFETY: `wide_sums` only where the CPU has AVX-512 F, DQ and
            // VL (`wide_sums()`).
            unsafe { end_block_avx512(&mut self.sums, &mut self.current) };
            return;
        }
        for (sum, current) in self.sums.iter_mut().zip(&mut self.current) {
            if *current != Vec4::ZERO {
                sum.add_f32(*current);
                *current = Vec4::ZERO;
            }
        }
    }

    /// Adds `value` sampled at raster position `pos` to every pixel within
    /// the filter's radius.
    #[inline]
    pub fn splat(&mut self, pos: Vec2, value: Rgb, table: &FilterTable) {
        let value = self.checked(value);
        let (px0, px1, py0, py1) = self.bounds.footprint(pos, table.radius);
        let v = value.extend(1.0) * self.scale;
        let taps = (px1 - px0 + 1).max(0) as usize;
        if let Some(g) = table.separable.as_deref()
            && taps == 4
            && py1 - py0 == 3
        {
            self.splat_4x4((px0, py0), pos, v, g, table);
            return;
        }
        // One row of weights, reused on every row of pixels.
        let mut wx = [0.0f32; MAX_TAPS];
        if let Some(g) = table.separable_row(pos.x, px0, taps, &mut wx) {
            let start = self.bounds.index(px0, py0);
            let rows = RowSplat {
                start,
                py0,
                py1,
                pos_y: pos.y,
                v,
            };
            // A Gaussian of radius 2 (Mitsuba's default filter) covers 4
            // or 5 columns: unrolled rows for those.
            match taps {
                4 => self.splat_rows::<4>(&rows, &wx, g, table),
                5 => self.splat_rows::<5>(&rows, &wx, g, table),
                _ => self.splat_rows_any(&rows, taps, &wx, g, table),
            }
            return;
        }
        let b = self.bounds;
        for y in py0..=py1 {
            let dy = y as f32 + 0.5 - pos.y;
            let row = &mut self.current[b.index(b.x0, y)..];
            for x in px0..=px1 {
                let w = table.weight(x as f32 + 0.5 - pos.x, dy);
                if w != 0.0 {
                    row[(x - b.x0) as usize] += v * w;
                }
            }
        }
    }

    /// [`Self::splat`]'s most common footprint, four columns by four rows
    /// from pixel (`x0`, `y0`) (a Gaussian of radius 2 away from the
    /// image's edges), its column and row factors computed four at a time
    /// ([`FilterTable::factor4`]): the weights and sums of
    /// [`Self::splat_rows`], bit for bit, in fewer instructions.
    #[inline(always)]
    fn splat_4x4(
        &mut self,
        (x0, y0): (i32, i32),
        pos: Vec2,
        v: Vec4,
        g: &Factor,
        table: &FilterTable,
    ) {
        let w = table.factor4(g, x0, pos.x).to_array();
        let gy = table.factor4(g, y0, pos.y).to_array();
        let width = self.bounds.width as usize;
        let start = self.bounds.index(x0, y0);
        // The bounds checked once for the whole footprint, not per row.
        let footprint = &mut self.current[start..start + 3 * width + 4];
        for (r, g) in gy.into_iter().enumerate() {
            let vy = v * g;
            // SAFETY: r·width + 4 ≤ 3·width + 4, the footprint's length,
            // for the rows r ≤ 3.
            let row = unsafe { footprint.get_unchecked_mut(r * width..r * width + 4) };
            for (sum, w) in row.iter_mut().zip(w) {
                *sum += vy * w;
            }
        }
    }

    /// The rows of a separable splat with `N` columns of weights `wx`:
    /// each pixel adds (v·g(row))·w, as [`Self::splat_rows_any`] does.
    #[inline(always)]
    fn splat_rows<const N: usize>(
        &mut self,
        rows: &RowSplat,
        wx: &[f32; MAX_TAPS],
        g: &Factor,
        table: &FilterTable,
    ) {
        // One load per weight: `separable_row` has just stored them one
        // at a time, and a 16-byte load of four of them cannot take them
        // from those stores (it waits until they reach the cache, about 15
        // cycles per splat). The reads are volatile so that the compiler
        // does not merge them into that load.
        // SAFETY: reads of initialised elements of `wx`.
        let w: [f32; N] = std::array::from_fn(|i| unsafe { std::ptr::read_volatile(&wx[i]) });
        let width = self.bounds.width as usize;
        let mut start = rows.start;
        for y in rows.py0..=rows.py1 {
            let vy = rows.v * table.factor(g, y as f32 + 0.5 - rows.pos_y);
            let row: &mut [Vec4; N] = (&mut self.current[start..start + N])
                .try_into()
                .expect("a slice of N pixels");
            for (sum, w) in row.iter_mut().zip(w) {
                *sum += vy * w;
            }
            start += width;
        }
    }

    /// [`Self::splat_rows`] for any number of columns up to [`MAX_TAPS`].
    #[inline(always)]
    fn splat_rows_any(
        &mut self,
        rows: &RowSplat,
        taps: usize,
        wx: &[f32; MAX_TAPS],
        g: &Factor,
        table: &FilterTable,
    ) {
        let width = self.bounds.width as usize;
        let mut start = rows.start;
        for y in rows.py0..=rows.py1 {
            let vy = rows.v * table.factor(g, y as f32 + 0.5 - rows.pos_y);
            for (sum, &w) in self.current[start..start + taps]
                .iter_mut()
                .zip(&wx[..taps])
            {
                *sum += vy * w;
            }
            start += width;
        }
    }

    /// `value`, or black (counted in `invalid_samples`) if it is NaN or
    /// infinite.
    #[inline]
    fn checked(&mut self, value: Rgb) -> Rgb {
        if value.is_finite() {
            value
        } else {
            self.invalid_samples += 1;
            Rgb::ZERO
        }
    }

    /// Adds `value` with filter weight `weight` to pixel (`x`, `y`) alone
    /// (filter importance sampling).
    #[inline]
    pub fn add(&mut self, x: u32, y: u32, value: Rgb, weight: f32) {
        let value = self.checked(value);
        let i = self.bounds.index(x as i32, y as i32);
        let weight = weight * self.scale;
        self.current[i] += (value * weight).extend(weight);
    }
}

/// The rows of one separable splat: where its first row starts in the
/// tile, its first and last row, the sample's y and its weighted value.
struct RowSplat {
    start: usize,
    py0: i32,
    py1: i32,
    pos_y: f32,
    v: Vec4,
}

/// The weighted sums of a frame's rows: of all of them, or of a band of
/// rows that slides down the frame as [`Film::advance`] hands finished
/// rows on (see [`band`]).
#[derive(Debug, Clone)]
pub struct Film {
    width: u32,
    height: u32,
    /// The first frame row held.
    top: u32,
    /// Rows held at most (all of them for a whole film).
    band: u32,
    /// Rows `top..top + sums.len() / width`, row-major.
    sums: Vec<Sums>,
    /// Samples whose value was NaN or infinite (recorded as zero).
    pub invalid_samples: u64,
    /// Under adaptive sampling, the image samples each pixel takes in the
    /// whole render (row-major), decided by the first pass that renders
    /// into this film: what a render's passes share beyond the sums (see
    /// `integrators/adaptive.rs`). Not saved with the sums: the decisions
    /// depend on the scene and its seed alone, so a resumed render makes
    /// them again, the same.
    pub adaptive_counts: Option<Vec<u32>>,
}

impl Film {
    /// An empty film.
    ///
    /// # Panics
    ///
    /// Where its memory cannot be allocated; [`Film::try_new`] reports
    /// that instead.
    pub fn new(width: u32, height: u32) -> Self {
        Self::try_new(width, height).unwrap_or_else(|e| panic!("{e}"))
    }

    /// An empty film of the whole frame, or what it needed where its memory
    /// (with that of the image it develops into) cannot be reserved.
    pub fn try_new(width: u32, height: u32) -> Result<Self, memory::FrameTooLarge> {
        memory::FrameTooLarge::new(width, height).check()?;
        Self::try_band(width, height, height)
            .ok_or_else(|| memory::FrameTooLarge::new(width, height))
    }

    /// An empty film that holds `rows` rows at a time (at least one, at
    /// most the frame's), starting with the frame's first, or `None` where
    /// their memory cannot be reserved.
    pub fn try_band(width: u32, height: u32, rows: u32) -> Option<Self> {
        let band = rows.clamp(1, height.max(1));
        let sums = memory::try_filled(band as usize * width as usize, Sums::ZERO)?;
        Some(Self {
            width,
            height,
            top: 0,
            band,
            sums,
            invalid_samples: 0,
            adaptive_counts: None,
        })
    }

    /// Rows held: `top..top + rows`.
    fn rows(&self) -> u32 {
        (self.sums.len() / self.width.max(1) as usize) as u32
    }

    /// Adds layers of per-pixel `f32` sums (Σ w·L in RGB, Σ w in alpha;
    /// each layer `width × height` pixels, row-major) and `invalid`
    /// samples — what the GPU backend renders. Each layer's sums are
    /// converted exactly, so the result is exact given the layers (but the
    /// layers' own `f32` sums depend on how the GPU split the samples).
    ///
    /// # Panics
    ///
    /// If `layers` is not a whole number of layers of this film's size, or
    /// the film holds a band rather than the whole frame.
    pub fn add_layers(&mut self, layers: &[f32], invalid: u64) {
        assert!(self.top == 0 && self.rows() == self.height, "a whole film");
        let layer = self.sums.len() * 4;
        assert_eq!(layers.len() % layer.max(1), 0, "not whole layers");
        for l in layers.chunks_exact(layer.max(1)) {
            for (sum, p) in self.sums.iter_mut().zip(l.chunks_exact(4)) {
                sum.add_f32(Vec4::new(p[0], p[1], p[2], p[3]));
            }
        }
        self.invalid_samples += invalid;
    }

    /// Adds the exact sums of a whole film (`width × height` pixels,
    /// row-major; a partial or resumable file's) and `invalid` samples.
    ///
    /// # Panics
    ///
    /// If `sums` is not one film of this size, or the film holds a band
    /// rather than the whole frame.
    pub fn add_sums(&mut self, sums: &[Sums], invalid: u64) {
        assert!(self.top == 0 && self.rows() == self.height, "a whole film");
        assert_eq!(sums.len(), self.sums.len(), "not one film");
        for (sum, s) in self.sums.iter_mut().zip(sums) {
            sum.add(s);
        }
        self.invalid_samples += invalid;
    }

    /// The exact sums of a whole film, row-major: what a sample partition
    /// or a resumable render stores for `radiant merge` or `--resume` to
    /// add.
    ///
    /// # Panics
    ///
    /// If the film holds a band rather than the whole frame.
    pub fn sums(&self) -> &[Sums] {
        assert!(self.top == 0 && self.rows() == self.height, "a whole film");
        &self.sums
    }

    /// Film width in pixels.
    pub fn width(&self) -> u32 {
        self.width
    }

    /// Film height in pixels.
    pub fn height(&self) -> u32 {
        self.height
    }

    /// Adds a tile's sums (the splats of a block it has not ended, at the
    /// end of its samples, count as one more block).
    ///
    /// # Panics
    ///
    /// If the tile reaches rows the film does not hold.
    pub fn merge(&mut self, tile: &TileFilm) {
        assert!(
            tile.bounds.y0 as u32 >= self.top
                && (tile.bounds.y0 + tile.bounds.height) as u32 <= self.top + self.rows(),
            "tile rows {}..{} outside the film's rows {}..{}",
            tile.bounds.y0,
            tile.bounds.y0 + tile.bounds.height,
            self.top,
            self.top + self.rows()
        );
        for y in 0..tile.bounds.height {
            let dst = ((tile.bounds.y0 as u32 + y as u32 - self.top) * self.width) as usize;
            tile.add_row(y as usize, &mut self.sums[dst..dst + self.width as usize]);
        }
        self.invalid_samples += tile.invalid_samples;
    }

    /// Adds the sums of `tiles`, as [`Film::merge`] of each would, in
    /// parallel over the film's rows: each row adds the rows of the tiles
    /// that reach it. The sums are exact, so the film is the same bit for
    /// bit whatever order the additions run in; a frame's tiles are many,
    /// and converting their `f32` block sums is what a serial merge would
    /// leave the other threads waiting on.
    ///
    /// # Panics
    ///
    /// If a tile reaches rows the film does not hold.
    pub fn merge_all(&mut self, tiles: &[TileFilm]) {
        use rayon::prelude::*;
        let (top, held) = (self.top as i32, self.rows() as i32);
        for tile in tiles {
            assert!(
                tile.bounds.y0 >= top && tile.bounds.y0 + tile.bounds.height <= top + held,
                "tile rows {}..{} outside the film's rows {top}..{}",
                tile.bounds.y0,
                tile.bounds.y0 + tile.bounds.height,
                top + held
            );
        }
        self.sums
            .par_chunks_mut(self.width.max(1) as usize)
            .enumerate()
            .for_each(|(r, row)| {
                let y = top + r as i32;
                for tile in tiles {
                    if (tile.bounds.y0..tile.bounds.y0 + tile.bounds.height).contains(&y) {
                        tile.add_row((y - tile.bounds.y0) as usize, row);
                    }
                }
            });
        self.invalid_samples += tiles.iter().map(|t| t.invalid_samples).sum::<u64>();
    }

    /// Develops the rows from the first held up to `until` (exclusive)
    /// onto `finished`, drops them, and takes up as many new empty rows
    /// below (as far as the frame goes) within the band's memory, which
    /// is not reallocated. Fails, leaving the film as it was, where
    /// `finished` cannot grow.
    ///
    /// # Panics
    ///
    /// If `until` is above the first row held or below the last.
    pub fn advance(
        &mut self,
        until: u32,
        finished: &mut Vec<Rgb>,
    ) -> Result<(), std::collections::TryReserveError> {
        assert!(
            (self.top..=self.top + self.rows()).contains(&until),
            "rows up to {until} are not held"
        );
        let done = (until - self.top) as usize * self.width as usize;
        finished.try_reserve(done)?;
        finished.extend(self.sums[..done].iter().map(Sums::develop));
        self.sums.drain(..done);
        self.top = until;
        let bottom = (self.top + self.band).min(self.height);
        self.sums.resize(
            (bottom - self.top) as usize * self.width as usize,
            Sums::ZERO,
        );
        Ok(())
    }

    /// The reconstructed image: Σ w·L / Σ w per pixel.
    ///
    /// # Panics
    ///
    /// Where its memory cannot be allocated; [`Film::try_develop`] reports
    /// that instead.
    pub fn develop(&self) -> Image {
        self.try_develop().unwrap_or_else(|e| panic!("{e}"))
    }

    /// The reconstructed image, or what the frame needed where its memory
    /// cannot be reserved.
    ///
    /// # Panics
    ///
    /// If the film holds a band rather than the whole frame.
    pub fn try_develop(&self) -> Result<Image, memory::FrameTooLarge> {
        assert!(self.top == 0 && self.rows() == self.height, "a whole film");
        let mut pixels = Vec::new();
        if pixels.try_reserve_exact(self.sums.len()).is_err() {
            return Err(memory::FrameTooLarge::new(self.width, self.height));
        }
        pixels.extend(self.sums.iter().map(Sums::develop));
        Ok(Image {
            width: self.width,
            height: self.height,
            pixels,
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    struct Tent;
    impl Filter for Tent {
        fn radius(&self) -> f32 {
            1.5
        }
        fn eval(&self, x: f32, y: f32) -> f32 {
            (1.5 - x.abs()).max(0.0) * (1.5 - y.abs()).max(0.0)
        }
    }

    #[test]
    fn constant_signal_develops_to_itself_with_tiles() {
        let table = FilterTable::new(&Tent);
        let (w, h) = (9u32, 7u32);
        let mut film = Film::new(w, h);
        for (x0, y0, x1, y1) in [(0, 0, 5, 7), (5, 0, 9, 4), (5, 4, 9, 7)] {
            let mut tile = TileFilm::new(x0, y0, x1, y1, (w, h), table.radius());
            for y in y0..y1 {
                for x in x0..x1 {
                    for s in 0..4 {
                        let pos = Vec2::new(
                            x as f32 + 0.2 + 0.2 * s as f32,
                            y as f32 + 0.9 - 0.2 * s as f32,
                        );
                        tile.splat(pos, Rgb::new(0.25, 0.5, 1.0), &table);
                    }
                }
            }
            film.merge(&tile);
        }
        let image = film.develop();
        for p in &image.pixels {
            assert!((*p - Rgb::new(0.25, 0.5, 1.0)).abs().max_element() < 1e-5);
        }
    }

    #[test]
    fn merging_all_tiles_at_once_equals_merging_them_one_by_one() {
        let table = FilterTable::new(&Tent);
        let (w, h) = (23u32, 19u32);
        // Fractions of a multiplicative hash of a counter: scattered enough.
        let mut i = 0u32;
        let mut next = move || {
            i += 1;
            (i.wrapping_mul(0x9e37_79b9) >> 8) as f32 / (1u32 << 24) as f32
        };
        // Overlapping tiles (the tent reaches 1.5 pixels), some of them
        // twice, with a block ended half-way so both sums and the f32
        // block sums are merged.
        let mut tiles = Vec::new();
        for (x0, y0) in [
            (0, 0),
            (8, 0),
            (16, 0),
            (0, 8),
            (8, 8),
            (16, 8),
            (8, 16),
            (8, 8),
        ] {
            let (x1, y1) = ((x0 + 8).min(w), (y0 + 8).min(h));
            let mut tile = TileFilm::new(x0, y0, x1, y1, (w, h), table.radius());
            for k in 0..40 {
                let pos = Vec2::new(
                    x0 as f32 + next() * (x1 - x0) as f32,
                    y0 as f32 + next() * (y1 - y0) as f32,
                );
                tile.splat(pos, Rgb::new(next(), 10.0 * next(), 1e-3 * next()), &table);
                if k == 20 {
                    tile.end_block();
                }
            }
            tiles.push(tile);
        }
        let mut one_by_one = Film::new(w, h);
        for tile in &tiles {
            one_by_one.merge(tile);
        }
        let mut all = Film::new(w, h);
        all.merge_all(&tiles);
        assert!(all.sums == one_by_one.sums);
        assert_eq!(all.develop(), one_by_one.develop());
        assert!(all.develop().mean() > 0.0);
    }

    #[test]
    fn importance_sampled_samples_stay_in_their_pixel() {
        let r = Reconstruction::new(&Tent, FilterSampling::Importance);
        assert_eq!(r.reach(), 0.0);
        assert_eq!(
            Reconstruction::new(&Tent, FilterSampling::Splat).reach(),
            1.5
        );
        let Reconstruction::Importance(sampler) = &r else {
            panic!("importance sampling expected");
        };
        let (w, h) = (4u32, 3u32);
        let mut film = Film::new(w, h);
        let mut tile = TileFilm::new(1, 1, 3, 3, (w, h), r.reach());
        for (k, (x, y)) in [(1, 1), (2, 1), (1, 2), (2, 2)].into_iter().enumerate() {
            for s in 0..8 {
                let u = Vec2::new((s as f32 + 0.5) / 8.0, ((s * 3 + k) % 8) as f32 / 8.0);
                let (_, weight) = sampler.sample(u);
                // The tent is positive: every weight is its integral, 2.25².
                assert!((weight - 5.0625).abs() < 0.01, "{weight}");
                tile.add(x, y, Rgb::splat(x as f32 + 10.0 * y as f32), weight);
            }
        }
        film.merge(&tile);
        let image = film.develop();
        for y in 0..h {
            for x in 0..w {
                let expected = if (1..3).contains(&x) && (1..3).contains(&y) {
                    x as f32 + 10.0 * y as f32
                } else {
                    0.0
                };
                let p = image.pixels[(y * w + x) as usize];
                assert!((p.x - expected).abs() < 1e-5, "({x}, {y}): {p}");
            }
        }
    }

    /// A radially symmetric filter, which is not separable.
    struct Disk;
    impl Filter for Disk {
        fn radius(&self) -> f32 {
            1.5
        }
        fn eval(&self, x: f32, y: f32) -> f32 {
            (1.5 - (x * x + y * y).sqrt()).max(0.0)
        }
    }

    #[test]
    fn separable_filters_are_detected() {
        assert!(FilterTable::new(&Tent).separable.is_some());
        assert!(FilterTable::new(&Disk).separable.is_none());
    }

    #[test]
    fn separable_splats_match_the_two_dimensional_table() {
        let table = FilterTable::new(&Tent);
        let general = FilterTable {
            separable: None,
            ..table.clone()
        };
        let mut fast = TileFilm::new(0, 0, 8, 8, (8, 8), table.radius());
        let mut slow = fast.clone();
        for (i, pos) in [(0.1, 0.2), (3.5, 3.5), (7.9, 0.4), (4.25, 6.75)]
            .into_iter()
            .enumerate()
        {
            let pos = Vec2::new(pos.0, pos.1);
            let value = Rgb::new(1.0, 2.0, 0.5) * (i + 1) as f32;
            fast.splat(pos, value, &table);
            slow.splat(pos, value, &general);
        }
        for (a, b) in fast.current.iter().zip(&slow.current) {
            assert!((*a - *b).abs().max_element() <= 1e-5 * b.abs().max_element().max(1.0));
        }
    }

    #[test]
    fn invalid_samples_are_counted_not_splatted() {
        let table = FilterTable::new(&Tent);
        let mut tile = TileFilm::new(0, 0, 2, 2, (2, 2), table.radius());
        tile.splat(Vec2::splat(0.5), Rgb::new(f32::NAN, 0.0, 0.0), &table);
        tile.splat(Vec2::splat(0.5), Rgb::splat(f32::INFINITY), &table);
        assert_eq!(tile.invalid_samples, 2);
        let mut film = Film::new(2, 2);
        film.merge(&tile);
        assert!(film.develop().pixels.iter().all(|p| p.is_finite()));
        assert_eq!(film.invalid_samples, 2);
    }
}
