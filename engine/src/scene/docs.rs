//! The documentation of the scene file's own keys — the film, sampler and
//! integrator sections and the shapes — which are read by the scene loader
//! rather than by modules, so the registry cannot describe them.
//! `radiant modules` prints them after the modules; a test checks them
//! against the keys the loader accepts.

use radiant_core::ParamDoc;

/// The keys of one part of a scene file.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct KeyDocs {
    /// Where the keys are written (`film`, `shape: sphere`, …).
    pub title: &'static str,
    /// One line on what the part is.
    pub summary: &'static str,
    /// Its keys.
    pub keys: &'static [ParamDoc],
}

const fn key(
    name: &'static str,
    ty: &'static str,
    default: &'static str,
    doc: &'static str,
) -> ParamDoc {
    ParamDoc {
        name,
        ty,
        default,
        doc,
    }
}

/// Keys every shape takes, whatever its `type`.
pub const SHAPE_KEYS: &[ParamDoc] = &[
    key(
        "type",
        "rectangle | cube | sphere | mesh | gltf",
        "required",
        "What the shape is (below).",
    ),
    key(
        "name",
        "text",
        "shape N",
        "The shape's name in messages and `radiant info`.",
    ),
    key(
        "transform",
        "transform",
        "identity",
        "translate / rotate / scale / matrix / look_at, or a list (the last acts first).",
    ),
    key(
        "material",
        "material name | inline",
        "required",
        "A material under `materials:` or an inline `{type: …}`.",
    ),
    key(
        "emitter",
        "light",
        "none",
        "A light emitting from the shape's surface (`area`).",
    ),
    key(
        "flip_normals",
        "bool",
        "false",
        "Turn the surface's front (and one-sided emission) the other way; not on spheres.",
    ),
    key(
        "animation",
        "tracks",
        "none",
        "Keyframed translate / rotate / scale.",
    ),
    key(
        "instances",
        "list | grid | scatter",
        "none",
        "Copies of the shape, each with its transform and material.",
    ),
    key(
        "interior",
        "medium name",
        "none",
        "The participating medium inside the closed shape.",
    ),
    key(
        "exterior",
        "medium name",
        "none",
        "The participating medium outside the shape.",
    ),
];

/// The scene file's own keys, section by section.
pub const SCENE_KEYS: &[KeyDocs] = &[
    KeyDocs {
        title: "film",
        summary: "The image: its size, pixel filter and output encoding.",
        keys: &[
            key("width", "pixels", "768", "Image width."),
            key("height", "pixels", "576", "Image height."),
            key(
                "filter",
                "filter",
                "gaussian",
                "The pixel filter module (see filters above).",
            ),
            key(
                "filter_sampling",
                "splat | importance",
                "splat",
                "Splat each sample over the filter (Mitsuba) or place it by the filter (pbrt).",
            ),
            key(
                "tonemap",
                "{type, exposure}",
                "clamp, 0",
                "PNG/JPEG tone curve: clamp | reinhard | aces | agx; exposure in stops.",
            ),
            key("bit_depth", "8 | 16", "8", "PNG bits per channel."),
            key("exr", "float | half", "float", "EXR sample type."),
            key("jpeg_quality", "1–100", "90", "JPEG quality."),
            key(
                "alpha",
                "bool",
                "false",
                "Coverage as an alpha channel (RGBA PNG, straight; EXR, premultiplied).",
            ),
            key(
                "aovs",
                "[albedo, normal, depth, position, spp]",
                "[]",
                "Output variables written as layers of the EXR (`--aov` replaces the list).",
            ),
        ],
    },
    KeyDocs {
        title: "sampler",
        summary: "The sample sequence (a sampler module's `type` and keys) and the count.",
        keys: &[
            key(
                "type",
                "sampler",
                "sobol (without a `sampler` block)",
                "The sampler module (see samplers above); a `sampler` block names one.",
            ),
            key(
                "spp",
                "positive integer",
                "64",
                "Samples per pixel (with `adaptive`, the most a pixel takes; with `adaptive: {error: mse}`, the average).",
            ),
            key(
                "adaptive",
                "{error, threshold, confidence, batch, min_spp, max_spp} | bool",
                "off",
                "error: relative (default) stops a pixel once z·σ/√n ≤ threshold·μ (defaults 0.05, 0.95, 64, batch, spp); error: mse spends spp per pixel on average, each pixel's share ∝ its σ from a pilot round (min_spp spp/4, max_spp 16·spp). Decided on separate samples, so unbiased.",
            ),
        ],
    },
    KeyDocs {
        title: "integrator",
        summary: "The light-transport algorithm (an integrator module, see integrators above) and the keys every integrator shares.",
        keys: &[
            key(
                "type",
                "integrator",
                "path",
                "The integrator module (see integrators above).",
            ),
            key(
                "max_depth",
                "integer ≥ -1",
                "-1",
                "Longest path in segments (1: emitters seen directly, 2: direct light); -1 unlimited.",
            ),
            key(
                "rr_depth",
                "integer",
                "5",
                "Depth where Russian roulette starts.",
            ),
            key(
                "light_selection",
                "power | uniform | spatial",
                "spatial",
                "How next-event estimation picks a light: by power, uniformly, or by importance at the shading point.",
            ),
        ],
    },
    KeyDocs {
        title: "shape (every type but gltf)",
        summary: "A list under `shapes:`; each takes these keys and those of its type.",
        keys: SHAPE_KEYS,
    },
    KeyDocs {
        title: "shape: rectangle",
        summary: "[-1, 1]² in z = 0, normal +z.",
        keys: &[],
    },
    KeyDocs {
        title: "shape: cube",
        summary: "[-1, 1]³, normals outward.",
        keys: &[],
    },
    KeyDocs {
        title: "shape: sphere",
        summary: "A sphere, normals outward (its transform may not scale unevenly).",
        keys: &[
            key("center", "[x, y, z]", "[0, 0, 0]", "Centre."),
            key("radius", "number > 0", "1", "Radius."),
        ],
    },
    KeyDocs {
        title: "shape: mesh",
        summary: "Triangles from an OBJ or PLY file (`#` in the name: one file per frame).",
        keys: &[
            key(
                "filename",
                "path",
                "required",
                "Relative to the scene file.",
            ),
            key(
                "flip_tex_coords",
                "bool",
                "OBJ true, PLY false",
                "Use (u, 1 − v).",
            ),
            key(
                "face_normals",
                "bool",
                "false",
                "Keep the facets: ignore the file's normals and make no smooth ones.",
            ),
        ],
    },
    KeyDocs {
        title: "shape: gltf",
        summary: "Every mesh of a glTF 2.0 file, with its node transforms, materials and lights; only these keys and `type`.",
        keys: &[
            key("name", "text", "shape N", "The shape's name in messages."),
            key(
                "filename",
                "path",
                "required",
                "A .gltf or .glb file, relative to the scene file.",
            ),
            key(
                "transform",
                "transform",
                "identity",
                "Applied over the file's node transforms.",
            ),
            key(
                "material",
                "material name | inline",
                "the file's",
                "Replaces every material of the file.",
            ),
            key("face_normals", "bool", "false", "As for `mesh`."),
            key(
                "lights",
                "bool",
                "true",
                "Add the file's KHR_lights_punctual lights.",
            ),
        ],
    },
];

