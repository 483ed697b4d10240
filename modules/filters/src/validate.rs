//! Parameter checks shared by the filters.

use radiant_core::{ParamError, Params};

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

/// `value` if it is finite, otherwise an error at `key`.
pub(crate) fn finite(params: &Params, key: &str, value: f32) -> Result<f32, ParamError> {
    if value.is_finite() {
        Ok(value)
    } else {
        Err(ParamError {
            message: format!("`{key}` must be a finite number, found {value}"),
            location: params.location_of(key),
        })
    }
}

/// The default radius of most filters, in pixels.
pub(crate) fn half() -> f32 {
    0.5
}
