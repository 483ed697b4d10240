//! glTF materials as Radiant `principled` materials, and the textures they
//! read, written as the YAML the loader reads (named textures that the
//! material refers to).
//!
//! * Base colour: the factor, the texture, or where both are given their
//!   product (a `layered` texture with the factor over black through the
//!   texture as mask: 0 + (factor − 0) · texture).
//! * Metallic and roughness: the factors, or where a metallic-roughness
//!   texture is given (metalness in its blue channel, roughness in its
//!   green one, read raw) the factor times that channel. Principled reads
//!   a scalar texture as the mean of its three channels, so the channel is
//!   picked by a `layered` texture whose upper colour is 3 × factor in that
//!   channel and 0 in the others: mean(0, 3f·G, 0) = f·G.
//! * A normal texture wraps the material in `normal_map` (read raw).
//! * Each texture is an `image` texture where its image is a file beside
//!   the glTF file, else a `gltf_image` (see `image.rs`); its sampler's wrap
//!   mode (wrapS: Radiant has one for both axes) and magnification filter
//!   carry over. `KHR_texture_transform` wraps it in `uv_transform`.
//! * All textures of a material must read the same `TEXCOORD_n` set (a
//!   Radiant mesh has one set); the primitive's mesh is read with it.

use super::asset::Asset;
use super::{generated, list, quoted};
use crate::scene::Loader;
use crate::world::{MaterialRef, ModuleSpec};
use radiant_core::params::Location;
use std::path::Path;

/// A glTF material as Radiant sees it.
#[derive(Clone)]
pub(super) struct Material {
    /// The `principled` (or `normal_map`) material.
    pub(super) material: MaterialRef,
    /// The `area` emitter of an emissive material.
    pub(super) emitter: Option<ModuleSpec>,
    /// The `TEXCOORD_n` set its textures read.
    pub(super) tex_coord: u32,
}

/// `KHR_texture_transform`: uv' = T(offset) · R(rotation) · S(scale) · uv,
/// glTF's R turning (1, 0) towards (0, −1) by `rotation` radians.
#[derive(Clone, Copy, Debug, PartialEq)]
struct UvMap {
    offset: [f64; 2],
    rotation: f64,
    scale: [f64; 2],
}

/// One texture as a material reads it.
struct TextureUse<'a> {
    texture: gltf::Texture<'a>,
    tex_coord: u32,
    transform: Option<UvMap>,
}

impl<'a> TextureUse<'a> {
    /// A texture info (base colour, metallic-roughness).
    fn from_info(info: &gltf::texture::Info<'a>) -> Self {
        let transform = info.texture_transform();
        Self {
            texture: info.texture(),
            tex_coord: transform
                .as_ref()
                .and_then(|t| t.tex_coord())
                .unwrap_or(info.tex_coord()),
            transform: transform.map(|t| UvMap {
                offset: t.offset().map(f64::from),
                rotation: f64::from(t.rotation()),
                scale: t.scale().map(f64::from),
            }),
        }
    }

    /// A normal texture, whose `KHR_texture_transform` the `gltf` crate
    /// leaves as JSON.
    fn from_normal(normal: &gltf::material::NormalTexture<'a>, what: &str) -> Result<Self, String> {
        let mut used = Self {
            texture: normal.texture(),
            tex_coord: normal.tex_coord(),
            transform: None,
        };
        let Some(value) = normal.extension_value("KHR_texture_transform") else {
            return Ok(used);
        };
        let bad = |key: &str, expected: &str| {
            format!("{what}: its normal texture's KHR_texture_transform `{key}` must be {expected}")
        };
        let pair = |key: &str, default: [f64; 2]| match value.get(key) {
            None => Ok(default),
            Some(v) => v
                .as_array()
                .and_then(|a| match a.as_slice() {
                    [x, y] => Some([x.as_f64()?, y.as_f64()?]),
                    _ => None,
                })
                .ok_or_else(|| bad(key, "two numbers")),
        };
        let rotation = match value.get("rotation") {
            None => 0.0,
            Some(v) => v.as_f64().ok_or_else(|| bad("rotation", "a number"))?,
        };
        if let Some(v) = value.get("texCoord") {
            let set = v
                .as_u64()
                .and_then(|n| u32::try_from(n).ok())
                .ok_or_else(|| bad("texCoord", "a set index (0, 1, …)"))?;
            used.tex_coord = set;
        }
        used.transform = Some(UvMap {
            offset: pair("offset", [0.0, 0.0])?,
            rotation,
            scale: pair("scale", [1.0, 1.0])?,
        });
        Ok(used)
    }
}

