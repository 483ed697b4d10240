//! Parameter checks and placement shared by the light modules: colours must
//! be finite and non-negative, and a free light's `transform` (light space
//! to world space) moves its positions and turns its directions.

use radiant_core::glam::{DVec3, Vec3};
use radiant_core::{BuildContext, Numbers, ParamError, Params, Rgb};

/// Rejects a colour parameter `key` that is negative or not finite.
pub(crate) fn check_colour(params: &Params, key: &str, c: Rgb) -> Result<(), ParamError> {
    if c.is_finite() && c.min_element() >= 0.0 {
        Ok(())
    } else {
        Err(ParamError {
            message: format!("`{key}` must be finite and non-negative, found {c}"),
            location: params.location_of(key),
        })
    }
}

/// A light-space point in render space.
pub(crate) fn place(ctx: &BuildContext<'_>, p: DVec3) -> Vec3 {
    ctx.to_render(ctx.to_world.transform_point3(p))
}

/// The unit axis of a light, in render space: `direction` (default +z) or
/// the way from `position` to `target` (not both), turned by the light's
/// transform.
pub(crate) fn axis(
    params: &Params,
    ctx: &BuildContext<'_>,
    position: DVec3,
    direction: Option<Numbers<3>>,
    target: Option<Numbers<3>>,
) -> Result<Vec3, ParamError> {
    let (key, d) = match (direction, target) {
        (Some(_), Some(_)) => {
            return Err(ParamError {
                message: "give either `direction` or `target`, not both".into(),
                location: params.location_of("target"),
            });
        }
        (Some(d), None) => ("direction", DVec3::from(d)),
        (None, Some(t)) => ("target", DVec3::from(t) - position),
        (None, None) => ("direction", DVec3::Z),
    };
    let d = ctx.to_world.transform_vector3(d);
    let n = d.normalize_or_zero();
    if n == DVec3::ZERO || !n.is_finite() {
        let what = if key == "target" {
            "`target` must differ from `position`"
        } else {
            "`direction` must be a finite, non-zero vector"
        };
        return Err(ParamError {
            message: format!("{what} (after the light's transform), found {d}"),
            location: params.location_of(key),
        });
    }
    Ok(n.as_vec3())
}
