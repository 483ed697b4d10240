//! Image output: every format Radiant writes read back within its
//! precision, the tone map in display formats only, banded (streamed)
//! renders equal to whole-image writes, the `film` keys' errors located in
//! the scene file, and `-o` defaulting to the scene's name.

// `unwrap`/`expect` in this test code is the assertion: the inputs are the
// test's own, so a failure is a bug, and the panic reports it.

use radiant::film::Image;
use radiant::film::encoding::{BitDepth, Encoding, ExrSamples};
use radiant::film::output::{read, srgb_encode, write_encoded};
use radiant::film::tonemap::{Curve, Tonemap};
use radiant_core::Rgb;
use std::path::{Path, PathBuf};
use std::process::Command;

/// A 13×7 image with values from 0 to 4 (some above display white) and a
/// smooth gradient, for lossy formats.
fn gradient() -> Image {
    let (w, h) = (13u32, 7u32);
    Image {
        width: w,
        height: h,
        pixels: (0..h)
            .flat_map(|y| (0..w).map(move |x| (x, y)))
            .map(|(x, y)| {
                let t = x as f32 / (w - 1) as f32;
                Rgb::new(t, 0.5 * t + 0.1 * y as f32, 4.0 * t * t)
            })
            .collect(),
    }
}

/// `image` clamped to [0, 1], as display formats store it (clamp curve).
fn clamped(image: &Image) -> Image {
    Image {
        pixels: image
            .pixels
            .iter()
            .map(|p| p.clamp(Rgb::ZERO, Rgb::ONE))
            .collect(),
        ..image.clone()
    }
}

/// Largest difference per channel between `a` and `b` after `f`.
fn max_diff(a: &Image, b: &Image, f: impl Fn(f32) -> f32) -> f32 {
    assert_eq!((a.width, a.height), (b.width, b.height));
    a.pixels
        .iter()
        .zip(&b.pixels)
        .flat_map(|(p, q)| (0..3).map(move |c| (p[c], q[c])))
        .map(|(x, y)| (f(x) - f(y)).abs())
        .fold(0.0, f32::max)
}

fn round_trip(name: &str, image: &Image, encoding: &Encoding) -> (tempfile::TempDir, Image) {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join(name);
    write_encoded(&path, image, encoding).unwrap();
    // Only the file: no temporary left beside it.
    assert_eq!(std::fs::read_dir(dir.path()).unwrap().count(), 1);
    let back = read(&path).unwrap();
    (dir, back)
}

#[test]
fn every_format_reads_back_within_its_precision() {
    let image = gradient();
    let float = Encoding::default();
    let (_d, exr) = round_trip("a.exr", &image, &float);
    assert_eq!(exr, image, "float EXR is exact");

    let half = Encoding {
        exr: ExrSamples::Half,
        ..Encoding::default()
    };
    let (_d, exr16) = round_trip("a.exr", &image, &half);
    for (p, q) in exr16.pixels.iter().zip(&image.pixels) {
        // 11 significant bits: half an ulp is 2^-11 of the value.
        assert!((*p - *q).abs().max_element() <= q.max_element() / 2048.0 + 1e-7);
    }
    assert_ne!(exr16, image, "half EXR rounds");

    let (_d, hdr) = round_trip("a.hdr", &image, &float);
    for (p, q) in hdr.pixels.iter().zip(&image.pixels) {
        // 8-bit mantissas of the largest channel.
        assert!((*p - *q).abs().max_element() <= q.max_element() / 128.0 + 1e-6);
    }

    // Display formats store the clamped sRGB encoding: 8 bits are within
    // half a step of it, 16 bits within half a 16-bit step.
    let (_d, png8) = round_trip("a.png", &image, &float);
    let e8 = max_diff(&png8, &clamped(&image), srgb_encode);
    assert!(e8 <= 0.5 / 255.0 + 1e-5, "{e8}");
    assert!(e8 > 0.5 / 65535.0, "8 bits quantize more coarsely");
    let sixteen = Encoding {
        bit_depth: BitDepth::Sixteen,
        ..Encoding::default()
    };
    let (dir, png16) = round_trip("a.png", &image, &sixteen);
    let e16 = max_diff(&png16, &clamped(&image), srgb_encode);
    assert!(e16 <= 0.5 / 65535.0 + 1e-6, "{e16}");
    let decoded = image::open(dir.path().join("a.png")).unwrap();
    assert_eq!(decoded.color(), image::ColorType::Rgb16);

    // JPEG is lossy: a smooth gradient stays within a few levels.
    for name in ["a.jpg", "a.jpeg"] {
        let (_d, jpeg) = round_trip(name, &image, &float);
        let mean: f32 = jpeg
            .pixels
            .iter()
            .zip(&clamped(&image).pixels)
            .map(|(p, q)| {
                (0..3)
                    .map(|c| (srgb_encode(p[c]) - srgb_encode(q[c])).abs())
                    .sum::<f32>()
            })
            .sum::<f32>()
            / (3 * image.pixels.len()) as f32;
        assert!(mean < 4.0 / 255.0, "{name}: mean error {mean}");
    }
}

