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
    #[arg(long, allow_negative_numbers = true, value_parser = samples_per_pixel)]
    pub spp: Option<u32>,
    /// Longest path in segments; -1 for unlimited (overrides the scene).
    #[arg(long, allow_negative_numbers = true, value_parser = clap::value_parser!(i32).range(-1..))]
    pub max_depth: Option<i32>,
    /// Sampler seed (of the scene's first frame; the others derive theirs).
    #[arg(long)]
    pub seed: Option<u64>,
}

/// Parses `--spp`: a whole number in 1..=2³²−1. Negative numbers reach
/// it (`allow_negative_numbers`), so `--spp -4` is called out of range
/// rather than an unexpected argument.
fn samples_per_pixel(text: &str) -> Result<u32, String> {
    let max = u32::MAX;
    match text.trim().parse::<i64>() {
        Ok(n) => u32::try_from(n)
            .ok()
            .filter(|&n| n >= 1)
            .ok_or_else(|| format!("{n} is not in 1..={max}: samples per pixel are 1 or more")),
        Err(_) => Err(format!(
            "`{text}` is not a whole number of samples per pixel (1..={max})"
        )),
    }
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
