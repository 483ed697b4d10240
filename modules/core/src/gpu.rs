//! The GPU side of modules: WGSL code with a fixed signature per kind and
//! parameters packed into 32-bit words.
//!
//! A module instance that can run on the GPU backend answers its trait's
//! `gpu()` with a [`GpuModule`]: the WGSL of its type, the identifier its
//! functions are named with, the shared WGSL libraries it calls, and its
//! parameters as words. The backend assembles each scene's kernel from the
//! code of exactly the module types the scene uses (each type's code once,
//! each library once), puts every instance's words into one parameter
//! buffer and hands a function its instance's offset `p` into it, from
//! which it reads with `param_f32(p + i)`, `param_u32(p + i)` and
//! `param_vec3(p + i)`.
//!
//! The signatures, per kind (`T` is [`GpuModule::ident`]):
//!
//! ```text
//! shader:  fn bsdf_sample_T(p: u32, s: ShadingPoint, u: vec3f) -> BsdfSample
//!          fn bsdf_eval_T(p: u32, s: ShadingPoint, wi: vec3f) -> BsdfEval
//! light:   fn light_sample_T(p: u32, r: vec3f, u: vec2f) -> LightSample
//!          fn light_hit_T(p: u32, h: EmitterHit) -> EmitterEval      (surface lights)
//!          fn light_escaped_T(p: u32, dir: vec3f) -> EmitterEval     (environment lights)
//! camera:  fn camera_ray_T(p: u32, film: vec2f, lens: vec2f) -> CameraRay
//! sampler: fn sample_1d_T(p: u32, pixel: u32, index: u32, dim: u32) -> f32
//!          fn sample_2d_T(p: u32, pixel: u32, index: u32, dim: u32) -> vec2f
//!                                           (optional: else two 1D values)
//! texture: fn texture_T(p: u32, uv: vec2f) -> vec3f
//! medium:  fn medium_flight_T(p: u32, o: vec3f, d: vec3f, t_max: f32, beta: vec3f,
//!                             u: vec2f, rng: ptr<function, Stream>) -> MediumFlight
//!          fn medium_transmittance_T(p: u32, o: vec3f, d: vec3f, t_max: f32,
//!                                    rng: ptr<function, Stream>) -> vec3f
//! phase:   fn phase_sample_T(p: u32, wo: vec3f, u: vec2f) -> BsdfSample
//!          fn phase_eval_T(p: u32, wo: vec3f, wi: vec3f) -> BsdfEval
//! ```
//!
//! with the structures of the Rust traits (directions in the local shading
//! frame for shaders, in render space elsewhere); shaders read their
//! textures with `texture_eval(id, uv)`. A sampler whose `fill_2d` is not
//! two `fill_1d` values (a stratified 2D pattern) defines `sample_2d_T` as
//! well, so that the GPU draws the same pairs. Filters need no WGSL: the backend
//! samples any filter from its tabulated distribution
//! ([`FilterSampler`](crate::FilterSampler)).

use crate::{Rgb, TextureId};
use glam::Vec3;
use std::borrow::Cow;

/// The WGSL every kernel starts with: the structures of the signatures
/// above (`ShadingPoint`, `BsdfSample`, `BsdfEval`, `LightSample`,
/// `EmitterHit`, `EmitterEval`, `CameraRay`), the parameter readers, and
/// the warps of [`crate::warp`]. The kernel declares the parameter buffer
/// `module_params` that the readers index.
pub const PRELUDE: &str = include_str!("gpu/prelude.wgsl");

/// The media's shared WGSL ([`MEDIUM`]'s source): `MediumFlight`, the
/// hashed `Stream`, the coefficients' readers and the homogeneous free
/// flight of [`crate::medium::free_flight`]. Every medium type requires
/// it; the backend includes it in every kernel with media.
pub const MEDIUM: GpuLibrary = GpuLibrary {
    name: "core::medium",
    wgsl: include_str!("gpu/medium.wgsl"),
    requires: &[],
};

