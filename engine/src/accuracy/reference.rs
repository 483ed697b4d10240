//! The reference every setting is measured against: an image read from an
//! EXR file, or a converged render of the scene as written, made here in
//! two seed halves so that its own remaining noise is known.

use super::AccuracyError;
use super::metrics::Halves;
use super::sweep::Setting;
use super::twin::{TwinImages, TwinRender};
use crate::extract::Overrides;
use crate::film::Image;
use crate::scene::Scene;
use radiant_core::Registry;
use std::path::Path;
use std::time::{Duration, Instant};

/// Seeds of the reference's halves, far from the sweep's, so that its
/// noise is independent of every setting's.
const REFERENCE_SEED: u64 = 0x5EED_0000_0000;

/// The reference image.
#[derive(Debug, Clone)]
pub struct Reference {
    /// The image the settings are measured against.
    pub image: Image,
    /// Its halves, when it was rendered here.
    pub halves: Option<[Image; 2]>,
    /// Samples per pixel, when it was rendered here.
    pub spp: Option<u32>,
    /// Render time (extract included), when it was rendered here.
    pub time: Option<Duration>,
}

impl Reference {
    /// Reads a reference EXR.
    pub fn read(path: &Path) -> Result<Self, AccuracyError> {
        Ok(Self {
            image: crate::film::output::read_exr(path)?,
            halves: None,
            spp: None,
            time: None,
        })
    }

    /// Renders the scene as written (with `base` overrides) in two halves
    /// until `time` has passed or `max_spp` samples per pixel are reached.
    /// The passes double the sample count, and one that would end past
    /// `time` is not started.
    pub fn render(
        scene: &mut Scene,
        registry: &Registry,
        base: &Overrides,
        time: Duration,
        max_spp: u32,
    ) -> Result<Self, AccuracyError> {
        let start = Instant::now();
        let max_half = (max_spp / 2).max(1);
        let overrides = Overrides {
            seed: Some(REFERENCE_SEED),
            spp: Some(max_half),
            ..*base
        };
        let render = Setting::baseline().extract(scene, registry, &overrides)?;
        let mut twin = TwinRender::new(scene, registry, render, REFERENCE_SEED + 1)?;
        twin.run_doubling(max_half, start, time, |_| {});
        let images = TwinImages::of(&twin);
        Ok(Self {
            image: images.combined,
            halves: Some(images.halves),
            spp: Some(2 * twin.spp()),
            time: Some(start.elapsed()),
        })
    }

    /// The halves, for the bias split.
    pub fn halves(&self) -> Option<Halves<'_>> {
        self.halves.as_ref().map(|[a, b]| Halves { a, b })
    }

    /// Relative standard error: the RMS noise of the image over its mean
    /// value (0 when the noise is unknown).
    pub fn relative_error(&self) -> Option<f64> {
        let mean = self.image.mean();
        self.halves()
            .map(|h| h.variance().sqrt() / mean.max(f64::MIN_POSITIVE))
    }

    /// Fails unless the reference is `width`×`height`.
    pub fn check_size(&self, width: u32, height: u32) -> Result<(), AccuracyError> {
        if (self.image.width, self.image.height) == (width, height) {
            Ok(())
        } else {
            Err(AccuracyError::ReferenceSize {
                reference: (self.image.width, self.image.height),
                film: (width, height),
            })
        }
    }
}
