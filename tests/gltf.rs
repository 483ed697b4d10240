//! glTF 2.0 scenes: what a `gltf` shape and a `gltf` camera import from a
//! file, each compared with a hand-written YAML twin of the same scene
//! (rendered with the same samples, so only rounding differs) and with a
//! wrong twin that must differ (the comparison's power). The glTF files
//! are the committed `tests/data/meshes/scene.gltf` (made by
//! `tests/reference/render_meshes.py`) edited here as JSON, and small
//! files written here; textures the twins need are written as EXR so that
//! their texels are exact.
//!
//! * Nodes, the material's factors and base-colour image, the camera and
//!   `KHR_lights_punctual` lights; normal textures and emission.
//! * Factors times textures (base colour; metalness and roughness from the
//!   blue and green channels of the metallic-roughness texture),
//!   `KHR_texture_transform`, `TEXCOORD_1`, images embedded as `data:`
//!   URIs and in a `.glb`'s binary chunk, samplers' wrap and filter,
//!   orthographic cameras.
//! * Light units: a glTF point or spot light of I candela and a
//!   directional light of E lux light a grey diffuse plane as Radiant
//!   lights of I W/sr and E W/m² do (radiance ρ/π · I/d² and ρ/π · E).
//! * Broken files are located errors naming the file and the problem.

use radiant::extract::Overrides;
use radiant::film::Image;
use radiant_tests::relative_difference;
use serde_json::{Value, json};
use std::path::Path;

/// The glTF scene of a folder: its camera, shapes and lights.
const GLTF_SCENE: &str = "camera: {type: gltf, filename: scene.gltf}\nshapes:\n  - {type: gltf, filename: scene.gltf}\nlights:\n";

/// The glTF scene's contents written in Radiant's YAML: the camera, the
/// lights (the spot and the sun shining along their nodes' turned −z), the
/// torus placed by the two nodes' transforms (parent translation, child
/// rotation and scale) and its material.
const GLTF_AS_YAML: &str = "\
camera: {type: perspective, fov: 30, fov_axis: y, look_at: {origin: [0, 0, 6], target: [0, 0, 0], up: [0, 1, 0]}}
textures: {checks: {type: image, filename: checks.png}}
materials: {torus: {type: principled, base_color: checks, metallic: 0.3, roughness: 0.6}}
shapes:
  - {type: mesh, filename: torus-uv.obj, material: torus, transform: [{translate: [0.3, -0.2, 0]}, {rotate: {axis: [1, 0, 0], angle: 90}}, {scale: 0.8}]}
lights:
  - {type: point, position: [3, 3, 2], intensity: [25, 22.5, 20]}
  - {type: spot, position: [-1, 2, 4], direction: [0, -0.5, -0.8660254037844387], intensity: [20, 20, 40], cutoff_angle: 28.64788975654116, beam_width: 17.188733853924695}
  - {type: directional, direction: [-0.7071067811865475, 0, -0.7071067811865475], irradiance: 0.5}
";

/// What both glTF comparisons render: a dim environment (glTF has none).
const SETTINGS: &str = "\
integrator: {type: path, max_depth: 3}
film: {width: 96, height: 64, filter: {type: gaussian, stddev: 0.5}}
sampler: {type: independent, spp: 16}
";

/// Renders `body` (after [`SETTINGS`], with an environment light added
/// where it has a `lights:` list) in `tests/data/meshes/`.
fn render_text(body: &str) -> Result<Image, String> {
    render_text_in(&radiant_tests::root().join("tests/data/meshes"), body)
}

/// As [`render_text`], with files relative to `dir`.
fn render_text_in(dir: &Path, body: &str) -> Result<Image, String> {
    use radiant::backend::cpu::{Progress, render};
    let text = format!("{SETTINGS}{body}  - {{type: environment, radiance: 0.1}}\n");
    let scene = radiant::scene::from_str(&text, &dir.join("gltf-test.yaml"), dir)
        .map_err(|e| e.to_string())?;
    let r = radiant::extract::extract(&scene, &radiant::builtin_registry(), &Overrides::default())
        .map_err(|e| e.to_string())?;
    Ok(render(&r, &Progress::none()).image)
}

/// The same difference allowed between the glTF scene and its YAML twin:
/// they trace the same sample sequence, so what differs is the rounding of
/// the transforms (the node's float quaternion against the YAML's rotation
/// by 90°). Measured: below 10⁻⁵; a node transform left out costs 0.095
/// or more, metalness 0.9 instead of 0.3 costs 0.0099.
const SAME_SCENE: f64 = 0.001;

