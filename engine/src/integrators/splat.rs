//! The whole-image splat film: contributions that land anywhere in the
//! image, from any thread — light paths that reach the camera (`bdpt`'s
//! t = 1 strategies) and Markov chains' deposits.
//!
//! A splat at raster position `pos` adds `value · f(x − pos) / ∫f` to
//! every pixel x within the filter's radius (unnormalized, unlike the
//! tile film's Σ w·L / Σ w: a splat is an estimate of the image's
//! integral, pbrt-v4's `AddSplat`); the driver scales the sums when it
//! adds them to the image. Every tap is converted exactly to fixed point
//! ([`Sums`]) and added under its row's lock, so the film does not depend
//! on the order of the splats or the number of threads.

use crate::film::exact::{FRACTION_BITS, Sums};
use crate::film::memory::FrameTooLarge;
use crate::film::{FilterTable, Image};
use glam::{Vec2, Vec4};
use radiant_core::{Filter, Rgb};
use std::sync::Mutex;

/// Sub-samples per pixel and axis of the numerical integral of the filter.
const INTEGRAL_STEPS: u32 = 32;

/// A frame's splats, row by row behind locks.
pub struct SplatFilm {
    width: u32,
    height: u32,
    table: FilterTable,
    /// 1 / ∫f, so that a splat adds `value` in all.
    norm: f32,
    rows: Vec<Mutex<Vec<Sums>>>,
    /// Per column and per row, ∫g / ∫ g over the image from the pixel's
    /// centre (g the filter's profile along the axis): 1 inside, more
    /// within the filter's radius of the border, where a splat's taps
    /// that fall outside the image are lost (see [`SplatFilm::add_to`]).
    edge: [Vec<f32>; 2],
    /// NaN or infinite splats, recorded as nothing.
    invalid: Mutex<u64>,
}

impl SplatFilm {
    /// An empty splat film of `width × height` pixels with `filter`, or
    /// what it needed where its memory cannot be reserved.
    pub fn new(width: u32, height: u32, filter: &dyn Filter) -> Result<Self, FrameTooLarge> {
        FrameTooLarge::new(width, height).check()?;
        let table = FilterTable::new(filter);
        let r = table.radius();
        // Midpoint rule over the filter's square (the table is what the
        // splats weigh with, so its own integral normalizes exactly what
        // they add).
        let n = (2.0 * r).ceil().max(1.0) as u32 * INTEGRAL_STEPS;
        let step = 2.0 * r / n as f32;
        let mut integral = 0.0f64;
        for j in 0..n {
            let y = -r + (j as f32 + 0.5) * step;
            for i in 0..n {
                let x = -r + (i as f32 + 0.5) * step;
                integral += f64::from(table.weight(x, y));
            }
        }
        integral *= f64::from(step) * f64::from(step);
        let norm = if integral > 0.0 {
            (1.0 / integral) as f32
        } else {
            0.0
        };
        let mut rows = Vec::new();
        rows.try_reserve_exact(height as usize)
            .map_err(|_| FrameTooLarge::new(width, height))?;
        for _ in 0..height {
            let row = crate::film::memory::try_filled(width as usize, Sums::ZERO)
                .ok_or_else(|| FrameTooLarge::new(width, height))?;
            rows.push(Mutex::new(row));
        }
        let edge = [width, height].map(|n| edge_factors(&table, n));
        Ok(Self {
            width,
            height,
            table,
            norm,
            rows,
            edge,
            invalid: Mutex::new(0),
        })
    }

    /// A film of no pixels that drops every splat: the target of samples
    /// whose splats must not reach the image (adaptive sampling's
    /// decision samples).
    pub fn sink(filter: &dyn Filter) -> Self {
        Self {
            width: 0,
            height: 0,
            table: FilterTable::new(filter),
            norm: 0.0,
            rows: Vec::new(),
            edge: [Vec::new(), Vec::new()],
            invalid: Mutex::new(0),
        }
    }

