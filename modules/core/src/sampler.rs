//! Samplers: the random or quasi-random numbers that drive every decision.
//!
//! A sampler is stateless: the value of dimension `dim` for sample `index` of
//! pixel `pixel` is a pure function of those and the scene seed. The
//! integrator assigns dimensions per bounce so they stay decorrelated.

/// The largest `f32` below 1: where a value meant to lie in [0, 1) is
/// clamped after arithmetic that may round it up to 1.
pub const ONE_MINUS_EPSILON: f32 = 1.0 - f32::EPSILON / 2.0;

/// Identifies one pixel sample (a camera path).
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct SampleId {
    /// Linear pixel index, `y * width + x`.
    pub pixel: u32,
    /// Index of the sample within the pixel.
    pub index: u32,
}

/// A sampler module.
pub trait Sampler: Send + Sync {
    /// Writes dimensions `dim` and `dim + 1` of sample `ids[i]` into
    /// `out[i]`, each in [0, 1).
    fn fill_2d(&self, ids: &[SampleId], dim: u32, out: &mut [glam::Vec2]);

    /// Writes dimension `dim` of sample `ids[i]` into `out[i]`, in [0, 1).
    fn fill_1d(&self, ids: &[SampleId], dim: u32, out: &mut [f32]);
    /// The sampler's GPU side (see [`crate::gpu`]), `None` where the type
    /// has none.
    fn gpu(&self) -> Option<crate::GpuModule> {
        None
    }
}