#[test]
fn gltf_nodes_material_texture_camera_and_lights_are_imported() {
    let gltf = render_text(GLTF_SCENE).expect("the glTF scene renders");
    let yaml = |from: &str, to: &str| {
        assert!(GLTF_AS_YAML.contains(from), "{from}");
        render_text(&GLTF_AS_YAML.replace(from, to)).expect("the YAML twin renders")
    };
    let same = relative_difference(&gltf, &yaml("", ""));
    eprintln!("glTF against YAML: {same:.2e}");
    assert!(
        same < SAME_SCENE,
        "the glTF scene differs from its YAML twin: {same}"
    );
    // The comparison's power: without the parent's translation or the
    // child's rotation, with another metalness, or with a light turned
    // or left out, the images differ.
    let wrong = [
        ("{translate: [0.3, -0.2, 0]}, ", ""),
        ("{rotate: {axis: [1, 0, 0], angle: 90}}, ", ""),
        ("metallic: 0.3", "metallic: 0.9"),
        ("direction: [0, -0.5,", "direction: [0, 0.5,"),
        (
            "direction: [-0.7071067811865475,",
            "direction: [0.7071067811865475,",
        ),
        (POINT_LIGHT_LINE, ""),
    ];
    for (from, to) in wrong {
        let d = relative_difference(&gltf, &yaml(from, to));
        eprintln!("`{from}` → `{to}`: {d:.5}");
        assert!(d > 5.0 * SAME_SCENE, "`{from}` → `{to}`: only {d}");
    }
    // With `lights: false` the glTF's lights stay out: the image is the
    // YAML twin's without them.
    let unlit = render_text(
        "camera: {type: gltf, filename: scene.gltf}\nshapes:\n  - {type: gltf, filename: scene.gltf, lights: false}\nlights:\n",
    )
    .expect("the glTF scene renders");
    let lights = GLTF_AS_YAML.find("lights:\n").expect("a light list") + "lights:\n".len();
    let twin = render_text(&GLTF_AS_YAML[..lights]).expect("the YAML twin renders");
    let d = relative_difference(&unlit, &twin);
    assert!(
        d < SAME_SCENE,
        "lights: false differs from the scene without the lights: {d}"
    );
}

/// A glTF material's normal texture becomes a `normal_map` around its
/// `principled` material (the image read raw), and its emissive factor an
/// `area` emitter on its meshes.
#[test]
fn gltf_normal_textures_and_emission_are_imported() {
    let data = radiant_tests::root().join("tests/data/meshes");
    let dir = tempfile::tempdir().expect("temporary folders can be made");
    for file in ["checks.png", "torus-uv.obj"] {
        std::fs::copy(data.join(file), dir.path().join(file)).expect("copyable");
    }
    let text = std::fs::read_to_string(data.join("scene.gltf")).expect("the glTF is committed");
    let from = "\"name\": \"checked metal\",";
    assert!(text.contains(from));
    let edited = text.replace(
        from,
        "\"name\": \"checked metal\", \"normalTexture\": {\"index\": 0}, \"emissiveFactor\": [0.2, 0.1, 0.05],",
    );
    std::fs::write(dir.path().join("scene.gltf"), edited).expect("writable");
    let gltf = render_text_in(dir.path(), GLTF_SCENE).expect("the glTF scene renders");
    let twin = |material: &str, emitter: &str| {
        let yaml = GLTF_AS_YAML
            .replace(
                "textures: {checks: {type: image, filename: checks.png}}",
                "textures: {checks: {type: image, filename: checks.png}, \
                 raw: {type: image, filename: checks.png, raw: true}}",
            )
            .replace(
                "materials: {torus: {type: principled, base_color: checks, metallic: 0.3, roughness: 0.6}}",
                &format!("materials: {{torus: {material}}}"),
            )
            .replace("material: torus,", &format!("material: torus, {emitter}"));
        render_text_in(dir.path(), &yaml).expect("the YAML twin renders")
    };
    let principled = "{type: principled, base_color: checks, metallic: 0.3, roughness: 0.6}";
    let mapped = format!("{{type: normal_map, normals: raw, material: {principled}}}");
    let glow = "emitter: {type: area, radiance: [0.2, 0.1, 0.05]},";
    let same = relative_difference(&gltf, &twin(&mapped, glow));
    eprintln!("glTF against YAML: {same:.2e}");
    assert!(same < SAME_SCENE, "differs from its YAML twin: {same}");
    for (material, emitter) in [(principled, glow), (mapped.as_str(), "")] {
        let d = relative_difference(&gltf, &twin(material, emitter));
        eprintln!("{material} {emitter}: {d:.5}");
        assert!(d > 5.0 * SAME_SCENE, "{material} {emitter}: only {d}");
    }
}

