//! The `image` texture: an image file looked up with bilinear (or nearest)
//! filtering and a wrap mode.
//!
//! Texture space is Mitsuba 3's: (u, v) = (0, 0) is the image's top-left
//! corner, u runs to the right and v down the image; texel (i, j) of a
//! w × h image, row j counted from the top, has its centre at
//! ((i + ½)/w, (j + ½)/h). (Meshes read from OBJ files store 1 − v, as
//! Mitsuba's loader does, so an image laid out for OBJ's bottom-up v
//! appears upright on them.)
//!
//! No mipmaps: the integrator does not track ray footprints, so lookups
//! are point samples of the bilinear reconstruction. A minified texture is
//! therefore noisy at low sample counts, but the pixel filter integrates
//! it, and the render converges to the correctly filtered image (mipmaps
//! would lower that noise at the price of a blur bias).

use crate::load::{LoadError, Texels, load};
use crate::wrap::WrapMode;
use foldhash::HashMap;
use radiant_core::glam::Vec2;
use radiant_core::{
    BuildContext, GpuModule, GpuParams, ModuleInfo, ParamDoc, ParamError, Params, Registry, Rgb,
    Texture,
};
use serde::Deserialize;
use std::sync::OnceLock;

/// How lookups between texel centres are reconstructed.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Filtering {
    /// Bilinear interpolation of the four nearest texels.
    #[default]
    Bilinear,
    /// The texel the point falls in.
    Nearest,
}

/// An image texture.
#[derive(Debug, Clone, PartialEq)]
pub struct ImageTexture {
    texels: Texels,
    filtering: Filtering,
    wrap: WrapMode,
    mean: Rgb,
    /// The GPU parameters, made on first use.
    gpu: GpuCache,
}

/// Parameters made once and kept with the texture they were made from;
/// every cache equals every other (a texture's equality is its data's).
#[derive(Debug, Clone, Default)]
struct GpuCache(OnceLock<GpuParams>);

impl PartialEq for GpuCache {
    fn eq(&self, _: &Self) -> bool {
        true
    }
}

/// Most distinct channel values a palette holds (8-bit indices).
const PALETTE: usize = 256;

impl ImageTexture {
    /// A texture over `texels` (at least one texel).
    pub fn new(texels: Texels, filtering: Filtering, wrap: WrapMode) -> Self {
        let sum = texels.data.iter().fold([0.0f64; 3], |s, t| {
            [s[0] + t.x as f64, s[1] + t.y as f64, s[2] + t.z as f64]
        });
        let n = texels.data.len().max(1) as f64;
        let mean = Rgb::new(
            (sum[0] / n) as f32,
            (sum[1] / n) as f32,
            (sum[2] / n) as f32,
        );
        Self {
            texels,
            filtering,
            wrap,
            mean,
            gpu: GpuCache::default(),
        }
    }

    /// The words of `image.wgsl` (see its header): size, filtering, wrap
    /// mode, then the texels — as indices into a palette of the distinct
    /// channel values where there are at most 256 (every 8-bit image, sRGB
    /// or raw: one word per texel, the values exactly those of the Rust
    /// side), else as three floats each.
    fn gpu_params(&self) -> &GpuParams {
        self.gpu.0.get_or_init(|| {
            let t = &self.texels;
            let head = GpuParams::new()
                .u32(t.width)
                .u32(t.height)
                .u32(match self.filtering {
                    Filtering::Bilinear => 0,
                    Filtering::Nearest => 1,
                })
                .u32(match self.wrap {
                    WrapMode::Repeat => 0,
                    WrapMode::Clamp => 1,
                    WrapMode::Mirror => 2,
                });
            match palette(&t.data) {
                Some((values, index)) if t.data.len() > values.len() => {
                    let i = |x: f32| index[&x.to_bits()] as u32;
                    t.data
                        .iter()
                        .fold(head.u32(values.len() as u32).f32s(values), |params, c| {
                            params.u32(i(c.x) | (i(c.y) << 8) | (i(c.z) << 16))
                        })
                }
                _ => head.u32(0).f32s(t.data.iter().flat_map(|c| c.to_array())),
            }
        })
    }

    /// The index in the texels of texel (`x`, `y`), wrapped.
    #[inline]
    fn index(&self, x: i64, y: i64) -> usize {
        let (w, h) = (self.texels.width as i64, self.texels.height as i64);
        let i = self.wrap.apply(x, w);
        let j = self.wrap.apply(y, h);
        j * w as usize + i
    }

    /// Continuous texel coordinates of `uv`, rows from the top, kept
    /// finite and far from i64's limits so that the neighbour indices
    /// cannot overflow.
    #[inline]
    fn coordinates(&self, uv: Vec2) -> (f32, f32) {
        (
            texel_coordinate(uv.x * self.texels.width as f32),
            texel_coordinate(uv.y * self.texels.height as f32),
        )
    }

    /// The texels a bilinear lookup at `uv` blends and its weights.
    #[inline]
    fn blend_at(&self, uv: Vec2) -> Blend {
        let (x, y) = self.coordinates(uv);
        let (x, y) = (x - 0.5, y - 0.5);
        let (x0, y0) = (x.floor(), y.floor());
        let (i, j) = (x0 as i64, y0 as i64);
        Blend {
            texels: [
                self.index(i, j),
                self.index(i + 1, j),
                self.index(i, j + 1),
                self.index(i + 1, j + 1),
            ],
            f: Vec2::new(x - x0, y - y0),
        }
    }