impl Loader<'_> {
    /// The material (and emitter) of a glTF material: `principled` with its
    /// factors and textures, wrapped in `normal_map` where it has a normal
    /// texture.
    pub(super) fn gltf_material(
        &mut self,
        asset: &Asset,
        material: &gltf::Material<'_>,
        at: Option<Location>,
    ) -> Result<Material, crate::error::SceneError> {
        use crate::error::SceneError;
        let located = |message: String| SceneError::new(self.file, at, message);
        let label = match (material.index(), material.name()) {
            (Some(i), Some(n)) => format!("material {i} (`{n}`)"),
            (Some(i), None) => format!("material {i}"),
            (None, _) => "the default material".to_string(),
        };
        let what = format!("glTF file `{}`: {label}", asset.path.display());
        let pbr = material.pbr_metallic_roughness();
        let base_texture = pbr.base_color_texture().map(|i| TextureUse::from_info(&i));
        let mr_texture = pbr
            .metallic_roughness_texture()
            .map(|i| TextureUse::from_info(&i));
        let normal_texture = material
            .normal_texture()
            .map(|n| TextureUse::from_normal(&n, &what))
            .transpose()
            .map_err(located)?;
        let uses = [
            ("base colour", &base_texture),
            ("metallic-roughness", &mr_texture),
            ("normal", &normal_texture),
        ];
        let mut sets = uses
            .iter()
            .filter_map(|(name, u)| u.as_ref().map(|u| (*name, u.tex_coord)));
        let tex_coord = match sets.next() {
            None => 0,
            Some((first, set)) => {
                if let Some((other, other_set)) = sets.find(|(_, s)| *s != set) {
                    return Err(located(format!(
                        "{what} reads TEXCOORD_{set} for its {first} texture and \
                         TEXCOORD_{other_set} for its {other} texture; a Radiant mesh carries \
                         one set of texture coordinates, so a material's textures must share one"
                    )));
                }
                set
            }
        };
        let prefix = format!("<glTF {label} of {}", asset.path.display());

        let [r, g, b, _alpha] = pbr.base_color_factor().map(f64::from);
        let base_color = match &base_texture {
            None => list(&[r, g, b]),
            Some(used) => {
                let texture = self.gltf_texture(asset, used, false).map_err(located)?;
                if [r, g, b] == [1.0; 3] {
                    texture
                } else {
                    self.generated_texture(
                        asset,
                        format!("{prefix}: base colour>"),
                        &layered(&[r, g, b], &texture),
                    )?
                }
            }
        };
        let (metallic, roughness) = (
            f64::from(pbr.metallic_factor()),
            f64::from(pbr.roughness_factor()),
        );
        let (metallic, roughness) = match &mr_texture {
            None => (format!("{metallic:?}"), format!("{roughness:?}")),
            Some(used) => {
                let texture = self.gltf_texture(asset, used, true).map_err(located)?;
                (
                    self.generated_texture(
                        asset,
                        format!("{prefix}: metallic>"),
                        &layered(&[0.0, 0.0, 3.0 * metallic], &texture),
                    )?,
                    self.generated_texture(
                        asset,
                        format!("{prefix}: roughness>"),
                        &layered(&[0.0, 3.0 * roughness, 0.0], &texture),
                    )?,
                )
            }
        };
        let mut text = format!(
            "{{type: principled, base_color: {base_color}, metallic: {metallic}, roughness: {roughness}}}"
        );
        if let Some(used) = &normal_texture {
            let normals = self.gltf_texture(asset, used, true).map_err(located)?;
            text = format!("{{type: normal_map, normals: {normals}, material: {text}}}");
        }
        let node = generated(&asset.path, &text)?;
        let spec = ModuleSpec::from_node(&asset.path, &node, "material", &[])?;
        self.materials.push((format!("{prefix}>"), spec));
        let material_ref = MaterialRef(self.materials.len() as u32 - 1);
        let emissive = material.emissive_factor().map(f64::from);
        let emitter = if emissive.iter().any(|&e| e > 0.0) {
            let node = generated(
                &asset.path,
                &format!("{{type: area, radiance: {}}}", list(&emissive)),
            )?;
            Some(ModuleSpec::from_node(&asset.path, &node, "emitter", &[])?)
        } else {
            None
        };
        Ok(Material {
            material: material_ref,
            emitter,
            tex_coord,
        })
    }

    /// Defines (once) the texture named `name` as the YAML mapping `text`
    /// and returns its name, quoted for YAML.
    fn generated_texture(
        &mut self,
        asset: &Asset,
        name: String,
        text: &str,
    ) -> Result<String, crate::error::SceneError> {
        if !self.textures.iter().any(|(n, _)| *n == name) {
            let node = generated(&asset.path, text)?;
            let spec = ModuleSpec::from_node(&asset.path, &node, "texture", &[])?;
            self.textures.push((name.clone(), spec));
        }
        Ok(quoted(&name))
    }

    /// Defines the textures a material's texture use needs (its image,
    /// read raw for data, and its `KHR_texture_transform`) and returns the
    /// name to give the material, quoted for YAML.
    fn gltf_texture(
        &mut self,
        asset: &Asset,
        used: &TextureUse<'_>,
        raw: bool,
    ) -> Result<String, String> {
        use gltf::texture::{MagFilter, WrappingMode};
        let name = asset.path.display();
        let image = used.texture.source();
        let sampler = used.texture.sampler();
        let wrap = match sampler.wrap_s() {
            WrappingMode::ClampToEdge => "clamp",
            WrappingMode::MirroredRepeat => "mirror",
            WrappingMode::Repeat => "repeat",
        };
        let filter = match sampler.mag_filter() {
            Some(MagFilter::Nearest) => "nearest",
            _ => "bilinear",
        };
        let mut text = match image.source() {
            gltf::image::Source::Uri { uri, .. } if !uri.contains(':') => {
                let path = asset.path.parent().unwrap_or(Path::new(".")).join(uri);
                if !path.is_file() {
                    return Err(format!(
                        "glTF file `{name}`: image {} is the file `{uri}`, which cannot be read \
                         (looked for `{}`)",
                        image.index(),
                        path.display()
                    ));
                }
                format!(
                    "{{type: image, filename: {}",
                    quoted(&path.display().to_string())
                )
            }
            _ => format!(
                "{{type: gltf_image, filename: {}, image: {}",
                quoted(&asset.path.display().to_string()),
                image.index()
            ),
        };
        text.push_str(&format!(", raw: {raw}, wrap: {wrap}, filter: {filter}}}"));
        let image_name = format!(
            "<glTF image {} of {name}{}, {wrap}, {filter}>",
            image.index(),
            if raw { ", raw" } else { "" },
        );
        let image_quoted = self
            .generated_texture(asset, image_name.clone(), &text)
            .map_err(|e| e.to_string())?;
        let Some(map) = used.transform else {
            return Ok(image_quoted);
        };
        // Radiant's `uv_transform` turns counter-clockwise, (1, 0) towards
        // (0, 1): glTF's rotation by θ is Radiant's by −θ.
        let text = format!(
            "{{type: uv_transform, texture: {image_quoted}, scale: {}, rotate: {:?}, offset: {}}}",
            list(&map.scale),
            -map.rotation.to_degrees(),
            list(&map.offset)
        );
        let transformed = format!(
            "{}, scale {:?}, rotation {:?}, offset {:?}>",
            image_name.trim_end_matches('>'),
            map.scale,
            map.rotation,
            map.offset
        );
        self.generated_texture(asset, transformed, &text)
            .map_err(|e| e.to_string())
    }
}

/// A `layered` texture: `color` times `mask` (a texture name, quoted).
fn layered(color: &[f64; 3], mask: &str) -> String {
    format!(
        "{{type: layered, upper: {}, lower: [0, 0, 0], mask: {mask}}}",
        list(color)
    )
}