const POINT_LIGHT_LINE: &str =
    "  - {type: point, position: [3, 3, 2], intensity: [25, 22.5, 20]}\n";

/// Loads the glTF scene with its text changed by `edit` (written beside a
/// copy of `checks.png`) and returns the error.
fn gltf_error(edit: impl Fn(&str) -> String, camera: bool) -> String {
    let data = radiant_tests::root().join("tests/data/meshes");
    let text = std::fs::read_to_string(data.join("scene.gltf")).expect("the glTF is committed");
    let dir = tempfile::tempdir().expect("temporary folders can be made");
    std::fs::write(dir.path().join("broken.gltf"), edit(&text)).expect("writable");
    std::fs::copy(data.join("checks.png"), dir.path().join("checks.png")).expect("copyable");
    let scene = if camera {
        "camera: {type: gltf, filename: broken.gltf}\n".to_string()
    } else {
        "camera: {type: perspective}\nshapes:\n  - {type: gltf, filename: broken.gltf}\n"
            .to_string()
    };
    let Err(err) = radiant::scene::from_str(&scene, Path::new("scene.yaml"), dir.path()) else {
        panic!("the broken glTF loads");
    };
    let message = err.to_string();
    assert!(message.contains("scene.yaml:"), "not located: {message}");
    assert!(
        message.contains("broken.gltf"),
        "the file is not named: {message}"
    );
    message
}

/// A change to the glTF file's text.
type Edit = Box<dyn Fn(&str) -> String>;

#[test]
fn broken_gltf_files_are_located_errors() {
    let data_uri = "\"uri\": \"data:application/octet-stream;base64,";
    let cases: Vec<(Edit, bool, &str)> = vec![
        (
            Box::new(|t| t[..t.len() / 2].to_string()),
            false,
            "is not valid glTF 2.0",
        ),
        (
            Box::new(move |t| {
                let start = t.find(data_uri).expect("an embedded buffer");
                let body = start + data_uri.len();
                let end = body + t[body..].find('"').expect("its end") + 1;
                format!("{}\"uri\": \"torus.bin\"{}", &t[..start], &t[end..])
            }),
            false,
            "buffer 0 is the file `torus.bin`, which cannot be read",
        ),
        (
            Box::new(|t| t.replacen("\"count\": 128", "\"count\": 4000", 1)),
            false,
            "accessor 0 needs 48000 bytes of buffer view 0, which has 1536",
        ),
        (
            Box::new(|t| t.replace("\"mode\": 4", "\"mode\": 0")),
            false,
            "draws Points, which Radiant does not render",
        ),
        (
            Box::new(|t| t.replace("\"uri\": \"checks.png\"", "\"uri\": \"missing.png\"")),
            false,
            "image 0 is the file `missing.png`, which cannot be read",
        ),
        (
            Box::new(|t| t.replace("\"camera\": 0,", "")),
            true,
            "has no camera in its scene",
        ),
    ];
    for (edit, camera, expected) in cases {
        let message = gltf_error(edit, camera);
        eprintln!("{message}");
        assert!(
            message.contains(expected),
            "expected `{expected}` in: {message}"
        );
    }
}

/// `scene.gltf` as JSON, to edit.
fn scene_json() -> Value {
    let path = radiant_tests::root().join("tests/data/meshes/scene.gltf");
    let text = std::fs::read_to_string(path).expect("the glTF is committed");
    serde_json::from_str(&text).expect("the committed glTF is JSON")
}

/// A folder holding `gltf` as `scene.gltf` beside copies of `checks.png`
/// and `torus-uv.obj` (which the YAML twins read).
fn gltf_folder(gltf: &Value) -> tempfile::TempDir {
    let data = radiant_tests::root().join("tests/data/meshes");
    let dir = tempfile::tempdir().expect("temporary folders can be made");
    for file in ["checks.png", "torus-uv.obj"] {
        std::fs::copy(data.join(file), dir.path().join(file)).expect("copyable");
    }
    std::fs::write(dir.path().join("scene.gltf"), gltf.to_string()).expect("writable");
    dir
}

/// Writes an `n`×`n` EXR texture whose texel in `column`, `row` is
/// `texel(column, row)`.
fn write_texture(path: &Path, n: u32, texel: impl Fn(u32, u32) -> [f32; 3]) {
    let pixels = (0..n * n)
        .map(|k| glam::Vec3::from(texel(k % n, k / n)))
        .collect();
    let image = Image {
        width: n,
        height: n,
        pixels,
    };
    radiant::film::output::write(path, &image).expect("the texture is written");
}

