//! Texture tests: exact values at texel centres of a committed image,
//! bilinear interpolation between them, wrap modes, sRGB decoding and raw
//! data, every file format, the composite textures, and errors that name
//! the parameter's line and column.

// `unwrap` in this test code is the assertion: the inputs are the test's
// own, so a failure is a bug, and the panic reports it with the error.

use super::*;
use radiant_core::glam::Vec2;
use radiant_core::params::check_param_docs;
use radiant_core::registry::BuildError;
use radiant_core::{BuildContext, Params, Rgb, Texture, TextureId, TextureTable};
use std::collections::HashMap;
use std::path::{Path, PathBuf};

/// The committed 4×2 test image (tests/data/make_texels_png.py), top row first.
const TEXELS: [[[u8; 3]; 4]; 2] = [
    [[0, 0, 0], [255, 255, 255], [128, 64, 32], [10, 200, 30]],
    [[255, 0, 0], [0, 255, 0], [0, 0, 255], [50, 100, 150]],
];

fn data_dir() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/data")
}

/// Textures built through the registry into one table, as a scene would.
struct Scene {
    registry: radiant_core::Registry,
    textures: TextureTable,
    named: HashMap<String, TextureId>,
    dir: PathBuf,
}

impl Scene {
    fn new(dir: PathBuf) -> Self {
        let mut registry = radiant_core::Registry::new();
        register(&mut registry);
        Self {
            registry,
            textures: TextureTable::default(),
            named: HashMap::new(),
            dir,
        }
    }

    /// Builds texture `ty` from `yaml` and names it `name`.
    fn add(&mut self, name: &str, ty: &str, yaml: &str) -> Result<TextureId, BuildError> {
        let mut ctx = BuildContext::standalone(&self.dir, &mut self.textures, &self.named);
        let params = Params::from_yaml(yaml).expect("test YAML parses");
        let texture = self.registry.build::<dyn Texture>(ty, &params, &mut ctx)?;
        let id = self.textures.add(texture);
        self.named.insert(name.to_string(), id);
        Ok(id)
    }

    fn eval(&self, id: TextureId, uv: &[Vec2]) -> Vec<Rgb> {
        let mut out = vec![Rgb::ZERO; uv.len()];
        self.textures.eval(id, uv, &mut out);
        out
    }

    fn at(&self, id: TextureId, u: f32, v: f32) -> Rgb {
        self.eval(id, &[Vec2::new(u, v)])[0]
    }
}

fn linear(c: [u8; 3]) -> Rgb {
    Rgb::from_array(c.map(|x| srgb_to_linear(x as f32 / 255.0)))
}

fn raw(c: [u8; 3]) -> Rgb {
    Rgb::from_array(c.map(|x| x as f32 / 255.0))
}

/// The centre of texel (i, j), row j from the top, of a 4×2 image
/// (Mitsuba 3's texture space: v runs down the image).
fn centre(i: usize, j: usize) -> (f32, f32) {
    ((i as f32 + 0.5) / 4.0, (j as f32 + 0.5) / 2.0)
}

fn close(a: Rgb, b: Rgb, tol: f32) -> bool {
    (a - b).abs().max_element() <= tol
}

#[test]
fn documented_parameters_match() {
    check_param_docs::<bitmap::ImageParams>(bitmap::DOCS).unwrap();
    check_param_docs::<checkerboard::CheckerboardParams>(checkerboard::DOCS).unwrap();
    check_param_docs::<layered::LayeredParams>(layered::DOCS).unwrap();
    check_param_docs::<uv_transform::UvTransformParams>(uv_transform::DOCS).unwrap();
}

#[test]
fn texel_centres_hold_the_exact_decoded_values() {
    let mut s = Scene::new(data_dir());
    let colour = s.add("c", "image", "filename: texels-4x2.png").unwrap();
    let data = s
        .add("d", "image", "filename: texels-4x2.png\nraw: true")
        .unwrap();
    for (j, row) in TEXELS.iter().enumerate() {
        for (i, texel) in row.iter().enumerate() {
            let (u, v) = centre(i, j);
            assert!(
                close(s.at(colour, u, v), linear(*texel), 1e-6),
                "({i}, {j})"
            );
            assert!(close(s.at(data, u, v), raw(*texel), 1e-6), "raw ({i}, {j})");
        }
    }
    // The mean of a repeating bilinear image is the mean of its texels.
    let mean: Rgb = TEXELS.iter().flatten().map(|t| linear(*t)).sum::<Rgb>() / 8.0;
    assert!(close(s.textures.mean(colour), mean, 1e-6));
}

