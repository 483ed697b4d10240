//! Textures: functions of surface (u, v) that shaders read in batches.
//!
//! Scenes reference textures by name or give a value inline; inline values
//! become constant entries of the [`TextureTable`] and are looked up without
//! any dynamic dispatch.

use crate::{Effects, Rgb};
use glam::Vec2;
use std::sync::Arc;

/// A texture module: evaluates colours for a batch of (u, v) coordinates.
pub trait Texture: Send + Sync {
    /// Writes the texture's value at `uv[i]` into `out[i]`, for every `i`
    /// (linear RGB; `uv` may lie outside [0, 1]², where a texture repeats
    /// or clamps as it documents). `out` is not cleared between batches.
    fn eval(&self, uv: &[Vec2], out: &mut [Rgb]);

    /// The single value of a texture that does not vary, if it is one.
    fn constant(&self) -> Option<Rgb> {
        None
    }

    /// The mean value over the unit square, used for power estimates.
    fn mean(&self) -> Rgb;

    /// The texture's GPU side (see [`crate::gpu`]), `None` where the type has
    /// none.
    fn gpu(&self) -> Option<crate::GpuModule> {
        None
    }
    /// Effects this texture needs.
    fn effects(&self) -> Effects {
        Effects::TEXTURES
    }
}

/// Index of a texture in the scene's [`TextureTable`].
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub struct TextureId(pub u32);

/// A texture as another module holds it (e.g. the layers of a `layered`
/// texture): a constant, or a shared module instance.
#[derive(Clone)]
pub enum TextureRef {
    /// A value that does not vary.
    Constant(Rgb),
    /// A texture module, shared with the scene's [`TextureTable`].
    Module(Arc<dyn Texture>),
}

impl TextureRef {
    /// Writes the texture's value at `uv[i]` into `out[i]`.
    #[inline]
    pub fn eval(&self, uv: &[Vec2], out: &mut [Rgb]) {
        match self {
            TextureRef::Constant(c) => out[..uv.len()].fill(*c),
            TextureRef::Module(t) => t.eval(uv, &mut out[..uv.len()]),
        }
    }

    /// The mean value over the unit square.
    pub fn mean(&self) -> Rgb {
        match self {
            TextureRef::Constant(c) => *c,
            TextureRef::Module(t) => t.mean(),
        }
    }

    /// Effects the texture needs.
    pub fn effects(&self) -> Effects {
        match self {
            TextureRef::Constant(_) => Effects::empty(),
            TextureRef::Module(t) => t.effects(),
        }
    }
}

/// All textures of a scene.
///
/// Entries are added while modules are built; when the engine rebuilds a
/// module for a new frame (an animated parameter changed), it releases the
/// entries the old instance added ([`TextureTable::take_added`],
/// [`TextureTable::release`]) so that their slots are reused and the table
/// does not grow from frame to frame.
#[derive(Default)]
pub struct TextureTable {
    entries: Vec<TextureRef>,
    /// Released slots, reused first.
    free: Vec<u32>,
    /// Ids handed out since the last [`TextureTable::take_added`].
    added: Vec<TextureId>,
}

impl TextureTable {
    fn push(&mut self, entry: TextureRef) -> TextureId {
        let id = match self.free.pop() {
            Some(i) => {
                self.entries[i as usize] = entry;
                TextureId(i)
            }
            None => {
                self.entries.push(entry);
                TextureId(self.entries.len() as u32 - 1)
            }
        };
        self.added.push(id);
        id
    }

    fn entry(texture: Box<dyn Texture>) -> TextureRef {
        match texture.constant() {
            Some(c) => TextureRef::Constant(c),
            None => TextureRef::Module(Arc::from(texture)),
        }
    }

    /// Adds an inline constant value and returns its id.
    pub fn add_constant(&mut self, value: Rgb) -> TextureId {
        self.push(TextureRef::Constant(value))
    }

    /// Adds a texture module instance and returns its id.
    pub fn add(&mut self, texture: Box<dyn Texture>) -> TextureId {
        self.push(Self::entry(texture))
    }

    /// Puts `texture` in place of texture `id` (a named texture rebuilt for
    /// a new frame keeps its id).
    pub fn replace(&mut self, id: TextureId, texture: Box<dyn Texture>) {
        self.entries[id.0 as usize] = Self::entry(texture);
    }

    /// The ids added since the last call (the entries a module added while
    /// it was built).
    pub fn take_added(&mut self) -> Vec<TextureId> {
        std::mem::take(&mut self.added)
    }

    /// Frees the entries `ids` for reuse; nothing may read them afterwards.
    pub fn release(&mut self, ids: &[TextureId]) {
        for id in ids {
            self.entries[id.0 as usize] = TextureRef::Constant(Rgb::ZERO);
            self.free.push(id.0);
        }
    }

    /// Evaluates texture `id` at every `uv[i]` into `out[i]`.
    #[inline]
    pub fn eval(&self, id: TextureId, uv: &[Vec2], out: &mut [Rgb]) {
        self.entries[id.0 as usize].eval(uv, out);
    }

    /// A handle on texture `id` that another module can keep (textures
    /// built from other textures hold their inputs this way).
    pub fn get(&self, id: TextureId) -> TextureRef {
        self.entries[id.0 as usize].clone()
    }

    /// The constant value of texture `id`, if it does not vary.
    pub fn constant(&self, id: TextureId) -> Option<Rgb> {
        match &self.entries[id.0 as usize] {
            TextureRef::Constant(c) => Some(*c),
            TextureRef::Module(_) => None,
        }
    }

    /// The mean value of texture `id` over the unit square.
    pub fn mean(&self, id: TextureId) -> Rgb {
        self.entries[id.0 as usize].mean()
    }

    /// Effects needed by texture `id`.
    pub fn effects(&self, id: TextureId) -> Effects {
        self.entries[id.0 as usize].effects()
    }

    /// Number of texture slots, constants and released ones included.
    pub fn len(&self) -> usize {
        self.entries.len()
    }

    /// Whether the table holds no texture.
    pub fn is_empty(&self) -> bool {
        self.entries.is_empty()
    }
}
