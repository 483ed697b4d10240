//! The scene as an ECS world (hecs) of plain-data components, and the
//! systems that animate it.
//!
//! The scene loader spawns one entity per shape, light and camera with
//! their components ([`components`]) and keeps what is not an entity —
//! settings, the filter and sampler, named textures and materials, the
//! timeline — beside the world in a [`Scene`]. Systems ([`systems`]) are
//! plain functions over the world: each frame, [`systems::animate`]
//! evaluates the animation tracks ([`animation`]) and writes the
//! transforms, poses, camera, module parameters and deforming meshes that
//! extract reads. Module parameters stay unparsed ([`ModuleSpec`]) until
//! extract, because modules are built in render space.

pub mod animation;
mod components;
mod resources;
pub mod systems;

pub use animation::{Interpolation, Key, Keyable, Track, TrackError, TransformTracks, Trs, slerp};
pub use components::{
    Animation, BaseTransform, CameraAnimation, CameraMotion, CameraPose, ClosingMesh, EmitterSpec,
    FlippedNormals, Geometry, InstanceSpec, Instances, LightSpec, MaterialRef, MeshData,
    MeshRepairs, MeshSequence, ModuleSpec, Name, ParamStep, ParamTrack, Pose, Transform,
};
pub use resources::{FrameTimes, Scene, Timeline};
