//! # radiant-lights: built-in light modules
//!
//! Lights serve next-event estimation (the wavefront's NEE stage samples them
//! in batches) and report their emission when a BSDF-sampled ray hits them
//! (surface emitters) or leaves the scene (environment lights).

mod area;
mod delta;
mod directional;
mod emitted;
mod environment;
mod map_file;
mod params;
mod point;
mod rectangle;
mod sphere;
mod spot;

pub use area::AreaLight;
pub use directional::DirectionalLight;
pub use environment::EnvironmentLight;
pub use point::PointLight;
pub use spot::SpotLight;

use radiant_core::{BuildContext, Light, ModuleInfo, ParamDoc, ParamError, Params, Registry};

/// Registers every built-in light type.
pub fn register(registry: &mut Registry) {
    area::register(registry);
    directional::register(registry);
    environment::register(registry);
    point::register(registry);
    spot::register(registry);
}

/// Registers the light type `type_name`, built from its parameters by
/// `build`.
fn register_light<L: Light + 'static>(
    registry: &mut Registry,
    type_name: &'static str,
    summary: &'static str,
    params: &'static [ParamDoc],
    build: fn(&Params, &mut BuildContext<'_>) -> Result<L, ParamError>,
) {
    registry.register::<dyn Light>(
        ModuleInfo {
            type_name,
            summary,
            params,
        },
        move |params: &Params, ctx| {
            not_on_a_shape(type_name, ctx)?;
            Ok(Box::new(build(params, ctx)?) as Box<dyn Light>)
        },
    );
}

/// The error for a light that exists apart from any surface (a point, a
/// spot, a direction, the environment) written as a shape's `emitter`:
/// said before its own parameters are checked, which would otherwise ask
/// for a `position` the shape cannot give it.
fn not_on_a_shape(type_name: &str, ctx: &BuildContext<'_>) -> Result<(), ParamError> {
    match ctx.emitter_shape {
        Some(_) => Err(ParamError::new(format!(
            "a `{type_name}` light cannot be attached to a shape (it emits from no surface): \
             a shape's `emitter` must be a light that emits from the shape's surface \
             (the built-in one is `area`); put the `{type_name}` light under `lights:`"
        ))),
        None => Ok(()),
    }
}
