//! # Radiant
//!
//! A data-oriented, physically based path-tracing scene engine. The folders
//! follow the data:
//!
//! 1. [`scene`] reads a YAML scene (and its OBJ meshes) into a [`world`]: a
//!    `hecs` ECS world of plain-data components.
//! 2. [`extract`] turns the world into flat structure-of-arrays render data,
//!    builds the module instances through the [`Registry`], and computes the
//!    scene's effect set.
//! 3. [`accel`] builds the BVH (obvhs) and intersects rays robustly.
//! 4. [`integrators`] hold the wavefront path tracer: generate → trace →
//!    shade by material → next-event estimation → shadow rays → splat.
//! 5. [`backend`] runs the integrator over tiles on all cores.
//! 6. [`film`] accumulates filtered samples and writes PNG/EXR atomically.
//!
//! With the default `cli` feature, [`cli::run`] is the whole `radiant`
//! command line for any registry, so a module crate's binary is
//! `radiant::cli::run(registry)` (see `tests/outside-module/src/main.rs`),
//! and [`accuracy`] is the accuracy tool behind `radiant accuracy`.
//!
//! ```no_run
//! let registry = radiant::builtin_registry();
//! let scene = radiant::scene::load("scenes/cornell-box.yaml").unwrap();
//! let render = radiant::extract::extract(&scene, &registry, &Default::default()).unwrap();
//! let image = radiant::backend::cpu::render(&render, &radiant::backend::cpu::Progress::none());
//! radiant::film::output::write("cornell.exr", &image.image).unwrap();
//! ```

// The command line's modules name the library `radiant::…`, as they did
// when they were the binary's own; this keeps those paths valid inside it.
extern crate self as radiant;

pub mod accel;
#[cfg(feature = "cli")]
pub mod accuracy;
pub mod backend;
#[cfg(feature = "cli")]
pub mod cli;
pub mod compare;
pub mod error;
pub mod extract;
pub mod farm;
pub mod film;
pub mod integrators;
pub mod out_of_memory;
pub mod scene;
pub mod settings;
pub mod world;

pub use radiant_core as core;
pub use radiant_core::Registry;

/// A registry holding every built-in module, registered through the same
/// public `register` functions an outside module crate provides.
pub fn builtin_registry() -> Registry {
    let mut registry = Registry::new();
    radiant_cameras::register(&mut registry);
    radiant_lights::register(&mut registry);
    radiant_filters::register(&mut registry);
    radiant_shaders::register(&mut registry);
    radiant_samplers::register(&mut registry);
    radiant_textures::register(&mut registry);
    radiant_media::register(&mut registry);
    scene::register_gltf_image(&mut registry);
    integrators::module::register(&mut registry);
    integrators::bdpt::register(&mut registry);
    integrators::mlt::register(&mut registry);
    registry
}