    /// Adds `value`, landed at raster position `pos` (pixels, (0, 0) the
    /// top left corner), to the pixels within the filter's radius.
    pub fn splat(&self, pos: Vec2, value: Rgb) {
        if !value.is_finite() {
            *self.invalid.lock().unwrap_or_else(|e| e.into_inner()) += 1;
            return;
        }
        let r = self.table.radius();
        let (w, h) = (self.width as i64, self.height as i64);
        let x0 = ((pos.x - 0.5 - r).ceil() as i64).max(0);
        let x1 = ((pos.x - 0.5 + r).floor() as i64).min(w - 1);
        let y0 = ((pos.y - 0.5 - r).ceil() as i64).max(0);
        let y1 = ((pos.y - 0.5 + r).floor() as i64).min(h - 1);
        let v = value * self.norm;
        for y in y0..=y1 {
            let dy = y as f32 + 0.5 - pos.y;
            let mut row = self.rows[y as usize]
                .lock()
                .unwrap_or_else(|e| e.into_inner());
            for x in x0..=x1 {
                let f = self.table.weight(x as f32 + 0.5 - pos.x, dy);
                if f != 0.0 {
                    row[x as usize].add_f32((v * f).extend(0.0));
                }
            }
        }
    }

    /// Splats that were NaN or infinite (recorded as nothing).
    pub fn invalid_samples(&self) -> u64 {
        *self.invalid.lock().unwrap_or_else(|e| e.into_inner())
    }

    /// Adds the splats times `scale` to `image` (of this film's size).
    ///
    /// Pixels within the filter's radius of the border are scaled by the
    /// share of the filter that lies inside the image, from their centre
    /// ([`edge_factors`], per axis: the built-in filters are separable):
    /// the tile film's Σ w·L / Σ w renormalizes there, so without it the
    /// splats' estimate of a border pixel would be darker than the camera
    /// samples' (2.5 % of a 16 × 16 image of light paths with a σ = 0.5
    /// Gaussian, `tests/bdpt.rs`).
    ///
    /// # Panics
    ///
    /// If `image` has another size.
    pub fn add_to(&self, image: &mut Image, scale: f64) {
        assert_eq!(
            (image.width, image.height),
            (self.width, self.height),
            "image size"
        );
        let unit = scale * (-f64::from(FRACTION_BITS)).exp2();
        for ((row, pixels), fy) in self
            .rows
            .iter()
            .zip(image.pixels.chunks_mut(self.width.max(1) as usize))
            .zip(&self.edge[1])
        {
            let row = row.lock().unwrap_or_else(|e| e.into_inner());
            for ((sum, p), fx) in row.iter().zip(pixels).zip(&self.edge[0]) {
                let c = |i: usize| (sum.0[i] as f64 * unit) as f32;
                *p += Rgb::new(c(0), c(1), c(2)) * (fx * fy);
            }
        }
    }

    /// The splats' exact sums at pixel (`x`, `y`) (r, g, b; the fourth is
    /// 0), for tests.
    pub fn sums_at(&self, x: u32, y: u32) -> Vec4 {
        self.rows[y as usize]
            .lock()
            .unwrap_or_else(|e| e.into_inner())[x as usize]
            .to_f32()
    }
}

