//! `radiant sheet`: a rendered sequence as a contact sheet or an animated
//! GIF.

use super::render::frame_path;
use clap::Args;
use radiant::film::sheet::write_sheet;
use std::path::PathBuf;

/// Options of `radiant sheet`.
#[derive(Args)]
pub struct SheetArgs {
    /// The frames' file name with a run of `#` for the frame number (as
    /// given to `render -o`).
    frames_pattern: PathBuf,
    /// The frames to show: `A..B` (inclusive).
    #[arg(long, value_parser = super::render::parse_frames)]
    frames: (i64, i64),
    /// Output: .png (a contact sheet) or .gif (an animation, looping).
    #[arg(short, long)]
    output: PathBuf,
    /// Frames per row of a contact sheet.
    #[arg(long, default_value_t = 8, value_parser = clap::value_parser!(u32).range(1..=1024))]
    columns: u32,
    /// Frames per second of a GIF.
    #[arg(long, default_value_t = 24.0)]
    fps: f64,
    /// Show every n-th frame only.
    #[arg(long, default_value_t = 1, value_parser = clap::value_parser!(u32).range(1..))]
    every: u32,
}

/// Writes the sheet as the arguments say.
pub fn run(args: &SheetArgs) -> miette::Result<()> {
    let pattern = args.frames_pattern.to_string_lossy();
    let named = args
        .frames_pattern
        .file_name()
        .is_some_and(|n| n.to_string_lossy().contains('#'));
    if !named {
        miette::bail!(
            "`{pattern}` has no run of `#` for the frame number, as in `out/frame_####.png`"
        );
    }
    if !(args.fps > 0.0 && args.fps <= 100.0) {
        miette::bail!("--fps must be between 0 and 100, found {}", args.fps);
    }
    let (first, last) = args.frames;
    let paths: Vec<PathBuf> = (first..=last)
        .step_by(args.every as usize)
        .map(|f| frame_path(&args.frames_pattern, f))
        .collect();
    if let Some(missing) = paths.iter().find(|p| !p.exists()) {
        miette::bail!("frame `{}` does not exist", missing.display());
    }
    write_sheet(&paths, &args.output, args.columns, args.fps)
        .map_err(|e| miette::miette!("{e}"))?;
    eprintln!("wrote {} frames to {}", paths.len(), args.output.display());
    Ok(())
}