    /// The bilinear blend `b` of the texels.
    #[inline]
    fn blend(&self, b: &Blend) -> Rgb {
        let t = |k: usize| self.texels.data[b.texels[k]];
        let top = t(0).lerp(t(1), b.f.x);
        let bottom = t(2).lerp(t(3), b.f.x);
        top.lerp(bottom, b.f.y)
    }
}

/// A bilinear lookup: the indices of the texels at its four corners
/// (top left, top right, bottom left, bottom right) and its place `f`
/// between them.
#[derive(Clone, Copy, Default)]
struct Blend {
    texels: [usize; 4],
    f: Vec2,
}

/// Lookups that [`ImageTexture::eval`] takes through its stages together.
const CHUNK: usize = 32;

/// Clamps a continuous texel coordinate to ±2⁴⁰ (NaN reads as 0): beyond
/// that an `f32` has no fractional bits left, so no lookup changes.
#[inline]
fn texel_coordinate(c: f32) -> f32 {
    const LIMIT: f32 = (1u64 << 40) as f32;
    if c.is_nan() {
        0.0
    } else {
        c.clamp(-LIMIT, LIMIT)
    }
}

/// The distinct channel values of `data` (by bits) and each one's index,
/// if there are at most [`PALETTE`].
fn palette(data: &[Rgb]) -> Option<(Vec<f32>, HashMap<u32, u8>)> {
    let mut values = Vec::new();
    let mut index = HashMap::default();
    for c in data.iter().flat_map(|c| c.to_array()) {
        if let std::collections::hash_map::Entry::Vacant(e) = index.entry(c.to_bits()) {
            if values.len() == PALETTE {
                return None;
            }
            e.insert(values.len() as u8);
            values.push(c);
        }
    }
    Some((values, index))
}

impl Texture for ImageTexture {
    /// Bilinear lookups go in two stages per chunk of [`CHUNK`]: first
    /// where each one reads, then the reads. The texels of a large image
    /// are mostly not in cache; with the addresses known beforehand, the
    /// short loop of reads has many of those misses in flight at once.
    fn eval(&self, uv: &[Vec2], out: &mut [Rgb]) {
        match self.filtering {
            Filtering::Nearest => {
                for (o, p) in out.iter_mut().zip(uv) {
                    let (x, y) = self.coordinates(*p);
                    *o = self.texels.data[self.index(x.floor() as i64, y.floor() as i64)];
                }
            }
            Filtering::Bilinear => {
                for (uv, out) in uv.chunks(CHUNK).zip(out.chunks_mut(CHUNK)) {
                    let mut blends = [Blend::default(); CHUNK];
                    for (b, p) in blends.iter_mut().zip(uv) {
                        *b = self.blend_at(*p);
                    }
                    for (o, b) in out.iter_mut().zip(&blends) {
                        *o = self.blend(b);
                    }
                }
            }
        }
    }

    fn mean(&self) -> Rgb {
        self.mean
    }

    fn gpu(&self) -> Option<GpuModule> {
        Some(GpuModule::new(
            "image",
            include_str!("image.wgsl"),
            self.gpu_params().clone(),
        ))
    }
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub(crate) struct ImageParams {
    filename: String,
    #[serde(default)]
    raw: bool,
    #[serde(default)]
    filter: Filtering,
    #[serde(default)]
    wrap: WrapMode,
}

pub(crate) const DOCS: &[ParamDoc] = &[
    ParamDoc {
        name: "filename",
        ty: "path (PNG, JPEG, EXR, HDR)",
        default: "required",
        doc: "The image, relative to the scene file.",
    },
    ParamDoc {
        name: "raw",
        ty: "bool",
        default: "false",
        doc: "Data, not colour: skip the sRGB decoding of 8/16-bit images (EXR and HDR are always linear).",
    },
    ParamDoc {
        name: "filter",
        ty: "bilinear | nearest",
        default: "bilinear",
        doc: "Reconstruction between texel centres (no mipmaps: the pixel filter integrates minification).",
    },
    ParamDoc {
        name: "wrap",
        ty: "repeat | clamp | mirror",
        default: "repeat",
        doc: "Lookups outside [0, 1]²: tile, extend the border, or tile mirrored.",
    },
];

pub(crate) fn register(registry: &mut Registry) {
    registry.register::<dyn Texture>(
        ModuleInfo {
            type_name: "image",
            summary: "Image file with bilinear filtering; (0, 0) is the top-left corner (Mitsuba 3).",
            params: DOCS,
        },
        |params: &Params, ctx: &mut BuildContext<'_>| {
            let p: ImageParams = params.parse()?;
            let path = ctx.scene_dir.join(&p.filename);
            let texels = load(&path, p.raw).map_err(|e| ParamError {
                message: match e {
                    LoadError::NonFinite { .. } => e.to_string(),
                    _ => format!("{e}; expected a readable PNG, JPEG, EXR or HDR file"),
                },
                location: params.location_of("filename"),
            })?;
            Ok(Box::new(ImageTexture::new(texels, p.filter, p.wrap)) as Box<dyn Texture>)
        },
    );
}