#[test]
fn bilinear_interpolates_between_centres_and_nearest_does_not() {
    let mut s = Scene::new(data_dir());
    let t = s.add("t", "image", "filename: texels-4x2.png").unwrap();
    let n = s
        .add("n", "image", "filename: texels-4x2.png\nfilter: nearest")
        .unwrap();
    let c = |i: usize, j: usize| linear(TEXELS[j][i]);
    // A quarter of the way from texel (1, 0) to (2, 0).
    let (u0, v0) = centre(1, 0);
    let got = s.at(t, u0 + 0.25 / 4.0, v0);
    assert!(close(got, c(1, 0) * 0.75 + c(2, 0) * 0.25, 1e-6), "{got}");
    // Midway between four centres: their average.
    let got = s.at(t, 0.5, 0.5);
    let avg = (c(1, 0) + c(2, 0) + c(1, 1) + c(2, 1)) * 0.25;
    assert!(close(got, avg, 1e-6), "{got} vs {avg}");
    // Nearest: the texel the point is in, however close to an edge (v
    // runs down the image: v < 0.5 is the top row).
    assert!(close(s.at(n, 0.499, 0.499), c(1, 0), 0.0));
    assert!(close(s.at(n, 0.501, 0.501), c(2, 1), 0.0));
}

#[test]
fn wrap_modes_repeat_clamp_and_mirror() {
    let mut s = Scene::new(data_dir());
    let modes = ["repeat", "clamp", "mirror"].map(|m| {
        s.add(
            m,
            "image",
            &format!("filename: texels-4x2.png\nwrap: {m}\nfilter: nearest"),
        )
        .unwrap()
    });
    let c = |i: usize, j: usize| linear(TEXELS[j][i]);
    let (_, v) = centre(0, 0);
    // One texel left of the image, one right, and 1.5 images to the right.
    let left = -0.5 / 4.0;
    let right = 1.0 + 0.5 / 4.0;
    let far = 2.0 + 1.5 / 4.0;
    let expect = [
        [c(3, 0), c(0, 0), c(1, 0)], // repeat
        [c(0, 0), c(3, 0), c(3, 0)], // clamp
        [c(0, 0), c(3, 0), c(1, 0)], // mirror: period 2 images
    ];
    for (m, e) in modes.iter().zip(expect) {
        for (u, want) in [left, right, far].into_iter().zip(e) {
            assert!(close(s.at(*m, u, v), want, 0.0), "mode {m:?} u {u}");
        }
    }
    // Mirroring in v: just above the top edge (v < 0) reads the top row.
    assert!(close(s.at(modes[2], 0.125, -0.2), c(0, 0), 0.0));
    // Bilinear + repeat blends across the seam; clamp does not.
    let r = s.add("r", "image", "filename: texels-4x2.png").unwrap();
    let k = s
        .add("k", "image", "filename: texels-4x2.png\nwrap: clamp")
        .unwrap();
    assert!(close(s.at(r, 0.0, v), (c(0, 0) + c(3, 0)) * 0.5, 1e-6));
    assert!(close(s.at(k, 0.0, v), c(0, 0), 1e-6));
    // Non-finite and huge coordinates give finite texels of the image.
    for texel in s.eval(r, &[Vec2::NAN, Vec2::INFINITY, Vec2::splat(-1e30)]) {
        assert!(texel.is_finite(), "{texel}");
        assert!(
            texel.min_element() >= 0.0 && texel.max_element() <= 1.0,
            "{texel}"
        );
    }
}

#[test]
fn srgb_images_round_trip_through_the_loader() {
    // Linear values → 8-bit sRGB PNG → texture: back within quantisation.
    let dir = tempfile::tempdir().unwrap();
    let values = [0.0f32, 0.001, 0.02, 0.1873, 0.5, 0.9, 1.0];
    let bytes: Vec<u8> = values
        .iter()
        .flat_map(|&x| {
            let e = (linear_to_srgb(x) * 255.0).round() as u8;
            [e, e, e]
        })
        .collect();
    image::RgbImage::from_raw(values.len() as u32, 1, bytes)
        .unwrap()
        .save(dir.path().join("ramp.png"))
        .unwrap();
    let mut s = Scene::new(dir.path().to_path_buf());
    let t = s
        .add("t", "image", "filename: ramp.png\nfilter: nearest")
        .unwrap();
    for (i, &x) in values.iter().enumerate() {
        let got = s.at(t, (i as f32 + 0.5) / values.len() as f32, 0.5);
        // Half an 8-bit step in sRGB, mapped to linear.
        let tol = 0.5 / 255.0 * 2.4 * x.max(0.01).powf(1.0 / 1.7) + 1e-6;
        assert!((got.x - x).abs() <= tol, "{x}: {}", got.x);
    }
}

