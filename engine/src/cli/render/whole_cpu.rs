//! The options that need one whole CPU render of the image alone —
//! `--spp-map` and `--strategies` — and what they cannot be combined
//! with, checked from the flags before the scene is read (and, for the
//! planes a scene's settings ask for, once they are known).

use super::RenderArgs;
use radiant::backend::BackendKind;

/// The first such option `args` asks for, by its flag.
pub(super) fn asked(args: &RenderArgs) -> Option<&'static str> {
    if args.spp_map.is_some() {
        Some("--spp-map")
    } else if args.strategies.is_some() {
        Some("--strategies")
    } else {
        None
    }
}

/// Refuses, from the flags alone, what an asked option cannot go with:
/// the GPU, passes, a partition, the other option, and several frames
/// into one file name (a run of `#` numbers them, as in `--output`).
pub(super) fn check_flags(args: &RenderArgs) -> miette::Result<()> {
    let Some(flag) = asked(args) else {
        return Ok(());
    };
    let conflict = if args.backend == BackendKind::Gpu {
        Some("--backend gpu")
    } else if args.progressive.is_set() {
        Some("--time, --checkpoint or --resume")
    } else if args.partition.is_some() {
        Some("--partition")
    } else if args.spp_map.is_some() && args.strategies.is_some() {
        Some("--strategies")
    } else {
        None
    };
    if let Some(what) = conflict {
        miette::bail!("{flag} cannot be combined with {what}: it needs one whole CPU render");
    }
    let several = args.frames.is_some_and(|(a, b)| b > a);
    let named = [&args.spp_map, &args.strategies]
        .into_iter()
        .flatten()
        .find(|p| {
            !p.file_name()
                .is_some_and(|n| n.to_string_lossy().contains('#'))
        });
    if let (true, Some(path)) = (several, named) {
        miette::bail!(
            "cannot write several frames' {flag} to `{}`: put a run of `#` in its last name \
             for the frame number, as in `out/frame_####`",
            path.display()
        );
    }
    Ok(())
}

/// Refuses an asked option where the frame records planes (output
/// variables, the denoiser's guides, alpha), which the option's render
/// does not.
pub(super) fn check_planes(args: &RenderArgs, planes: bool) -> miette::Result<()> {
    match asked(args) {
        Some(flag) if planes => miette::bail!(
            "{flag} cannot be combined with output variables, --denoise or alpha: it needs one \
             whole CPU render of the image alone"
        ),
        _ => Ok(()),
    }
}
