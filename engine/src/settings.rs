//! Render settings: how a frame is rendered, as the scene file says and as
//! the command line or a tool overrides it.
//!
//! Both sides read this module: the scene loader fills [`RenderSettings`]
//! from the file, and extract, the integrators, the film and the backends
//! read the settings of the frame. [`RenderSettings::with`] is the one place
//! where [`Overrides`] are checked and applied.

pub use crate::film::encoding::{Encoding, OutputOverrides};
use serde::Deserialize;
use std::fmt;

/// The largest film width or height in pixels, in a scene file or as an
/// override.
pub const MAX_FILM_SIZE: u32 = 1 << 15;

/// How a frame is rendered: the scene's integrator, film and sampler
/// settings (command-line options may override them).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct RenderSettings {
    /// Film width in pixels.
    pub width: u32,
    /// Film height in pixels.
    pub height: u32,
    /// Samples per pixel.
    pub spp: u32,
    /// Longest path in segments (Mitsuba 3 semantics); -1 for no limit.
    pub max_depth: i32,
    /// Depth from which Russian roulette may end paths.
    pub rr_depth: u32,
    /// Seed of the sampler (of the scene's first frame; later frames derive
    /// theirs from it, see [`RenderSettings::frame_seed`]).
    pub seed: u64,
    /// How next-event estimation chooses a light.
    pub light_selection: LightSelection,
    /// How samples reach the pixels through the pixel filter.
    pub filter_sampling: FilterSampling,
    /// How the image's values are written (`film: {tonemap, bit_depth,
    /// exr, jpeg_quality}`).
    pub output: Encoding,
    /// Adaptive sampling (`sampler: {adaptive: …}`), if on: `spp` is then
    /// the most a pixel takes unless `max_spp` says otherwise.
    pub adaptive: Option<crate::integrators::adaptive::Adaptive>,
}

impl Default for RenderSettings {
    /// The settings of a scene file that gives none: 768×576, 64 spp,
    /// unlimited depth, Russian roulette from depth 5.
    fn default() -> Self {
        Self {
            width: 768,
            height: 576,
            spp: 64,
            max_depth: -1,
            rr_depth: 5,
            seed: 0,
            light_selection: LightSelection::default(),
            filter_sampling: FilterSampling::default(),
            output: Encoding::default(),
            adaptive: None,
        }
    }
}

/// How the film applies the pixel filter (`film: {filter_sampling: …}`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum FilterSampling {
    /// Each sample is placed uniformly in its pixel and added to every
    /// pixel within the filter's radius, weighted by the filter; a pixel is
    /// Σ f·L / Σ f (Mitsuba 3). Wide filters cost more per sample.
    #[default]
    Splat,
    /// Each sample's offset from its pixel's centre is drawn in proportion
    /// to |f| and the sample is added to that pixel alone with weight
    /// f/pdf (pbrt-v4): any filter costs what `box` costs, pixels are
    /// uncorrelated, and the noise per sample is somewhat higher.
    Importance,
}

/// How next-event estimation chooses among the scene's lights
/// (`integrator: {light_selection: …}`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum LightSelection {
    /// In proportion to each light's emitted power.
    Power,
    /// Every light equally likely.
    Uniform,
    /// By each light's importance at the shading point — its power over
    /// the squared distance, zero outside its emission cone (pbrt-v4's
    /// light bounds, after Conty and Kulla 2018); lights at infinity take
    /// a fixed share. The default: the CPU and the GPU choose alike
    /// (`backend/gpu/wgsl/light_selection.wgsl`), and with unequal lights
    /// it is far less noisy than power (`engine/benches/SUITE.md`).
    #[default]
    Spatial,
}

/// BVH build quality preset.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum BuildQuality {
    /// Fast build, slower traversal.
    Fast,
    /// The trade-off for very large scenes.
    Medium,
    /// Slow build (about twice Medium's), best traversal.
    High,
}

impl BuildQuality {
    /// Primitives up to which scenes get [`BuildQuality::High`] by default.
    pub const HIGH_UP_TO: usize = 1 << 20;

    /// The default for a hierarchy of `primitives`: `High` up to
    /// [`Self::HIGH_UP_TO`] (0.27 s instead of 0.14 s for 169k triangles on
    /// one core; the Cornell box renders 4.5 % faster), `Medium` beyond,
    /// where the build's time starts to count.
    pub fn default_for(primitives: usize) -> Self {
        if primitives <= Self::HIGH_UP_TO {
            Self::High
        } else {
            Self::Medium
        }
    }
}

