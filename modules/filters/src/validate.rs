//! Parameter checks shared by the filters.

use radiant_core::{ParamError, Params};

/// The smallest filter radius in pixels. Below half a pixel, parts of the
/// image plane are further than the radius from every pixel centre: their
/// samples are lost, and at the extreme the image is black.
pub(crate) const MIN_RADIUS: f32 = 0.5;

/// The largest filter radius in pixels. A splat touches (2r)² pixels, and
/// with importance-sampled filtering most samples of a wide filter land off
/// a small film; wider blurs belong in post-processing.
pub(crate) const MAX_RADIUS: f32 = 32.0;

/// `value` if it is a positive finite number of pixels, otherwise an error
/// at `key`.
pub(crate) fn positive(params: &Params, key: &str, value: f32) -> Result<f32, ParamError> {
    if value > 0.0 && value.is_finite() {
        Ok(value)
    } else {
        Err(ParamError {
            message: format!("`{key}` must be a positive number of pixels, found {value}"),
            location: params.location_of(key),
        })
    }
}

/// `value` if it is a radius from [`MIN_RADIUS`] to [`MAX_RADIUS`] pixels,
/// otherwise an error at `key`.
pub(crate) fn radius(params: &Params, key: &str, value: f32) -> Result<f32, ParamError> {
    if (MIN_RADIUS..=MAX_RADIUS).contains(&value) {
        Ok(value)
    } else {
        Err(ParamError {
            message: format!(
                "`{key}` must be from {MIN_RADIUS} to {MAX_RADIUS} pixels, found {value}{}",
                if value < MIN_RADIUS {
                    " (below half a pixel, samples between pixel centres are lost)"
                } else {
                    ""
                }
            ),
            location: params.location_of(key),
        })
    }
}

/// `value` if it lies in [0, 1], otherwise an error at `key`.
pub(crate) fn unit(params: &Params, key: &str, value: f32) -> Result<f32, ParamError> {
    if (0.0..=1.0).contains(&value) {
        Ok(value)
    } else {
        Err(ParamError {
            message: format!("`{key}` must be from 0 to 1, found {value}"),
            location: params.location_of(key),
        })
    }
}

/// The default radius of most filters, in pixels.
pub(crate) fn half() -> f32 {
    0.5
}
