//! Options that `render` and `accuracy` share: the film size overrides and
//! the worker threads, with the ranges they allow (checked by clap before
//! anything is loaded), and the thread pool they ask for.

use clap::Args;
use clap::builder::RangedI64ValueParser;
use radiant::scene::MAX_FILM_SIZE;

/// The most worker threads `--threads` takes.
const MAX_THREADS: i64 = 1024;

/// Film size overrides and worker threads.
#[derive(Args)]
pub struct FilmArgs {
    /// Film width in pixels, 1 to 32768 (overrides the scene).
    #[arg(long, allow_negative_numbers = true, value_parser = clap::value_parser!(u32).range(1..=i64::from(MAX_FILM_SIZE)))]
    pub width: Option<u32>,
    /// Film height in pixels, 1 to 32768 (overrides the scene).
    #[arg(long, allow_negative_numbers = true, value_parser = clap::value_parser!(u32).range(1..=i64::from(MAX_FILM_SIZE)))]
    pub height: Option<u32>,
    /// Worker threads, 1 to 1024 (default: all cores).
    #[arg(long, allow_negative_numbers = true, value_parser = RangedI64ValueParser::<usize>::new().range(1..=MAX_THREADS))]
    pub threads: Option<usize>,
}

impl FilmArgs {
    /// A pool of the asked-for number of threads (all cores by default).
    pub fn thread_pool(&self) -> miette::Result<rayon::ThreadPool> {
        rayon::ThreadPoolBuilder::new()
            .num_threads(self.threads.unwrap_or(0))
            .build()
            .map_err(|e| miette::miette!("cannot start worker threads: {e}"))
    }
}
