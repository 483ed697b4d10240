//! # radiant-shaders: built-in shader (BSDF) modules
//!
//! In the wavefront, hits are sorted by material and each shader processes
//! its whole slice: sampling continuation directions and evaluating the BSDF
//! for next-event estimation.
//!
//! Shared maths: [`microfacet`] (GGX with visible-normal sampling),
//! `fresnel`, `lobes` (GGX reflection and the rough dielectric interface
//! used by several shaders), `half_vector` (the shader of `ward` and
//! `ashikhmin_shirley`), `perturb` (the normal-perturbing wrapper of
//! `normal_map` and `bump`), `inputs` (parameter helpers) and `metals`
//! (complex indices of refraction).
//!
//! GPU sides: each type's WGSL is `src/<type>.wgsl`, included in a kernel
//! as a library of that type's (`gpu`), so that `blend` can call any type;
//! `normal_map` and `bump` have none yet (they need tangent frames).
//!
//! Emissive surfaces are not a shader: they are declared with an `emitter`
//! (the `area` light) on the shape, so that next-event estimation can
//! sample them and multiple importance sampling can weight their hits;
//! an emission term on the BSDF would be invisible to light sampling.

mod ashikhmin_shirley;
mod blend;
mod bump;
mod conductor;
mod dielectric;
mod diffuse;
mod fresnel;
mod gpu;
mod half_vector;
mod inputs;
mod lobes;
mod metals;
pub mod microfacet;
mod normal_map;
mod perturb;
mod plastic;
mod principled;
mod rough_diffuse;
mod thin_dielectric;
mod ward;

pub use diffuse::Diffuse;

use radiant_core::{BuildContext, ModuleInfo, ParamDoc, ParamError, Params, Registry, Shader};

/// Registers every built-in shader type.
pub fn register(registry: &mut Registry) {
    diffuse::register(registry);
    rough_diffuse::register(registry);
    conductor::register(registry);
    dielectric::register(registry);
    thin_dielectric::register(registry);
    plastic::register(registry);
    principled::register(registry);
    ashikhmin_shirley::register(registry);
    ward::register(registry);
    blend::register(registry);
    normal_map::register(registry);
    bump::register(registry);
}

/// Registers the shader type `type_name`, built from its parameters by
/// `build`.
fn register_shader<S: Shader + 'static>(
    registry: &mut Registry,
    type_name: &'static str,
    summary: &'static str,
    params: &'static [ParamDoc],
    build: fn(&Params, &mut BuildContext<'_>) -> Result<S, ParamError>,
) {
    registry.register::<dyn Shader>(
        ModuleInfo {
            type_name,
            summary,
            params,
        },
        move |params: &Params, ctx| Ok(Box::new(build(params, ctx)?) as Box<dyn Shader>),
    );
}
