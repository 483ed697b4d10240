//! The scene as an ECS world (hecs) of plain-data components.
//!
//! The scene loader spawns one entity per shape, light and camera; systems
//! (plain functions over the world) and the extract step read them. Module
//! parameters stay unparsed ([`ModuleSpec`]) until extract, because modules
//! are built in render space, which depends on the camera.

mod animation;
mod components;

pub use animation::{Interpolation, Key, Keyable, Track, TrackError, TransformTracks, Trs, slerp};
pub use components::{
    CameraPose, EmitterSpec, FlippedNormals, Geometry, LightSpec, MaterialRef, MeshData,
    MeshRepairs, ModuleSpec, Name, Transform,
};