#[test]
fn float_formats_are_linear_and_jpeg_is_decoded() {
    let dir = tempfile::tempdir().unwrap();
    let values = [Rgb::new(0.25, 2.0, 17.5), Rgb::new(0.0, 0.5, 1.0)];
    // EXR (f32): exact, with values above 1.
    {
        use exr::prelude::*;
        let channels = SpecificChannels::rgb(|p: Vec2<usize>| {
            let c = values[p.x()];
            (c.x, c.y, c.z)
        });
        Image::from_channels((2, 1), channels)
            .write()
            .to_file(dir.path().join("values.exr"))
            .unwrap();
    }
    // Radiance HDR: RGBE, an 8-bit mantissa.
    let hdr: Vec<image::Rgb<f32>> = values.iter().map(|c| image::Rgb(c.to_array())).collect();
    image::codecs::hdr::HdrEncoder::new(
        std::fs::File::create(dir.path().join("values.hdr")).unwrap(),
    )
    .encode(&hdr, 2, 1)
    .unwrap();
    // JPEG: a flat sRGB colour survives compression within a few steps.
    let flat = image::RgbImage::from_pixel(16, 16, image::Rgb([200, 100, 50]));
    flat.save(dir.path().join("flat.jpg")).unwrap();

    let mut s = Scene::new(dir.path().to_path_buf());
    let exr = s
        .add("e", "image", "filename: values.exr\nfilter: nearest")
        .unwrap();
    let hdr = s
        .add("h", "image", "filename: values.hdr\nfilter: nearest")
        .unwrap();
    let jpg = s.add("j", "image", "filename: flat.jpg").unwrap();
    for (i, want) in values.iter().enumerate() {
        let u = (i as f32 + 0.5) / 2.0;
        assert_eq!(s.at(exr, u, 0.5), *want);
        let got = s.at(hdr, u, 0.5);
        assert!(
            close(got, *want, want.max_element() / 128.0),
            "{got} vs {want}"
        );
    }
    assert!(close(s.at(jpg, 0.3, 0.6), linear([200, 100, 50]), 0.02));
}

#[test]
fn missing_and_unreadable_files_are_errors_at_the_filename() {
    let mut s = Scene::new(data_dir());
    for (file, needle) in [
        ("no-such-image.png", "cannot read image"),
        ("not-an-image.png", "cannot read image"),
        ("missing.exr", "cannot read image"),
    ] {
        let yaml = format!("wrap: clamp\nfilename: {file}\n");
        let Err(BuildError::Params(e)) = s.add("x", "image", &yaml) else {
            panic!("{file} should be rejected");
        };
        assert!(
            e.message.contains(needle) && e.message.contains(file),
            "{}",
            e.message
        );
        assert!(e.message.contains("PNG, JPEG, EXR or HDR"), "{}", e.message);
        let loc = e.location.expect("a location");
        assert_eq!((loc.line, loc.column), (2, 11), "{}", e.message);
    }
    let Err(BuildError::Params(e)) = s.add("x", "image", "wrap: sideways\nfilename: a.png") else {
        panic!("bad wrap mode accepted");
    };
    assert!(e.message.contains("sideways"), "{}", e.message);
    let Err(BuildError::Params(e)) = s.add("x", "image", "raw: true") else {
        panic!("missing filename accepted");
    };
    assert!(e.message.contains("filename"), "{}", e.message);
}

#[test]
fn checkerboard_alternates_and_repeats() {
    let mut s = Scene::new(data_dir());
    let t = s
        .add("c", "checkerboard", "color0: [1, 0, 0]\ncolor1: 0.25")
        .unwrap();
    let red = Rgb::X;
    let grey = Rgb::splat(0.25);
    for (u, v, want) in [
        (0.25, 0.25, red),
        (0.75, 0.25, grey),
        (0.25, 0.75, grey),
        (0.75, 0.75, red),
        (1.25, 0.25, red),
        (-0.25, 0.25, grey),
        (-0.25, -0.25, red),
    ] {
        assert_eq!(s.at(t, u, v), want, "({u}, {v})");
    }
    assert!(close(s.textures.mean(t), (red + grey) * 0.5, 1e-6));
    let d = s.add("d", "checkerboard", "{}").unwrap();
    assert_eq!(s.at(d, 0.1, 0.1), Rgb::splat(0.4));
}

