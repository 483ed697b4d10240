//! What the delta lights (`point`, `spot`, `directional`) share: each
//! reference point sees exactly one point of the light, so a next-event
//! sample is that point with its radiance, chosen with probability 1.

use radiant_core::glam::Vec3;
use radiant_core::{LightSample, Rgb};

/// Writes the sample of every reference point `refs[i]`: the light's point
/// and the radiance arriving from it, `at(refs[i])`, with no surface
/// normal and probability 1.
#[inline]
pub(crate) fn sample_delta(
    refs: &[Vec3],
    out: &mut [LightSample],
    at: impl Fn(Vec3) -> (Vec3, Rgb),
) {
    for (r, o) in refs.iter().zip(out.iter_mut()) {
        let (p, radiance) = at(*r);
        *o = LightSample {
            p,
            n: Vec3::ZERO,
            radiance,
            pdf: 1.0,
        };
    }
}
