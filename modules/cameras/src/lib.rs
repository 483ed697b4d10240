//! # radiant-cameras: built-in camera modules
//!
//! Cameras turn film positions into primary rays (the first stage of the
//! wavefront). The engine parses the camera's pose (`look_at` or
//! `transform`) itself and passes it as
//! [`BuildContext::camera_to_render`](radiant_core::BuildContext); a camera
//! module only parses its projection parameters. What the projections share
//! (field of view, film to image plane) lives in `projection`.

mod importance;
mod orthographic;
mod perspective;
mod projection;
mod spherical;
mod thin_lens;

pub use orthographic::Orthographic;
pub use perspective::Perspective;
pub use projection::{FovAxis, InvalidParam};
pub use spherical::Spherical;
pub use thin_lens::ThinLens;

use radiant_core::glam::{Mat4, Vec2};
use radiant_core::{BuildContext, Camera, ModuleInfo, ParamDoc, Params, Registry};
use serde::de::DeserializeOwned;

/// Registers every built-in camera type.
pub fn register(registry: &mut Registry) {
    perspective::register(registry);
    thin_lens::register(registry);
    orthographic::register(registry);
    spherical::register(registry);
}

/// Registers the camera type `type_name`: `make` builds it from its
/// parameters `P`, the pose (camera to render space) and the film
/// resolution; a parameter out of range is reported at its key.
fn register_camera<P: DeserializeOwned + 'static, C: Camera + 'static>(
    registry: &mut Registry,
    type_name: &'static str,
    summary: &'static str,
    params: &'static [ParamDoc],
    make: fn(P, Mat4, Vec2) -> Result<C, InvalidParam>,
) {
    registry.register::<dyn Camera>(
        ModuleInfo {
            type_name,
            summary,
            params,
        },
        move |params: &Params, ctx: &mut BuildContext<'_>| {
            let camera = make(
                params.parse()?,
                ctx.camera_to_render,
                ctx.resolution.as_vec2(),
            )
            .map_err(|e| e.at(params))?;
            Ok(Box::new(camera) as Box<dyn Camera>)
        },
    );
}

#[cfg(test)]
mod tests;
