//! `radiant merge`: adds the partial EXR files of a frame's sample
//! partitions into the frame (`radiant::farm::merge`) and writes it as
//! `radiant render` writes images (atomically; nothing on an error), encoded
//! as its tone map, exposure, bit depth and EXR options say.

use super::output_args::OutputArgs;
use super::render::check_output;
use clap::Args;
use radiant::film::encoding::Encoding;
use std::path::PathBuf;

/// Options of `radiant merge`.
#[derive(Args)]
pub struct MergeArgs {
    /// The partial EXR files `radiant render --partition K/N` wrote, in any
    /// order; together they must hold each sample of the frame once.
    #[arg(required = true)]
    inputs: Vec<PathBuf>,
    /// The frame: .exr, .hdr (linear RGB), .png or .jpg (tone-mapped sRGB).
    #[arg(short, long)]
    output: PathBuf,
    /// How the frame's values are written (partial files hold no scene
    /// settings: pass those the render used).
    #[command(flatten)]
    encoding: OutputArgs,
}

/// Merges as the arguments say.
pub fn run(args: &MergeArgs) -> miette::Result<()> {
    check_output(&args.output)?;
    if args.encoding.alpha {
        miette::bail!(
            "--alpha: partial files hold no coverage, so a merged frame has no alpha; leave it out"
        );
    }
    let encoding = Encoding::default()
        .with(&args.encoding.overrides())
        .map_err(|e| miette::miette!("{e}"))?;
    let (film, header) =
        radiant::farm::merge::merge(&args.inputs).map_err(|e| miette::miette!("{e}"))?;
    let image = film.try_develop().map_err(|e| miette::miette!("{e}"))?;
    radiant::film::output::write_encoded(&args.output, &image, &encoding)
        .map_err(|e| miette::miette!("{e}"))?;
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
