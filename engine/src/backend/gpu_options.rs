//! How the GPU backend is asked for: the options `--gpu-kernel`,
//! `--gpu-bvh` and `--gpu-stats` fill and [`super::choose`] opens an
//! adapter with. They are plain data, compiled with or without the `gpu`
//! cargo feature, so the command line parses the same flags either way
//! and a build without the GPU backend refuses `--backend gpu` with
//! [`super::RenderError::GpuNotBuilt`] rather than an unknown flag.

use std::fmt;

/// How to open the GPU.
#[derive(Debug, Clone, Default, PartialEq, Eq)]
pub struct GpuOptions {
    /// The largest storage buffer the frame will need, if known: an
    /// adapter that cannot bind one that large is refused up front.
    pub storage_buffer_bytes: Option<u64>,
    /// Compile traversal counters into the kernel (nodes visited,
    /// primitives tested; slower), read with the GPU backend's
    /// `last_stats`.
    pub stats: bool,
    /// The hierarchy layout of the frames' geometry (`--gpu-bvh`).
    pub bvh: BvhLayout,
    /// Which kernel renders the paths (`--gpu-kernel`).
    pub kernel: GpuKernel,
    /// Path slots of the wavefront's pool, if not its default (at most
    /// 2^19, fewer where a batch has fewer work items).
    pub wavefront_paths: Option<u32>,
}

/// Which kernel renders the paths on the GPU (`--gpu-kernel`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
#[cfg_attr(feature = "cli", derive(clap::ValueEnum))]
pub enum GpuKernel {
    /// One invocation traces one whole path (`wgsl/path.wgsl`).
    #[default]
    Megakernel,
    /// Paths pass through generate, extend, shade, connect and accumulate
    /// stages with queues between them (`wgsl/wavefront.wgsl`).
    Wavefront,
}

impl fmt::Display for GpuKernel {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(match self {
            GpuKernel::Megakernel => "megakernel",
            GpuKernel::Wavefront => "wavefront",
        })
    }
}

/// The hierarchy layout of the GPU backend (`--gpu-bvh`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
#[cfg_attr(feature = "cli", derive(clap::ValueEnum))]
pub enum BvhLayout {
    /// Binary BVH, two child boxes per 64-byte node, up to 4 primitives
    /// per leaf.
    #[default]
    Binary,
    /// Compressed wide BVH (Ylitie et al. 2017): eight quantized child
    /// boxes per 80-byte node, up to 3 primitives per leaf.
    Wide,
}

impl fmt::Display for BvhLayout {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(match self {
            BvhLayout::Binary => "binary (64-byte nodes, 2 children)",
            BvhLayout::Wide => "compressed wide (80-byte nodes, 8 children)",
        })
    }
}
