//! Options that `render` and `farm slurm` share: the overrides of the
//! scene's samples, path depth and seed, with the ranges they allow
//! (checked by clap before anything is loaded).

use super::film_args::FilmArgs;
use clap::Args;
use radiant::extract::Overrides;

/// Sample count, path depth and seed overrides.
#[derive(Args)]
pub struct SamplingArgs {
    /// Samples per pixel, at least 1 (overrides the scene's sampler).
    #[arg(long, value_parser = clap::value_parser!(u32).range(1..))]
    pub spp: Option<u32>,
    /// Longest path in segments; -1 for unlimited (overrides the scene).
    #[arg(long, allow_negative_numbers = true, value_parser = clap::value_parser!(i32).range(-1..))]
    pub max_depth: Option<i32>,
    /// Sampler seed (of the scene's first frame; the others derive theirs).
    #[arg(long)]
    pub seed: Option<u64>,
}

impl SamplingArgs {
    /// These overrides with the film size ones of `film`.
    pub fn overrides(&self, film: &FilmArgs) -> Overrides {
        Overrides {
            spp: self.spp,
            max_depth: self.max_depth,
            seed: self.seed,
            width: film.width,
            height: film.height,
            ..Default::default()
        }
    }
}
