//! Linear RGB colour, the spectral representation every module works in.

/// Linear-RGB radiance, reflectance or weight (Rec. 709 primaries).
pub type Rgb = glam::Vec3;

/// Luminance (Y) of a linear Rec. 709 colour.
#[inline]
pub fn luminance(c: Rgb) -> f32 {
    0.212_671 * c.x + 0.715_160 * c.y + 0.072_169 * c.z
}