#[cfg(test)]
mod tests {
    use super::*;
    use std::collections::BTreeSet;
    use std::path::Path;

    /// The keys the loader names as allowed when `text` has an unknown key.
    fn allowed(text: &str) -> BTreeSet<String> {
        let scenes = Path::new(env!("CARGO_MANIFEST_DIR")).join("../scenes");
        let err = crate::scene::from_str(text, &scenes.join("probe.yaml"), &scenes)
            .err()
            .expect("an unknown key is an error")
            .to_string();
        let list = err
            .split_once("allowed keys: ")
            .or_else(|| err.split_once("expected one of "))
            .unwrap_or_else(|| panic!("no list of keys in: {err}"))
            .1;
        // `a, b, c` (the loader's) or `` `a`, `b`, or `c` `` (serde's).
        list.split(", ")
            .map(|k| {
                k.trim_start_matches("or ")
                    .trim_matches(|c: char| c == '`' || c.is_whitespace())
                    .to_string()
            })
            .collect()
    }

    /// The documented keys of `title` (with the shapes' common keys for a
    /// shape type).
    fn documented(title: &str) -> BTreeSet<String> {
        let docs = SCENE_KEYS.iter().find(|d| d.title == title).expect(title);
        let mut keys: BTreeSet<String> = docs.keys.iter().map(|k| k.name.to_string()).collect();
        if title == "shape: gltf" {
            keys.insert("type".to_string());
        } else if title.starts_with("shape: ") {
            keys.extend(SHAPE_KEYS.iter().map(|k| k.name.to_string()));
        }
        keys
    }

    #[test]
    fn every_key_the_loader_accepts_is_documented_and_no_other() {
        let camera = "camera: {type: perspective}\n";
        let cases = [
            ("film", format!("{camera}film: {{unknown_key: 1}}\n")),
            (
                "shape: rectangle",
                format!("{camera}shapes: [{{type: rectangle, unknown_key: 1}}]\n"),
            ),
            (
                "shape: cube",
                format!("{camera}shapes: [{{type: cube, unknown_key: 1}}]\n"),
            ),
            (
                "shape: sphere",
                format!("{camera}shapes: [{{type: sphere, unknown_key: 1}}]\n"),
            ),
            (
                "shape: mesh",
                format!(
                    "{camera}shapes: [{{type: mesh, filename: meshes/icosahedron.obj, unknown_key: 1}}]\n"
                ),
            ),
            (
                "shape: gltf",
                format!("{camera}shapes: [{{type: gltf, filename: x.gltf, unknown_key: 1}}]\n"),
            ),
        ];
        for (title, text) in cases {
            assert_eq!(allowed(&text), documented(title), "{title}");
        }
        // The integrator's shared keys are the loader's; the rest are the
        // module's own (documented with it, checked at extract).
        let mut shared: BTreeSet<String> = crate::scene::INTEGRATOR_KEYS
            .iter()
            .map(|k| k.to_string())
            .collect();
        shared.insert("type".to_string());
        assert_eq!(documented("integrator"), shared);
    }
}