/// A value in [lo, hi] that varies irregularly over texels and channels.
fn varied(column: u32, row: u32, channel: u32, lo: f32, hi: f32) -> f32 {
    let k = (column * 7 + row * 13 + channel * 5) % 11;
    lo + (hi - lo) * k as f32 / 10.0
}

/// Texels of the test texture (8×8).
const TEXELS: u32 = 8;

/// The colour texture of the tests, texel (column, row).
fn colour(column: u32, row: u32) -> [f32; 3] {
    [0, 1, 2].map(|c| varied(column, row, c, 0.1, 0.9))
}

/// Asserts that `gltf` renders as `twin` does and unlike each of `wrong`.
fn assert_twin(gltf: &Image, twin: &Image, wrong: &[(&str, Image)]) {
    let same = relative_difference(gltf, twin);
    eprintln!("glTF against its YAML twin: {same:.2e}");
    assert!(same < SAME_SCENE, "differs from its YAML twin: {same}");
    for (what, image) in wrong {
        let d = relative_difference(gltf, image);
        eprintln!("{what}: {d:.5}");
        assert!(d > 5.0 * SAME_SCENE, "{what}: only {d}");
    }
}

/// The YAML twin with its texture and material lines replaced.
fn twin_yaml(textures: &str, material: &str) -> String {
    let texture_line = "textures: {checks: {type: image, filename: checks.png}}";
    let material_line =
        "materials: {torus: {type: principled, base_color: checks, metallic: 0.3, roughness: 0.6}}";
    assert!(GLTF_AS_YAML.contains(texture_line) && GLTF_AS_YAML.contains(material_line));
    GLTF_AS_YAML
        .replace(texture_line, &format!("textures: {textures}"))
        .replace(material_line, &format!("materials: {{torus: {material}}}"))
}

/// The base-colour factor multiplies the base-colour texture, and the
/// metallic and roughness factors multiply the blue and green channels of
/// the metallic-roughness texture (read raw).
#[test]
fn gltf_factors_multiply_their_textures() {
    let mut gltf = scene_json();
    gltf["images"] = json!([{"uri": "colour.exr"}, {"uri": "mr.exr"}]);
    gltf["textures"] = json!([{"source": 0}, {"source": 1}]);
    gltf["materials"][0]["pbrMetallicRoughness"] = json!({
        "baseColorTexture": {"index": 0},
        "baseColorFactor": [0.5, 0.8, 1.0, 1.0],
        "metallicRoughnessTexture": {"index": 1},
        "metallicFactor": 0.7,
        "roughnessFactor": 0.9,
    });
    let dir = gltf_folder(&gltf);
    let at = |name: &str| dir.path().join(name);
    let factor = [0.5f32, 0.8, 1.0];
    let roughness = |c, r| varied(c, r, 1, 0.5, 0.9);
    let metalness = |c, r| varied(c, r, 2, 0.05, 0.45);
    write_texture(&at("colour.exr"), TEXELS, colour);
    write_texture(&at("mr.exr"), TEXELS, |c, r| {
        [0.5, roughness(c, r), metalness(c, r)]
    });
    // The twin's textures hold the products (a grey texture is its value).
    write_texture(&at("base.exr"), TEXELS, |c, r| {
        let t = colour(c, r);
        [0, 1, 2].map(|k| factor[k] * t[k])
    });
    write_texture(&at("metal.exr"), TEXELS, |c, r| [0.7 * metalness(c, r); 3]);
    write_texture(&at("rough.exr"), TEXELS, |c, r| [0.9 * roughness(c, r); 3]);
    let textures = "{checks: {type: image, filename: base.exr}, plain: {type: image, filename: colour.exr}, \
                    metal: {type: image, filename: metal.exr}, rough: {type: image, filename: rough.exr}}";
    let twin = |material: &str| {
        render_text_in(dir.path(), &twin_yaml(textures, material)).expect("the twin renders")
    };
    let gltf = render_text_in(dir.path(), GLTF_SCENE).expect("the glTF scene renders");
    assert_twin(
        &gltf,
        &twin("{type: principled, base_color: checks, metallic: metal, roughness: rough}"),
        &[
            (
                "the base-colour factor left out",
                twin("{type: principled, base_color: plain, metallic: metal, roughness: rough}"),
            ),
            (
                "metalness and roughness from the other channels",
                twin("{type: principled, base_color: checks, metallic: rough, roughness: metal}"),
            ),
            (
                "the metallic-roughness texture left out",
                twin("{type: principled, base_color: checks, metallic: 0.7, roughness: 0.9}"),
            ),
        ],
    );
}