#[test]
fn the_tone_map_changes_display_formats_only() {
    let image = gradient();
    let aces = Encoding {
        tonemap: Tonemap::new(Curve::Aces, 1.0).unwrap(),
        ..Encoding::default()
    };
    let (_d, exr) = round_trip("a.exr", &image, &aces);
    assert_eq!(exr, image, "EXR keeps the radiance");
    let (_d, png) = round_trip("a.png", &image, &{
        Encoding {
            bit_depth: BitDepth::Sixteen,
            ..aces
        }
    });
    for (p, q) in png.pixels.iter().zip(&image.pixels) {
        for c in 0..3 {
            // Narkowicz's curve of the exposed value, 2^1 · x.
            let x = 2.0 * q[c] as f64;
            let expected = ((x * (2.51 * x + 0.03)) / (x * (2.43 * x + 0.59) + 0.14)).min(1.0);
            assert!((p[c] as f64 - expected).abs() < 1e-3, "{x}: {}", p[c]);
        }
    }
}

/// The repository's root.
fn root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("..")
}

/// The Cornell box, small and at few samples.
fn small_cornell() -> radiant::extract::RenderScene {
    let scene = radiant::scene::load(root().join("scenes/cornell-box.yaml")).unwrap();
    let overrides = radiant::extract::Overrides {
        width: Some(37),
        height: Some(45),
        spp: Some(2),
        ..Default::default()
    };
    radiant::extract::extract(&scene, &radiant::builtin_registry(), &overrides).unwrap()
}

#[test]
fn banded_renders_write_the_same_files_as_whole_images() {
    let mut scene = small_cornell();
    let whole = radiant::backend::cpu::render(&scene, &radiant::backend::Progress::none()).image;
    let dir = tempfile::tempdir().unwrap();
    for (name, bit_depth, curve) in [
        ("a.png", BitDepth::Sixteen, Curve::Agx),
        ("a.png", BitDepth::Eight, Curve::Reinhard),
        ("a.hdr", BitDepth::Eight, Curve::Clamp),
        ("a.jpg", BitDepth::Eight, Curve::Aces),
        ("a.exr", BitDepth::Eight, Curve::Clamp),
    ] {
        scene.settings.output = Encoding {
            tonemap: Tonemap::new(curve, -0.5).unwrap(),
            bit_depth,
            ..Encoding::default()
        };
        let (streamed, reference) = (dir.path().join("s").join(name), dir.path().join(name));
        std::fs::create_dir_all(streamed.parent().unwrap()).unwrap();
        radiant::backend::cpu::write(&scene, &streamed, &radiant::backend::Progress::none())
            .unwrap();
        write_encoded(&reference, &whole, &scene.settings.output).unwrap();
        assert!(
            std::fs::read(&streamed).unwrap() == std::fs::read(&reference).unwrap(),
            "{name} {bit_depth:?} {curve:?}"
        );
    }
}

/// `film` of a scene with `film_keys`, loaded from text.
fn load_film(film_keys: &str) -> Result<radiant::scene::Scene, String> {
    let text = format!(
        "film: {{width: 8, height: 8, {film_keys}}}\n\
         camera: {{type: perspective, fov: 40, look_at: {{origin: [0, 0, 4], target: [0, 0, 0], up: [0, 1, 0]}}}}\n"
    );
    radiant::scene::from_str(&text, Path::new("film.yaml"), Path::new("."))
        .map_err(|e| e.to_string())
}

#[test]
fn film_output_keys_parse_and_bad_ones_are_located() {
    let s = load_film("tonemap: {type: agx, exposure: -1.5}, bit_depth: 16, exr: half").unwrap();
    let out = s.settings.output;
    assert_eq!(out.tonemap, Tonemap::new(Curve::Agx, -1.5).unwrap());
    assert_eq!(
        (out.bit_depth, out.exr),
        (BitDepth::Sixteen, ExrSamples::Half)
    );
    let plain = load_film("filter_sampling: splat").unwrap();
    assert_eq!(plain.settings.output, Encoding::default());
    for (keys, expected) in [
        ("tonemap: {type: filmic}", "film.yaml:1:"),
        ("tonemap: {type: filmic}", "aces"),
        ("tonemap: {type: aces, exposure: nan}", "finite"),
        ("tonemap: {type: aces, exposure: inf}", "finite"),
        ("tonemap: {type: aces, gamma: 2}", "gamma"),
        ("bit_depth: 12", "8 or 16"),
        ("exr: double", "half"),
        ("jpeg_quality: 0", "between 1 and 100"),
        ("tonemapping: aces", "tonemap"),
    ] {
        let e = load_film(keys)
            .err()
            .unwrap_or_else(|| panic!("{keys} loads"));
        assert!(e.contains(expected), "{keys}: {e}");
        assert!(e.starts_with("film.yaml:"), "{keys}: {e}");
    }
    // The exposure's own line and column.
    let e = load_film("tonemap: {type: aces, exposure: nan}")
        .err()
        .unwrap();
    assert!(e.starts_with("film.yaml:1:"), "{e}");
}

