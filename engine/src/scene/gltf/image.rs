//! The `gltf_image` texture: an image embedded in a glTF file (a `data:`
//! URI, or a buffer view of a `.glb`'s binary chunk or of another buffer).
//!
//! A glTF material whose image is embedded gets a `gltf_image` texture
//! naming the glTF file and the image's index; when the scene is
//! extracted, the texture opens the file again (checking its buffers as
//! the mesh reader does), takes the image's encoded bytes and decodes them
//! as the `image` texture decodes a file (sRGB unless `raw`). Images that
//! are files beside the glTF file stay `image` textures. The module is
//! registered with the built-in ones, so a scene may also name an embedded
//! image itself.

use super::asset::Asset;
use radiant_core::{BuildContext, ModuleInfo, ParamDoc, ParamError, Params, Registry, Texture};
use radiant_textures::{Filtering, ImageTexture, WrapMode, load_bytes};
use serde::Deserialize;

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct GltfImageParams {
    filename: String,
    image: usize,
    #[serde(default)]
    raw: bool,
    #[serde(default)]
    filter: Filtering,
    #[serde(default)]
    wrap: WrapMode,
}

const DOCS: &[ParamDoc] = &[
    ParamDoc {
        name: "filename",
        ty: "path (.gltf or .glb)",
        default: "required",
        doc: "The glTF file holding the image, relative to the scene file.",
    },
    ParamDoc {
        name: "image",
        ty: "integer ≥ 0",
        default: "required",
        doc: "The index of the image in the file's `images` (PNG or JPEG, embedded or not).",
    },
    ParamDoc {
        name: "raw",
        ty: "bool",
        default: "false",
        doc: "Data, not colour: skip the sRGB decoding.",
    },
    ParamDoc {
        name: "filter",
        ty: "bilinear | nearest",
        default: "bilinear",
        doc: "Reconstruction between texel centres, as the `image` texture's.",
    },
    ParamDoc {
        name: "wrap",
        ty: "repeat | clamp | mirror",
        default: "repeat",
        doc: "Lookups outside [0, 1]², as the `image` texture's.",
    },
];

/// Registers the `gltf_image` texture.
pub fn register(registry: &mut Registry) {
    registry.register::<dyn Texture>(
        ModuleInfo {
            type_name: "gltf_image",
            summary: "An image of a glTF file, embedded in it or not (what glTF materials' embedded images become).",
            params: DOCS,
        },
        |params: &Params, ctx: &mut BuildContext<'_>| {
            let p: GltfImageParams = params.parse()?;
            let at = |key: &str, message: String| ParamError {
                message,
                location: params.location_of(key),
            };
            let path = ctx.scene_dir.join(&p.filename);
            let asset = Asset::open(&path).map_err(|e| at("filename", e))?;
            let bytes = asset.image_bytes(p.image).map_err(|e| at("image", e))?;
            let origin = path.with_file_name(format!(
                "{}#image{}",
                path.file_name().map_or_else(
                    || p.filename.clone(),
                    |n| n.to_string_lossy().into_owned()
                ),
                p.image
            ));
            let texels = load_bytes(&bytes, &origin, p.raw).map_err(|e| at("image", e.to_string()))?;
            Ok(Box::new(ImageTexture::new(texels, p.filter, p.wrap)) as Box<dyn Texture>)
        },
    );
}