/// `KHR_texture_transform` on a base-colour and a normal texture: turning
/// by 90° with an offset of (0, 1) maps (u, v) to (v, 1 − u), which is
/// the texture turned texel by texel (so the twin needs no `uv_transform`);
/// a general transform (scale, then rotation, then offset) equals Radiant's
/// `uv_transform` turning the other way round.
#[test]
fn gltf_texture_transforms_are_applied() {
    let quarter = json!({"rotation": std::f64::consts::FRAC_PI_2, "offset": [0.0, 1.0]});
    let mut gltf = scene_json();
    gltf["images"] = json!([{"uri": "colour.exr"}]);
    gltf["materials"][0]["pbrMetallicRoughness"]["baseColorTexture"] =
        json!({"index": 0, "extensions": {"KHR_texture_transform": quarter}});
    gltf["materials"][0]["normalTexture"] =
        json!({"index": 0, "extensions": {"KHR_texture_transform": quarter}});
    let dir = gltf_folder(&gltf);
    let at = |name: &str| dir.path().join(name);
    write_texture(&at("colour.exr"), TEXELS, colour);
    // Texel (i, j) of the turned texture is texel (j, n − 1 − i).
    write_texture(&at("turned.exr"), TEXELS, |i, j| colour(j, TEXELS - 1 - i));
    let textures =
        "{checks: {type: image, filename: turned.exr}, plain: {type: image, filename: colour.exr}}";
    let twin = |textures: &str, base: &str, normals: &str| {
        let material = format!(
            "{{type: normal_map, normals: {normals}, material: {{type: principled, base_color: {base}, metallic: 0.3, roughness: 0.6}}}}"
        );
        render_text_in(dir.path(), &twin_yaml(textures, &material)).expect("the twin renders")
    };
    let gltf_image = render_text_in(dir.path(), GLTF_SCENE).expect("the glTF scene renders");
    assert_twin(
        &gltf_image,
        &twin(textures, "checks", "checks"),
        &[
            ("base colour not turned", twin(textures, "plain", "checks")),
            ("normals not turned", twin(textures, "checks", "plain")),
        ],
    );

    let (scale, rotation, offset) = ([2.0, 3.0], 0.4f64, [0.25, 0.1]);
    gltf["materials"][0]["pbrMetallicRoughness"]["baseColorTexture"] = json!({"index": 0,
        "extensions": {"KHR_texture_transform": {"scale": scale, "rotation": rotation, "offset": offset}}});
    gltf["materials"][0]
        .as_object_mut()
        .expect("a material is an object")
        .remove("normalTexture");
    std::fs::write(at("scene.gltf"), gltf.to_string()).expect("writable");
    let gltf_image = render_text_in(dir.path(), GLTF_SCENE).expect("the glTF scene renders");
    let mapped = |degrees: f64| {
        let textures = format!(
            "{{plain: {{type: image, filename: colour.exr}}, checks: {{type: uv_transform, texture: plain, \
             scale: [2, 3], rotate: {degrees}, offset: [0.25, 0.1]}}}}"
        );
        render_text_in(
            dir.path(),
            &twin_yaml(
                &textures,
                "{type: principled, base_color: checks, metallic: 0.3, roughness: 0.6}",
            ),
        )
        .expect("the twin renders")
    };
    assert_twin(
        &gltf_image,
        &mapped(-rotation.to_degrees()),
        &[("turned the other way", mapped(rotation.to_degrees()))],
    );
}

/// A material whose texture reads `TEXCOORD_1` gets the mesh's second set
/// of texture coordinates; a material whose textures read different sets
/// is an error (a Radiant mesh carries one set).
#[test]
fn gltf_textures_read_their_texture_coordinate_set() {
    let mut gltf = scene_json();
    // TEXCOORD_0 becomes other numbers (the normals' first two
    // coordinates); TEXCOORD_1 the torus's texture coordinates.
    let accessors = gltf["accessors"].as_array_mut().expect("a list");
    accessors.push(json!({"bufferView": 1, "componentType": 5126, "count": 128, "type": "VEC2"}));
    let other = accessors.len() - 1;
    let attributes = &mut gltf["meshes"][0]["primitives"][0]["attributes"];
    attributes["TEXCOORD_1"] = attributes["TEXCOORD_0"].clone();
    attributes["TEXCOORD_0"] = json!(other);
    gltf["materials"][0]["pbrMetallicRoughness"]["baseColorTexture"]["texCoord"] = json!(1);
    let dir = gltf_folder(&gltf);
    let gltf_image = render_text_in(dir.path(), GLTF_SCENE).expect("the glTF scene renders");
    gltf["materials"][0]["pbrMetallicRoughness"]["baseColorTexture"]["texCoord"] = json!(0);
    std::fs::write(dir.path().join("scene.gltf"), gltf.to_string()).expect("writable");
    let first_set = render_text_in(dir.path(), GLTF_SCENE).expect("the glTF scene renders");
    let twin = render_text_in(dir.path(), GLTF_AS_YAML).expect("the twin renders");
    assert_twin(
        &gltf_image,
        &twin,
        &[("TEXCOORD_0 read instead", first_set)],
    );

    gltf["materials"][0]["normalTexture"] = json!({"index": 0, "texCoord": 1});
    std::fs::write(dir.path().join("scene.gltf"), gltf.to_string()).expect("writable");
    let err = render_text_in(dir.path(), GLTF_SCENE).expect_err("mixed sets are refused");
    eprintln!("{err}");
    assert!(
        err.contains("gltf-test.yaml")
            && err.contains("scene.gltf")
            && err.contains(
                "reads TEXCOORD_0 for its base colour texture and TEXCOORD_1 for its normal texture"
            ),
        "{err}"
    );
}