/// Changes to the scene's settings from the command line or a tool; `None`
/// keeps the scene's value.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct Overrides {
    /// Samples per pixel.
    pub spp: Option<u32>,
    /// Maximum path depth.
    pub max_depth: Option<i32>,
    /// Depth from which Russian roulette may end paths.
    pub rr_depth: Option<u32>,
    /// Sampler seed.
    pub seed: Option<u64>,
    /// Film width.
    pub width: Option<u32>,
    /// Film height.
    pub height: Option<u32>,
    /// Light selection of next-event estimation.
    pub light_selection: Option<LightSelection>,
    /// How samples reach the pixels.
    pub filter_sampling: Option<FilterSampling>,
    /// BVH build quality (default: [`BuildQuality::default_for`] each
    /// hierarchy's primitive count).
    pub bvh: Option<BuildQuality>,
    /// Tone map, PNG bit depth and EXR sample type.
    pub output: OutputOverrides,
}

/// An override outside the range a scene file allows.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[error("{0}")]
pub struct OverrideError(pub String);

impl RenderSettings {
    /// These settings with `overrides` applied, each checked against the
    /// range the scene file allows.
    pub fn with(mut self, o: &Overrides) -> Result<Self, OverrideError> {
        let error = |what: String| Err(OverrideError(what));
        for (key, value) in [("width", o.width), ("height", o.height)] {
            if let Some(v) = value
                && !(1..=MAX_FILM_SIZE).contains(&v)
            {
                return error(format!(
                    "the film {key} override must be between 1 and {MAX_FILM_SIZE} pixels, found {v}"
                ));
            }
        }
        if o.spp == Some(0) {
            return error("the spp override must be at least 1".into());
        }
        if let Some(d) = o.max_depth
            && d < -1
        {
            return error(format!(
                "the max_depth override must be -1 (unlimited) or at least 0, found {d}"
            ));
        }
        self.spp = o.spp.unwrap_or(self.spp);
        self.max_depth = o.max_depth.unwrap_or(self.max_depth);
        self.rr_depth = o.rr_depth.unwrap_or(self.rr_depth);
        self.seed = o.seed.unwrap_or(self.seed);
        self.width = o.width.unwrap_or(self.width);
        self.height = o.height.unwrap_or(self.height);
        self.light_selection = o.light_selection.unwrap_or(self.light_selection);
        self.filter_sampling = o.filter_sampling.unwrap_or(self.filter_sampling);
        self.output = self
            .output
            .with(&o.output)
            .map_err(|e| OverrideError(format!("the exposure override: {e}")))?;
        Ok(self)
    }

    /// The sampler seed of the frame `offset` frames after the scene's
    /// first: the base seed for the first frame (so a still renders as it
    /// always has), and a well-mixed different one for every other, so
    /// that noise does not stand still over a moving image. With
    /// `locked`, every frame uses the base seed (the same noise pattern in
    /// every frame, for A/B comparisons).
    pub fn frame_seed(&self, offset: i64, locked: bool) -> u64 {
        if locked {
            return self.seed;
        }
        // A Weyl sequence of the golden ratio: distinct for every offset
        // (odd multiplier), 0 for the first frame; samplers hash the seed.
        self.seed
            .wrapping_add((offset as u64).wrapping_mul(0x9e37_79b9_7f4a_7c15))
    }
}

impl fmt::Display for FilterSampling {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(match self {
            FilterSampling::Splat => "splat",
            FilterSampling::Importance => "importance",
        })
    }
}

impl fmt::Display for LightSelection {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(match self {
            LightSelection::Power => "power",
            LightSelection::Uniform => "uniform",
            LightSelection::Spatial => "spatial",
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn overrides_replace_values_and_are_checked() {
        let s = RenderSettings::default();
        let o = Overrides {
            spp: Some(3),
            rr_depth: Some(2),
            filter_sampling: Some(FilterSampling::Importance),
            ..Overrides::default()
        };
        let t = s.with(&o).expect("valid overrides");
        assert_eq!((t.spp, t.rr_depth, t.width), (3, 2, s.width));
        assert_eq!(t.filter_sampling, FilterSampling::Importance);
        for bad in [
            Overrides {
                spp: Some(0),
                ..Overrides::default()
            },
            Overrides {
                width: Some(MAX_FILM_SIZE + 1),
                ..Overrides::default()
            },
            Overrides {
                max_depth: Some(-2),
                ..Overrides::default()
            },
        ] {
            assert!(s.with(&bad).is_err(), "{bad:?}");
        }
    }

    #[test]
    fn frame_seeds_differ_except_when_locked() {
        let s = RenderSettings {
            seed: 7,
            ..RenderSettings::default()
        };
        assert_eq!(s.frame_seed(0, false), 7);
        let seeds: std::collections::HashSet<u64> =
            (0..1000).map(|f| s.frame_seed(f, false)).collect();
        assert_eq!(seeds.len(), 1000);
        assert!((0..10).all(|f| s.frame_seed(f, true) == 7));
    }
}
