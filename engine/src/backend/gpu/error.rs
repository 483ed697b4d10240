//! What can go wrong on the GPU backend, each said so that the user knows
//! what is missing and what to do.

use thiserror::Error;

/// A GPU backend failure.
#[derive(Debug, Error)]
pub enum GpuError {
    /// No adapter was found.
    #[error(
        "no GPU adapter found ({0}); render with `--backend cpu`, or install a Vulkan, Metal or DX12 driver (Mesa's lavapipe, `mesa-vulkan-drivers`, runs anywhere)"
    )]
    NoAdapter(String),
    /// The adapter lacks a limit the backend needs.
    #[error(
        "the GPU adapter `{adapter}` lacks a needed limit: {limit} must be at least {needed}, the adapter allows {allowed}"
    )]
    Limit {
        /// The adapter's name.
        adapter: String,
        /// The limit's name (as wgpu names it).
        limit: &'static str,
        /// What the backend needs.
        needed: u64,
        /// What the adapter allows.
        allowed: u64,
    },
    /// The device could not be created.
    #[error("could not open the GPU adapter `{adapter}`: {message}")]
    Device {
        /// The adapter's name.
        adapter: String,
        /// The driver's message.
        message: String,
    },
    /// A module in the scene has no GPU code.
    #[error(
        "the {kind}{} (type `{type_name}`) has no GPU code, so the scene cannot render with `--backend gpu`; render it with `--backend cpu` (or `auto`)",
        named(name)
    )]
    MissingCode {
        /// The module kind (`material`, `light`, …).
        kind: &'static str,
        /// Which one: a material's name, a light's number; empty for the
        /// scene's one camera, sampler or integrator.
        name: String,
        /// The module type.
        type_name: String,
    },
    /// The scene needs what the chosen kernel does not do.
    #[error(
        "{what} cannot render with the {kernel} GPU kernel; use `--gpu-kernel megakernel` (the default) or `--backend cpu`"
    )]
    Unsupported {
        /// The kernel (`wavefront`).
        kernel: &'static str,
        /// What the scene has that it lacks.
        what: String,
    },
    /// The generated kernel did not compile.
    #[error("the GPU kernel did not compile{}: {message}", module.as_ref().map(|m| format!(" (in the code of {m})")).unwrap_or_default())]
    Compile {
        /// The module whose code the error points into, if any.
        module: Option<String>,
        /// The compiler's message.
        message: String,
    },
    /// The device failed while rendering (lost, out of memory, a
    /// validation error).
    #[error("the GPU failed while rendering: {0}")]
    Render(String),
    /// The frame's buffers do not fit the device.
    #[error(
        "the scene needs a GPU buffer of {needed} bytes for {what}, more than the adapter's largest ({allowed} bytes)"
    )]
    TooLarge {
        /// What the buffer holds.
        what: &'static str,
        /// Its size.
        needed: u64,
        /// The adapter's limit.
        allowed: u64,
    },
}

/// The module's name in backticks after a space, or nothing for the
/// scene's one camera, sampler or integrator.
fn named(name: &str) -> String {
    if name.is_empty() {
        String::new()
    } else {
        format!(" `{name}`")
    }
}