/// Base64, as a `data:` URI holds bytes.
fn base64(bytes: &[u8]) -> String {
    const DIGITS: &[u8; 64] = b"ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
    let mut out = String::new();
    for chunk in bytes.chunks(3) {
        let b = [0, 1, 2].map(|k| u32::from(chunk.get(k).copied().unwrap_or(0)));
        let n = (b[0] << 16) | (b[1] << 8) | b[2];
        for k in 0..4 {
            out.push(if k <= chunk.len() {
                DIGITS[(n >> (18 - 6 * k)) as usize & 63] as char
            } else {
                '='
            });
        }
    }
    out
}

/// A `.glb` file: `json` and `bin` as its two chunks, each padded to a
/// multiple of 4 bytes.
fn glb(json: &Value, mut bin: Vec<u8>) -> Vec<u8> {
    let mut text = json.to_string().into_bytes();
    text.resize(text.len().next_multiple_of(4), b' ');
    bin.resize(bin.len().next_multiple_of(4), 0);
    let total = 12 + 8 + text.len() + 8 + bin.len();
    let mut out = Vec::with_capacity(total);
    out.extend_from_slice(b"glTF");
    out.extend_from_slice(&2u32.to_le_bytes());
    out.extend_from_slice(&(total as u32).to_le_bytes());
    for (chunk, kind) in [(&text, b"JSON"), (&bin, b"BIN\0")] {
        out.extend_from_slice(&(chunk.len() as u32).to_le_bytes());
        out.extend_from_slice(kind);
        out.extend_from_slice(chunk);
    }
    out
}

/// Images embedded in the glTF file (a `data:` URI in a `.gltf`, a buffer
/// view of a `.glb`'s binary chunk) render as the same image beside it.
#[test]
fn gltf_embedded_images_are_read() {
    let png = std::fs::read(radiant_tests::root().join("tests/data/meshes/checks.png"))
        .expect("the image is committed");
    let beside = render_text(GLTF_SCENE).expect("the glTF scene renders");
    let dir = tempfile::tempdir().expect("temporary folders can be made");
    std::fs::copy(
        radiant_tests::root().join("tests/data/meshes/torus-uv.obj"),
        dir.path().join("torus-uv.obj"),
    )
    .expect("copyable");

    let mut gltf = scene_json();
    gltf["images"] = json!([{"uri": format!("data:image/png;base64,{}", base64(&png))}]);
    std::fs::write(dir.path().join("scene.gltf"), gltf.to_string()).expect("writable");
    let data_uri = render_text_in(dir.path(), GLTF_SCENE).expect("the glTF scene renders");

    // The binary chunk is buffer 0 and holds the image; the mesh's data
    // stays in its data URI, now buffer 1.
    let mut gltf = scene_json();
    let mesh_buffer = gltf["buffers"][0].clone();
    gltf["buffers"] = json!([{"byteLength": png.len()}, mesh_buffer]);
    let views = gltf["bufferViews"].as_array_mut().expect("a list");
    for view in views.iter_mut() {
        view["buffer"] = json!(1);
    }
    views.push(json!({"buffer": 0, "byteOffset": 0, "byteLength": png.len()}));
    let view = views.len() - 1;
    gltf["images"] = json!([{"bufferView": view, "mimeType": "image/png"}]);
    std::fs::write(dir.path().join("scene.glb"), glb(&gltf, png.clone())).expect("writable");
    let binary = render_text_in(dir.path(), &GLTF_SCENE.replace("scene.gltf", "scene.glb"))
        .expect("the glTF scene renders");

    for (what, image) in [("data URI", &data_uri), ("binary chunk", &binary)] {
        let d = relative_difference(image, &beside);
        eprintln!("{what}: {d:.2e}");
        assert!(
            d < SAME_SCENE,
            "the image in a {what} renders differently: {d}"
        );
    }
    // The comparison's power: another image in the data URI.
    let mut red = Vec::new();
    image::RgbImage::from_pixel(4, 4, image::Rgb([200, 60, 60]))
        .write_to(&mut std::io::Cursor::new(&mut red), image::ImageFormat::Png)
        .expect("a PNG is encoded");
    let mut gltf = scene_json();
    gltf["images"] = json!([{"uri": format!("data:image/png;base64,{}", base64(&red))}]);
    std::fs::write(dir.path().join("scene.gltf"), gltf.to_string()).expect("writable");
    let other = render_text_in(dir.path(), GLTF_SCENE).expect("the glTF scene renders");
    assert!(relative_difference(&other, &beside) > 5.0 * SAME_SCENE);
    // Bytes that are no image: an error naming the file and the image.
    gltf["images"] = json!([{"uri": "data:image/png;base64,AAAA"}]);
    std::fs::write(dir.path().join("scene.gltf"), gltf.to_string()).expect("writable");
    let err = render_text_in(dir.path(), GLTF_SCENE).expect_err("a broken image is refused");
    eprintln!("{err}");
    assert!(err.contains("scene.gltf#image0"), "{err}");
}

