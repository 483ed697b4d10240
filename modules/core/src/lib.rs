//! # radiant-core: the module contract
//!
//! Radiant's engine and its plugin modules meet in this crate. It defines
//!
//! * one trait per module kind — [`Camera`], [`Light`], [`Filter`], [`Shader`],
//!   [`Sampler`], [`Texture`], [`Medium`], [`Phase`] — whose hot methods take *batches* (slices), so
//!   dynamic dispatch happens once per batch and the inner loops are plain code;
//! * the [`Registry`] through which built-in and outside modules are made
//!   known by their YAML `type` name, and [`Params`], the YAML parameters a
//!   module parses for itself with serde;
//! * the [`Effects`] a module declares, from which the engine decides which
//!   light-transport features a scene needs;
//! * the optional GPU side of a module ([`GpuModule`]): WGSL with a fixed
//!   signature per kind and parameters packed as words;
//! * the small shared maths every module uses: [`Frame`], sampling warps in
//!   [`warp`], stateless hashing in [`hash`], piecewise-constant
//!   distributions in [`distribution`];
//! * the helpers every shader author needs, in [`shading`] (range-checked
//!   texture inputs such as [`fraction`], [`reflection_sample`]).
//!
//! Data flow: the engine parses a scene, looks up each `type` in the
//! [`Registry`], hands the module its [`Params`] and a [`BuildContext`], and
//! gets back a boxed trait object that it calls once per batch while rendering.

pub mod build;
pub mod camera;
pub mod color;
pub mod distribution;
pub mod effects;
pub mod exr_file;
pub mod filter;
pub mod frame;
pub mod gpu;
pub mod hash;
pub mod input_file;
pub mod light;
pub mod light_bounds;
pub mod medium;
pub mod memory;
pub mod params;
pub mod registry;
pub mod sampler;
pub mod shader;
pub mod shading;
pub mod texture;
pub mod warp;

pub use build::{BoundingSphere, BuildContext, EmitterShape, MaterialSource};
pub use camera::{Camera, CameraRayPdf, CameraRays, Importance, LensSample};
pub use color::{Rgb, luminance};
pub use effects::Effects;
pub use filter::{Filter, FilterSampler};
pub use frame::Frame;
pub use gpu::{GpuLibrary, GpuModule, GpuParams};
pub use light::{
    Emission, EmissionKind, EmissionPdf, EmissionSample, EmittedRay, EmitterEval, EmitterHit,
    Light, LightSample,
};
pub use light_bounds::{BoundsLanes, LightBounds, PreparedBounds};
pub use medium::{Coefficients, Medium, Phase, Profile};
pub use params::{Color, Numbers, ParamError, Params, TextureInput};
pub use registry::{ModuleInfo, ModuleKind, ParamDoc, Registry};
pub use sampler::{ONE_MINUS_EPSILON, SampleId, Sampler};
pub use shader::{
    BsdfEval, BsdfSample, Pooled, Scratch, ShadeContext, Shader, SurfaceBatch, estimate_albedo,
};
pub use shading::{fraction, reflection_sample};
pub use texture::{Texture, TextureId, TextureRef, TextureTable};

pub use glam;
