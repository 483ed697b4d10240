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
//! the image: in expectation, and sample for sample with the default
//! box filter (radius ½ pixel), where the image's Σ w·L / Σ w is the
//! plain mean of each pixel's own samples.
//!
//! That scaling needs every pixel to take the same samples and every
//! sample to be placed uniformly in its pixel, and there must be finitely
//! many strategies: [`tile_strategies`] refuses adaptive sampling, importance
//! sampling of the filter and an unlimited `max_depth`.

use super::module::{Family, TileIntegrator};
use super::splat::SplatFilm;
use crate::extract::RenderScene;
use crate::film::Image;
use crate::film::memory::{FrameTooLarge, IMAGE_BYTES, SUM_BYTES, try_filled};
use crate::settings::FilterSampling;
use glam::Vec2;
use radiant_core::Rgb;

/// Each strategy's name and developed image, in the integrator's order.
pub type StrategyImages = Vec<(String, Image)>;

/// Why a frame cannot be split by strategy.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
pub enum StrategiesError {
    /// The scene's integrator or settings do not allow it (the message
    /// says which and what to change).
    #[error("{0}")]
    Refused(String),
    /// The films do not fit in memory.
    #[error(
        "{0}; the per-strategy images are max_depth × (max_depth + 3) / 2 films: a lower \
         --max-depth needs fewer"
    )]
    TooLarge(FrameTooLarge),
}

impl From<FrameTooLarge> for StrategiesError {
    fn from(e: FrameTooLarge) -> Self {
        Self::TooLarge(e)
    }
}

/// `scene`'s tile integrator and the names of its strategies, or why its
/// frame cannot be split by them (see the module documentation).
pub fn tile_strategies(
    scene: &RenderScene,
) -> Result<(&dyn TileIntegrator, Vec<String>), StrategiesError> {
    let s = &scene.settings;
    let refuse = |why: String| Err(StrategiesError::Refused(why));
    if s.max_depth < 0 {
        return refuse(
            "per-strategy images need a finite max_depth (one image per strategy of every \
             path length); the scene's is -1: set it, or pass --max-depth N"
                .into(),
        );
    }
    if s.max_depth == 0 {
        return refuse("per-strategy images need max_depth ≥ 1: at 0 no path is traced".into());
    }
    if s.adaptive.is_some() {
        return refuse(
            "per-strategy images need a fixed spp: the scene's sampler has `adaptive:`, whose \
             samples per pixel vary"
                .into(),
        );
    }
    if s.filter_sampling != FilterSampling::Splat {
        return refuse(
            "per-strategy images need `film: {filter_sampling: splat}` (the default): they \
             splat every contribution through the filter"
                .into(),
        );
    }
    if let Family::Tiles(tiles) = scene.integrator.family() {
        let names = tiles.strategies(scene);
        if !names.is_empty() {
            return Ok((tiles, names));
        }
    }
    refuse(format!(
        "per-strategy images need an integrator with sampling strategies to split (`bdpt`); \
         the scene's `{}` has none",
        crate::backend::cpu::integrator_name(scene)
    ))
}

/// One whole-image film per strategy of a frame.
pub struct StrategyFilms {
    names: Vec<String>,
    films: Vec<SplatFilm>,
}

impl StrategyFilms {
    /// Empty films for the strategies `names` of `scene`'s frame, or what
    /// the frame needed (its film, splat film and these) where that is
    /// more than the memory available.
    pub fn new(names: Vec<String>, scene: &RenderScene) -> Result<Self, FrameTooLarge> {
        let (width, height) = (scene.settings.width, scene.settings.height);
        let pixels = width as u64 * height as u64;
        let mut need = FrameTooLarge::new(width, height);
        need.parts
            .push(("the light paths' splat film", pixels * SUM_BYTES));
        need.parts.push((
            "the per-strategy images' sums and pixels",
            names.len() as u64 * pixels * (SUM_BYTES + IMAGE_BYTES),
        ));
        need.check()?;
        let films = names
            .iter()
            .map(|_| SplatFilm::new(width, height, scene.filter.as_ref()))
            .collect::<Result<_, _>>()?;
        Ok(Self { names, films })
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