/// An orthographic glTF camera is Radiant's `orthographic` camera
/// `2 · xmag` wide, placed by its node.
#[test]
fn gltf_orthographic_cameras_are_imported() {
    let mut gltf = scene_json();
    gltf["cameras"] = json!([{"type": "orthographic",
        "orthographic": {"xmag": 2.0, "ymag": 1.5, "znear": 0.01, "zfar": 100.0}}]);
    let dir = gltf_folder(&gltf);
    let camera_line = "camera: {type: perspective, fov: 30, fov_axis: y, look_at: {origin: [0, 0, 6], target: [0, 0, 0], up: [0, 1, 0]}}";
    assert!(GLTF_AS_YAML.contains(camera_line));
    let twin = |width: &str| {
        let camera = format!(
            "camera: {{type: orthographic, width: {width}, look_at: {{origin: [0, 0, 6], target: [0, 0, 0], up: [0, 1, 0]}}}}"
        );
        render_text_in(dir.path(), &GLTF_AS_YAML.replace(camera_line, &camera))
            .expect("the twin renders")
    };
    let gltf_image = render_text_in(dir.path(), GLTF_SCENE).expect("the glTF scene renders");
    assert_twin(&gltf_image, &twin("4"), &[("xmag as the width", twin("2"))]);
}

/// A square of side 4 on z = 0 facing +z, an orthographic camera 5 above
/// it looking down at its middle 0.2 × 0.2, and a light node 2 above it
/// pointing down; `light` is the `KHR_lights_punctual` light.
fn lit_square(light: Value) -> Value {
    let positions: [[f32; 3]; 4] = [
        [-2.0, -2.0, 0.0],
        [2.0, -2.0, 0.0],
        [2.0, 2.0, 0.0],
        [-2.0, 2.0, 0.0],
    ];
    let mut bytes: Vec<u8> = positions
        .iter()
        .flatten()
        .flat_map(|v| v.to_le_bytes())
        .collect();
    bytes.extend([0u32, 1, 2, 0, 2, 3].iter().flat_map(|i| i.to_le_bytes()));
    json!({
        "asset": {"version": "2.0"},
        "scene": 0,
        "scenes": [{"nodes": [0, 1, 2]}],
        "nodes": [
            {"mesh": 0},
            {"camera": 0, "translation": [0.0, 0.0, 5.0]},
            {"translation": [0.0, 0.0, 2.0], "extensions": {"KHR_lights_punctual": {"light": 0}}}
        ],
        "meshes": [{"primitives": [{"attributes": {"POSITION": 0}, "indices": 1}]}],
        "accessors": [
            {"bufferView": 0, "componentType": 5126, "count": 4, "type": "VEC3",
             "min": [-2.0, -2.0, 0.0], "max": [2.0, 2.0, 0.0]},
            {"bufferView": 1, "componentType": 5125, "count": 6, "type": "SCALAR"}
        ],
        "bufferViews": [
            {"buffer": 0, "byteOffset": 0, "byteLength": 48},
            {"buffer": 0, "byteOffset": 48, "byteLength": 24}
        ],
        "buffers": [{"byteLength": bytes.len(),
            "uri": format!("data:application/octet-stream;base64,{}", base64(&bytes))}],
        "cameras": [{"type": "orthographic",
            "orthographic": {"xmag": 0.1, "ymag": 0.1, "znear": 0.01, "zfar": 100.0}}],
        "extensionsUsed": ["KHR_lights_punctual"],
        "extensions": {"KHR_lights_punctual": {"lights": [light]}}
    })
}