/// For each of the `n` pixels along an axis, ∫g / ∫ g over [0, n] from
/// the pixel's centre, with g(t) the filter table's profile along the
/// axis (its weight at (t, 0); the built-in filters' tables are outer
/// products, so the 2D share is the product of the axes').
fn edge_factors(table: &FilterTable, n: u32) -> Vec<f32> {
    let r = table.radius();
    let steps = (2.0 * r).ceil().max(1.0) as u32 * INTEGRAL_STEPS;
    let step = 2.0 * r / steps as f32;
    (0..n)
        .map(|i| {
            let centre = i as f32 + 0.5;
            let (mut all, mut inside) = (0.0f64, 0.0f64);
            for k in 0..steps {
                let t = -r + (k as f32 + 0.5) * step;
                let g = f64::from(table.weight(t, 0.0));
                all += g;
                if (0.0..n as f32).contains(&(centre + t)) {
                    inside += g;
                }
            }
            if inside > 0.0 {
                (all / inside) as f32
            } else {
                1.0
            }
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A box filter of radius `r`.
    struct BoxFilter(f32);
    impl Filter for BoxFilter {
        fn radius(&self) -> f32 {
            self.0
        }
        fn eval(&self, x: f32, y: f32) -> f32 {
            if x.abs() <= self.0 && y.abs() <= self.0 {
                1.0
            } else {
                0.0
            }
        }
    }

    /// A tent of radius 1.5.
    struct Tent;
    impl Filter for Tent {
        fn radius(&self) -> f32 {
            1.5
        }
        fn eval(&self, x: f32, y: f32) -> f32 {
            (1.0 - x.abs() / 1.5).max(0.0) * (1.0 - y.abs() / 1.5).max(0.0)
        }
    }

    #[test]
    fn a_splat_adds_its_value_in_all() {
        // Away from the edges, the taps of a splat add up to its value on
        // average over positions (∫f normalizes): positions on a grid
        // over one pixel average to within 1 %.
        let film = SplatFilm::new(12, 12, &Tent).expect("a small film");
        let n = 16;
        for j in 0..n {
            for i in 0..n {
                let pos = Vec2::new(6.0 + i as f32 / n as f32, 6.0 + j as f32 / n as f32);
                film.splat(pos, Rgb::splat(1.0));
            }
        }
        let mut total = 0.0f64;
        for y in 0..12 {
            for x in 0..12 {
                total += f64::from(film.sums_at(x, y).x);
            }
        }
        let mean = total / f64::from(n * n);
        assert!((mean - 1.0).abs() < 0.01, "{mean}");
    }

    #[test]
    fn uniform_splats_develop_flat_up_to_the_border() {
        // Splats spread evenly over the whole film develop to the same
        // value in every pixel, the border's included (the tile film's
        // renormalization there, which the splats match).
        let (w, h) = (10u32, 8u32);
        let film = SplatFilm::new(w, h, &Tent).expect("a small film");
        let n = 16;
        for j in 0..h * n {
            for i in 0..w * n {
                let pos = Vec2::new((i as f32 + 0.5) / n as f32, (j as f32 + 0.5) / n as f32);
                film.splat(pos, Rgb::splat(1.0));
            }
        }
        let mut image = Image {
            width: w,
            height: h,
            pixels: vec![Rgb::ZERO; (w * h) as usize],
        };
        film.add_to(&mut image, 1.0 / f64::from(n * n));
        for (i, p) in image.pixels.iter().enumerate() {
            assert!((p.x - 1.0).abs() < 0.01, "pixel {i}: {}", p.x);
        }
    }

    #[test]
    fn splats_do_not_depend_on_their_order() {
        // Many splats in two orders, one of them from several threads:
        // the exact sums are equal bit for bit.
        let splats: Vec<(Vec2, Rgb)> = (0..2000u32)
            .map(|i| {
                use radiant_core::hash::{hash_u32, unit_float};
                let h = hash_u32(i);
                let u = unit_float(h);
                let v = unit_float(hash_u32(h));
                let value = unit_float(hash_u32(h ^ 0x9e37_79b9)) * 100.0;
                (
                    Vec2::new(u * 9.0, v * 7.0),
                    Rgb::new(value, 1e-3, value * 1e3),
                )
            })
            .collect();
        let a = SplatFilm::new(9, 7, &BoxFilter(1.0)).expect("a small film");
        for (p, v) in &splats {
            a.splat(*p, *v);
        }
        let b = SplatFilm::new(9, 7, &BoxFilter(1.0)).expect("a small film");
        std::thread::scope(|s| {
            for chunk in splats.chunks(300).rev() {
                let b = &b;
                s.spawn(move || {
                    for (p, v) in chunk.iter().rev() {
                        b.splat(*p, *v);
                    }
                });
            }
        });
        for y in 0..7 {
            for x in 0..9 {
                assert_eq!(a.sums_at(x, y), b.sums_at(x, y), "({x}, {y})");
            }
        }
        let mut image = Image {
            width: 9,
            height: 7,
            pixels: vec![Rgb::ZERO; 63],
        };
        a.add_to(&mut image, 0.5);
        assert!(image.pixels.iter().any(|p| p.x > 0.0));
        b.splat(Vec2::ONE, Rgb::splat(f32::NAN));
        assert_eq!(b.invalid_samples(), 1);
    }
}