#[test]
fn layered_blends_by_its_mask_and_uses_named_textures() {
    let mut s = Scene::new(data_dir());
    s.add("mask", "checkerboard", "color0: 1\ncolor1: [0, 0.5, 1]")
        .unwrap();
    let t = s
        .add(
            "l",
            "layered",
            "upper: [0.8, 0.6, 0.4]\nlower: 0.2\nmask: mask",
        )
        .unwrap();
    assert!(close(s.at(t, 0.25, 0.25), Rgb::new(0.8, 0.6, 0.4), 1e-6));
    // Per channel: lower + (upper − lower) · mask.
    assert!(close(s.at(t, 0.75, 0.25), Rgb::new(0.2, 0.4, 0.4), 1e-6));
    // A batch longer than one evaluation chunk.
    let uv: Vec<Vec2> = (0..300)
        .map(|i| Vec2::new(i as f32 / 300.0, 0.25))
        .collect();
    let out = s.eval(t, &uv);
    for (p, o) in uv.iter().zip(&out) {
        assert_eq!(*o, s.at(t, p.x, p.y));
    }
    let mean = (Rgb::new(0.8, 0.6, 0.4) + Rgb::new(0.2, 0.4, 0.4)) * 0.5;
    assert!(close(s.textures.mean(t), mean, 1e-5));
    let Err(BuildError::Params(e)) = s.add("x", "layered", "upper: 1\nlower: 0\nmask: nosuch")
    else {
        panic!("undefined mask accepted");
    };
    assert!(
        e.message.contains("undefined texture `nosuch`") && e.message.contains("mask"),
        "{}",
        e.message
    );
    assert_eq!(e.location.map(|l| l.line), Some(3));
}

#[test]
fn uv_transform_scales_rotates_and_offsets() {
    let mut s = Scene::new(data_dir());
    s.add("checks", "checkerboard", "color0: 1\ncolor1: 0")
        .unwrap();
    let t = s
        .add(
            "t",
            "uv_transform",
            "texture: checks\nscale: 4\nrotate: 90\noffset: [0.1, 0.2]",
        )
        .unwrap();
    // uv' = R(90°)(4 uv) + (0.1, 0.2) = (−4v + 0.1, 4u + 0.2).
    for (u, v) in [(0.01f32, 0.02f32), (0.3, 0.7), (0.55, 0.16)] {
        let mapped = Vec2::new(-4.0 * v + 0.1, 4.0 * u + 0.2);
        assert_eq!(
            s.at(t, u, v),
            s.at(s.named["checks"], mapped.x, mapped.y),
            "({u}, {v})"
        );
    }
    let a = s
        .add("a", "uv_transform", "texture: checks\nscale: [2, 0.5]")
        .unwrap();
    assert_eq!(s.at(a, 0.3, 0.9), s.at(s.named["checks"], 0.6, 0.45));
    assert!(close(s.textures.mean(a), Rgb::splat(0.5), 0.01));
    for (yaml, line, needle) in [
        ("texture: checks\nscale: [1, 2, 3]", 2, "2 values"),
        ("texture: checks\noffset: far", 2, "number or a [u, v] list"),
        ("scale: 2", 1, "texture"),
    ] {
        let Err(BuildError::Params(e)) = s.add("x", "uv_transform", yaml) else {
            panic!("{yaml:?} accepted");
        };
        assert!(e.message.contains(needle), "{yaml:?}: {}", e.message);
        assert_eq!(e.location.map(|l| l.line), Some(line), "{yaml:?}: {e:?}");
    }
}

#[test]
fn images_with_non_finite_texels_are_errors_at_the_filename() {
    use exr::prelude::*;
    let dir = tempfile::tempdir().unwrap();
    // A 3×2 image with NaN at column 2 of the top row and +∞ below it.
    write_rgb_file(dir.path().join("bad.exr"), 3, 2, |x, y| match (x, y) {
        (2, 0) => (f32::NAN, 0.5, 0.5),
        (2, 1) => (0.5, f32::INFINITY, 0.5),
        _ => (0.5, 0.5, 0.5),
    })
    .unwrap();
    let mut s = Scene::new(dir.path().to_path_buf());
    let Err(BuildError::Params(e)) = s.add("x", "image", "filename: bad.exr") else {
        panic!("an image with NaN texels should be rejected");
    };
    assert!(
        e.message.contains("2 NaN or infinite texels")
            && e.message.contains("column 2, row 0")
            && e.message.contains("bad.exr")
            && !e.message.contains("readable"),
        "{}",
        e.message
    );
    assert_eq!(e.location.map(|l| l.line), Some(1), "{}", e.message);
}
