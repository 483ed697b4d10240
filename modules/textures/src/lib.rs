//! # radiant-textures: built-in texture modules
//!
//! Textures are read by shaders in batches through the scene's
//! [`TextureTable`](radiant_core::TextureTable). `constant` and `image`
//! are leaves; `checkerboard`, `layered` and `uv_transform` are built from
//! other textures (inline values or names defined earlier under
//! `textures:`), which they hold as [`TextureRef`](radiant_core::TextureRef)s
//! and evaluate chunk by chunk on the stack (`compose`). Image files are
//! decoded once at build time (`load`, `srgb`) and looked up with a wrap
//! mode (`wrap`).

mod bitmap;
mod checkerboard;
mod compose;
mod constant;
mod layered;
mod load;
mod srgb;
mod uv_transform;
mod wrap;

pub use bitmap::{Filtering, ImageTexture};
pub use checkerboard::Checkerboard;
pub use compose::Child;
pub use constant::Constant;
pub use layered::Layered;
pub use load::{LoadError, Texels, load, load_bytes, load_image};
pub use srgb::{linear_to_srgb, srgb_to_linear};
pub use uv_transform::UvTransform;
pub use wrap::WrapMode;

use radiant_core::Registry;

/// Registers every built-in texture type.
pub fn register(registry: &mut Registry) {
    constant::register(registry);
    bitmap::register(registry);
    checkerboard::register(registry);
    layered::register(registry);
    uv_transform::register(registry);
}

#[cfg(test)]
mod tests;
