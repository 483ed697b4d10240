//! `radiant merge`: adds the partial EXR files of a frame's sample
//! partitions into the frame (`radiant::farm::merge`) and writes it as
//! `radiant render` writes images (atomically; nothing on an error).

use super::render::check_output;
use clap::Args;
use std::path::PathBuf;

/// Options of `radiant merge`.
#[derive(Args)]
pub struct MergeArgs {
    /// The partial EXR files `radiant render --partition K/N` wrote, in any
    /// order; together they must hold each sample of the frame once.
    #[arg(required = true)]
    inputs: Vec<PathBuf>,
    /// The frame: .exr (linear float RGB) or .png (tone-mapped sRGB).
    #[arg(short, long)]
    output: PathBuf,
}

/// Merges as the arguments say.
pub fn run(args: &MergeArgs) -> miette::Result<()> {
    check_output(&args.output)?;
    let (film, header) =
        radiant::farm::merge::merge(&args.inputs).map_err(|e| miette::miette!("{e}"))?;
    let image = film.try_develop().map_err(|e| miette::miette!("{e}"))?;
    radiant::film::output::write(&args.output, &image).map_err(|e| miette::miette!("{e}"))?;
    if film.invalid_samples > 0 {
        eprintln!(
            "warning: {} samples were NaN or infinite and were recorded as black",
            film.invalid_samples
        );
    }
    eprintln!(
        "merged {} files of frame {} ({}x{}, {} spp) → {}",
        args.inputs.len(),
        header.frame,
        header.width,
        header.height,
        header.spp,
        args.output.display()
    );
    Ok(())
}
