//! Per-strategy images (`radiant render --strategies DIR`): the image
//! split by the sampling strategy that made each contribution, as in
//! Veach's thesis (figure 10.3) and pbrt's `visualizestrategies` — for
//! `bdpt`, one image per (s light vertices, t camera vertices).
//!
//! A tile integrator that has strategies names them
//! ([`TileIntegrator::strategies`](super::TileIntegrator::strategies));
//! where a render asks for them, the CPU driver holds one whole-image
//! [`SplatFilm`] per strategy and passes them in
//! [`TileContext::strategies`](super::TileContext::strategies). The
//! integrator splats every contribution, times its MIS weight, into its
//! strategy's film at the raster position it belongs to (a camera
//! sample's film position, or where a light path reached the lens), and
//! the driver develops each film as it develops the splat film: scaled
//! by the pixels over the camera samples. So the strategy images are
//! estimates of the weighted contributions of each strategy and sum to
//! the image (exactly in expectation; sample for sample with a box
//! filter, where the image's Σ w·L / Σ w is the plain mean).

use super::splat::SplatFilm;
use crate::film::Image;
use crate::film::memory::{FrameTooLarge, IMAGE_BYTES, SUM_BYTES, try_filled};
use glam::Vec2;
use radiant_core::{Filter, Rgb};

/// Each strategy's name and developed image, in the integrator's order.
pub type StrategyImages = Vec<(String, Image)>;

/// One whole-image film per strategy of a frame.
pub struct StrategyFilms {
    names: Vec<String>,
    films: Vec<SplatFilm>,
}

impl StrategyFilms {
    /// Empty films of `width × height` for the strategies `names`, or what
    /// they needed where their memory is not available.
    pub fn new(
        names: Vec<String>,
        width: u32,
        height: u32,
        filter: &dyn Filter,
    ) -> Result<Self, FrameTooLarge> {
        let pixels = width as u64 * height as u64;
        let mut need = FrameTooLarge::new(width, height);
        need.parts.push((
            "the per-strategy images' sums and pixels",
            names.len() as u64 * pixels * (SUM_BYTES + IMAGE_BYTES),
        ));
        need.check()?;
        let films = names
            .iter()
            .map(|_| SplatFilm::new(width, height, filter))
            .collect::<Result<_, _>>()?;
        Ok(Self { names, films })
    }

    /// Number of strategies.
    pub fn len(&self) -> usize {
        self.films.len()
    }

    /// Whether there are none.
    pub fn is_empty(&self) -> bool {
        self.films.is_empty()
    }

    /// Adds `value` (weighted), landed at raster position `pos`, to the
    /// image of strategy `index`.
    #[inline]
    pub fn splat(&self, index: usize, pos: Vec2, value: Rgb) {
        self.films[index].splat(pos, value);
    }

    /// Each strategy's name and image, its sums scaled by the pixels over
    /// the camera samples `samples` (as the splat film), in the order of
    /// the names; or what they needed where the images cannot be
    /// allocated.
    pub fn develop(
        &self,
        width: u32,
        height: u32,
        samples: u64,
    ) -> Result<StrategyImages, FrameTooLarge> {
        let scale = width as f64 * height as f64 / samples.max(1) as f64;
        self.names
            .iter()
            .zip(&self.films)
            .map(|(name, film)| {
                let pixels = try_filled(width as usize * height as usize, Rgb::ZERO)
                    .ok_or_else(|| FrameTooLarge::new(width, height))?;
                let mut image = Image {
                    width,
                    height,
                    pixels,
                };
                film.add_to(&mut image, scale);
                Ok((name.clone(), image))
            })
            .collect()
    }
}