/// WGSL shared by several module types (microfacet maths, Fresnel terms),
/// included once in a kernel that any of them is in.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub struct GpuLibrary {
    /// Unique name (a crate-qualified one, such as `shaders::microfacet`).
    pub name: &'static str,
    /// The WGSL source.
    pub wgsl: &'static str,
    /// Libraries this one calls (included before it).
    pub requires: &'static [GpuLibrary],
}

/// The GPU side of one module instance.
#[derive(Debug, Clone, PartialEq)]
pub struct GpuModule {
    /// The identifier in the type's function names (`bsdf_sample_T`): a
    /// WGSL identifier, unique among the types of its kind.
    pub ident: Cow<'static, str>,
    /// The type's WGSL: its kind's functions for `ident`.
    pub wgsl: Cow<'static, str>,
    /// Libraries its code calls.
    pub requires: &'static [GpuLibrary],
    /// The instance's parameters.
    pub params: GpuParams,
}

impl GpuModule {
    /// The GPU side of an instance of a built-in type whose code and
    /// identifier are static.
    pub fn new(ident: &'static str, wgsl: &'static str, params: GpuParams) -> Self {
        Self {
            ident: Cow::Borrowed(ident),
            wgsl: Cow::Borrowed(wgsl),
            requires: &[],
            params,
        }
    }

    /// The same module, calling `libraries`.
    pub fn with_libraries(self, libraries: &'static [GpuLibrary]) -> Self {
        Self {
            requires: libraries,
            ..self
        }
    }
}

/// A module instance's parameters as 32-bit words, in the order its WGSL
/// reads them.
#[derive(Debug, Clone, Default, PartialEq, Eq)]
pub struct GpuParams {
    words: Vec<u32>,
}

impl GpuParams {
    /// No parameters yet.
    pub fn new() -> Self {
        Self::default()
    }

    /// Appends a float (read with `param_f32`).
    pub fn f32(mut self, v: f32) -> Self {
        self.words.push(v.to_bits());
        self
    }

    /// Appends an unsigned integer (read with `param_u32`).
    pub fn u32(mut self, v: u32) -> Self {
        self.words.push(v);
        self
    }

    /// Appends three floats (read with `param_vec3`).
    pub fn vec3(self, v: Vec3) -> Self {
        self.f32(v.x).f32(v.y).f32(v.z)
    }

    /// Appends a colour (three floats).
    pub fn rgb(self, c: Rgb) -> Self {
        self.vec3(c)
    }

    /// Appends a texture reference (read with `param_u32`, passed to
    /// `texture_eval`).
    pub fn texture(self, id: TextureId) -> Self {
        self.u32(id.0)
    }

    /// Appends every float of `values`.
    pub fn f32s(mut self, values: impl IntoIterator<Item = f32>) -> Self {
        self.words.extend(values.into_iter().map(f32::to_bits));
        self
    }

    /// Appends the words of `other`.
    pub fn append(mut self, other: &GpuParams) -> Self {
        self.words.extend_from_slice(&other.words);
        self
    }

    /// The words.
    pub fn words(&self) -> &[u32] {
        &self.words
    }

    /// Number of words.
    pub fn len(&self) -> usize {
        self.words.len()
    }

    /// Whether there are none.
    pub fn is_empty(&self) -> bool {
        self.words.is_empty()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn words_are_appended_in_order_with_float_bits() {
        let p = GpuParams::new()
            .f32(1.5)
            .u32(7)
            .vec3(Vec3::new(1.0, 2.0, 3.0))
            .texture(TextureId(4));
        assert_eq!(
            p.words(),
            &[
                1.5f32.to_bits(),
                7,
                1.0f32.to_bits(),
                2.0f32.to_bits(),
                3.0f32.to_bits(),
                4
            ]
        );
        assert_eq!(p.len(), 6);
    }
}