/// Runs `radiant` with `args` in `dir`.
fn radiant_in(dir: &Path, args: &[&str]) -> std::process::Output {
    Command::new(env!("CARGO_BIN_EXE_radiant"))
        .args(args)
        .current_dir(dir)
        .output()
        .expect("radiant runs")
}

#[test]
fn output_defaults_to_the_scene_name_and_options_reach_the_file() {
    let dir = tempfile::tempdir().unwrap();
    let scene = root().join("scenes/cornell-box.yaml");
    let scene = scene.to_str().unwrap();
    let small = ["--width", "24", "--height", "16", "--spp", "1"];
    let o = radiant_in(dir.path(), &[&["render", scene][..], &small].concat());
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let png = image::open(dir.path().join("cornell-box.png")).unwrap();
    assert_eq!((png.width(), png.height()), (24, 16));
    assert_eq!(png.color(), image::ColorType::Rgb8);

    let args = [
        "--tonemap",
        "agx",
        "--exposure",
        "-1",
        "--bit-depth",
        "16",
        "-o",
        "deep.png",
    ];
    let o = radiant_in(
        dir.path(),
        &[&["render", scene][..], &small, &args].concat(),
    );
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let deep = image::open(dir.path().join("deep.png")).unwrap();
    assert_eq!(deep.color(), image::ColorType::Rgb16);
    assert_ne!(deep.to_rgb8().into_raw(), png.to_rgb8().into_raw());

    let o = radiant_in(
        dir.path(),
        &[&["render", scene][..], &small, &["--half", "-o", "h.exr"]].concat(),
    );
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let meta = exr::meta::MetaData::read_from_file(dir.path().join("h.exr"), false).unwrap();
    let channels = &meta.headers[0].channels.list;
    assert!(
        channels
            .iter()
            .all(|c| c.sample_type == exr::meta::attribute::SampleType::F16)
    );

    for (bad, says) in [
        (&["--exposure", "nan"][..], "finite"),
        (&["--tonemap", "filmic"][..], "agx"),
        (&["--bit-depth", "12"][..], "8 or 16"),
    ] {
        let o = radiant_in(dir.path(), &[&["render", scene][..], &small, bad].concat());
        assert!(!o.status.success(), "{bad:?}");
        let err = String::from_utf8_lossy(&o.stderr);
        assert!(err.contains(says), "{bad:?}: {err}");
    }
}

#[test]
fn alpha_is_the_coverage_in_png_and_exr() {
    let dir = tempfile::tempdir().unwrap();
    // A sphere in the middle of an empty frame: opaque there, transparent
    // in the corners.
    let scene = dir.path().join("ball.yaml");
    std::fs::write(
        &scene,
        "film: {width: 24, height: 24, alpha: true}\n\
         sampler: {type: independent, spp: 4}\n\
         camera: {type: perspective, fov: 30, look_at: {origin: [0, 0, 4], target: [0, 0, 0], up: [0, 1, 0]}}\n\
         materials: {white: {type: diffuse, reflectance: 0.8}}\n\
         shapes: [{type: sphere, radius: 0.5, material: white}]\n\
         lights: [{type: point, position: [0, 2, 3], intensity: 20}]\n",
    )
    .unwrap();
    let scene = scene.to_str().unwrap();
    let o = radiant_in(dir.path(), &["render", scene, "-o", "ball.png"]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let png = image::open(dir.path().join("ball.png")).unwrap();
    assert_eq!(png.color(), image::ColorType::Rgba8);
    let png = png.to_rgba8();
    assert_eq!(png.get_pixel(12, 12).0[3], 255);
    assert_eq!(png.get_pixel(0, 0).0[3], 0);
    // Edge pixels are partly covered.
    assert!(png.pixels().any(|p| (1..255).contains(&p.0[3])));

    let o = radiant_in(dir.path(), &["render", scene, "-o", "ball.exr"]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let exr = exr::prelude::read_first_rgba_layer_from_file(
        dir.path().join("ball.exr"),
        |size, _| vec![[0.0f32; 4]; size.width() * size.height()],
        |pixels, pos, (r, g, b, a): (f32, f32, f32, f32)| {
            pixels[pos.y() * 24 + pos.x()] = [r, g, b, a]
        },
    )
    .unwrap();
    let pixels = &exr.layer_data.channel_data.pixels;
    assert_eq!(pixels[12 * 24 + 12][3], 1.0);
    assert_eq!(pixels[0][3], 0.0);
    // A progressive render keeps no coverage: refused before rendering.
    let o = radiant_in(
        dir.path(),
        &["render", scene, "-o", "t.png", "--time", "5s"],
    );
    assert!(!o.status.success());
    assert!(String::from_utf8_lossy(&o.stderr).contains("needs a whole render"));
    assert!(!dir.path().join("t.png").exists());
    // JPEG has no alpha channel: refused.
    let o = radiant_in(dir.path(), &["render", scene, "-o", "ball.jpg"]);
    assert!(!o.status.success());
    assert!(String::from_utf8_lossy(&o.stderr).contains("no alpha channel"));
}