/// glTF's light units carried over 1:1: a point light of I cd and a spot
/// light of I cd (on its axis) 2 above a diffuse square of reflectance
/// ρ = 0.5 give it radiance ρ/π · I/4 below them, and a directional light
/// of E lux shining straight down ρ/π · E; each colour channel scaled by
/// the light's colour.
#[test]
fn gltf_light_units_are_candela_and_lux_read_as_radiant_units() {
    let colour = [1.0f32, 0.5, 0.25];
    let cases = [
        (
            json!({"type": "point", "intensity": 8.0, "color": colour}),
            8.0 / 4.0,
        ),
        (
            json!({"type": "spot", "intensity": 8.0, "color": colour,
                   "spot": {"innerConeAngle": 0.3, "outerConeAngle": 0.5}}),
            8.0 / 4.0,
        ),
        (
            json!({"type": "directional", "intensity": 3.0, "color": colour}),
            3.0,
        ),
    ];
    let dir = tempfile::tempdir().expect("temporary folders can be made");
    for (light, irradiance) in cases {
        let kind = light["type"].clone();
        std::fs::write(
            dir.path().join("square.gltf"),
            lit_square(light).to_string(),
        )
        .expect("writable");
        let scene = "integrator: {type: path, max_depth: 2}\nfilm: {width: 8, height: 8}\n\
                     sampler: {type: independent, spp: 4}\n\
                     camera: {type: gltf, filename: square.gltf}\n\
                     materials: {grey: {type: diffuse, reflectance: 0.5}}\n\
                     shapes:\n  - {type: gltf, filename: square.gltf, material: grey}\n";
        let scene = radiant::scene::from_str(scene, &dir.path().join("lit.yaml"), dir.path())
            .expect("the scene loads");
        let r =
            radiant::extract::extract(&scene, &radiant::builtin_registry(), &Overrides::default())
                .expect("the scene extracts");
        let image =
            radiant::backend::cpu::render(&r, &radiant::backend::cpu::Progress::none()).image;
        let mean = image.pixels.iter().copied().sum::<glam::Vec3>() / image.pixels.len() as f32;
        for (k, c) in colour.iter().enumerate() {
            // The corners of the 0.2-wide view are 0.14 off the light's
            // axis: the point and spot lights' irradiance there is 0.7 %
            // lower (cos³), 0.2 % on average.
            let expected = 0.5 / std::f32::consts::PI * irradiance * c;
            let got = mean[k];
            eprintln!("{kind} channel {k}: {got} against {expected}");
            assert!(
                (got / expected - 1.0).abs() < 0.01,
                "{kind}: channel {k} is {got}, expected {expected}"
            );
        }
    }
}

/// A texture's sampler carries over: `CLAMP_TO_EDGE` as `wrap: clamp`,
/// `NEAREST` magnification as `filter: nearest` (the texture is repeated
/// three times by its transform, so the wrap mode shows).
#[test]
fn gltf_samplers_set_wrap_and_filter() {
    let mut gltf = scene_json();
    gltf["images"] = json!([{"uri": "colour.exr"}]);
    gltf["samplers"] = json!([{"magFilter": 9728, "wrapS": 33071, "wrapT": 33071}]);
    gltf["textures"] = json!([{"source": 0, "sampler": 0}]);
    gltf["materials"][0]["pbrMetallicRoughness"]["baseColorTexture"] =
        json!({"index": 0, "extensions": {"KHR_texture_transform": {"scale": [3.0, 3.0]}}});
    let dir = gltf_folder(&gltf);
    write_texture(&dir.path().join("colour.exr"), TEXELS, colour);
    let twin = |sampling: &str| {
        let textures = format!(
            "{{plain: {{type: image, filename: colour.exr{sampling}}}, checks: {{type: uv_transform, \
             texture: plain, scale: [3, 3]}}}}"
        );
        let material = "{type: principled, base_color: checks, metallic: 0.3, roughness: 0.6}";
        render_text_in(dir.path(), &twin_yaml(&textures, material)).expect("the twin renders")
    };
    let gltf_image = render_text_in(dir.path(), GLTF_SCENE).expect("the glTF scene renders");
    assert_twin(
        &gltf_image,
        &twin(", wrap: clamp, filter: nearest"),
        &[
            ("repeated", twin(", filter: nearest")),
            ("bilinear", twin(", wrap: clamp")),
        ],
    );
}
