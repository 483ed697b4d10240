//! Helpers shared by Radiant's workspace-level tests: rendering a scene in
//! process and comparing images statistically.

use radiant::backend::cpu::{Progress, Rendered, render};
use radiant::extract::{Overrides, extract};
use radiant::film::Image;
use std::path::{Path, PathBuf};

/// The workspace root.
pub fn root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("..")
}

/// The mean of |a − b| over all channels, relative to the mean of `b`.
pub fn relative_difference(a: &Image, b: &Image) -> f64 {
    assert_eq!((a.width, a.height), (b.width, b.height));
    let (mut diff, mut sum) = (0.0f64, 0.0f64);
    for (p, q) in a.pixels.iter().zip(&b.pixels) {
        diff += f64::from((*p - *q).abs().element_sum());
        sum += f64::from(q.element_sum());
    }
    diff / sum
}

/// Renders the scene file `scene` (relative to the workspace root) with the
/// built-in modules.
pub fn render_scene(scene: &str, overrides: Overrides) -> Image {
    let scene = radiant::scene::load(root().join(scene)).expect("scene loads");
    let r = extract(&scene, &radiant::builtin_registry(), &overrides).expect("scene extracts");
    render(&r, &Progress::none()).image
}

/// Renders the scene file `scene` (relative to the workspace root) with its
/// text changed by `edit` first, for variants of a committed scene.
pub fn render_edited(
    scene: &str,
    edit: impl FnOnce(&str) -> String,
    overrides: Overrides,
) -> Rendered {
    let path = root().join(scene);
    let text = std::fs::read_to_string(&path).expect("scene readable");
    let dir = path.parent().expect("scene folder");
    let loaded =
        radiant::scene::from_str(&edit(&text), Path::new(scene), dir).expect("edited scene parses");
    let r = extract(&loaded, &radiant::builtin_registry(), &overrides).expect("scene extracts");
    render(&r, &Progress::none())
}

/// Renders like [`render_scene`] and checks what every torture case must
/// satisfy: no sample was NaN or infinite (the film would have recorded it
/// as black), every pixel is finite, and the image has the requested size.
pub fn render_checked(scene: &str, overrides: Overrides) -> Image {
    let loaded = radiant::scene::load(root().join(scene)).expect("scene loads");
    let r = extract(&loaded, &radiant::builtin_registry(), &overrides).expect("scene extracts");
    let rendered = render(&r, &Progress::none());
    assert_eq!(
        rendered.invalid_samples, 0,
        "{scene}: samples were NaN or infinite"
    );
    let image = rendered.image;
    assert_eq!(
        (image.width, image.height),
        (r.settings.width, r.settings.height),
        "{scene}: wrong image size"
    );
    assert!(
        image.pixels.iter().all(|p| p.is_finite()),
        "{scene}: non-finite pixels"
    );
    image
}

/// The primary rays (origin, unit direction; render space) of `scene`'s
/// camera through the film positions `film` (raster pixels), with the lens
/// sample at the aperture's centre.
pub fn camera_rays(
    scene: &radiant::extract::RenderScene,
    film: &[glam::Vec2],
) -> Vec<(glam::Vec3, glam::Vec3)> {
    use glam::{Vec2, Vec3};
    let n = film.len();
    let lens = vec![Vec2::splat(0.5); n];
    let (mut origins, mut directions, mut weights) =
        (vec![Vec3::ZERO; n], vec![Vec3::ZERO; n], vec![0.0; n]);
    scene.camera.generate(
        film,
        &lens,
        radiant_core::CameraRays {
            origins: &mut origins,
            directions: &mut directions,
            weights: &mut weights,
        },
    );
    origins.into_iter().zip(directions).collect()
}

/// The closed box [-1, 1]³ scaled by `scale` and moved to `offset`, as 12
/// triangles (two per face, corners in order) with outward normals.
pub fn box_triangles(scale: glam::Vec3, offset: glam::Vec3) -> Vec<[glam::Vec3; 3]> {
    use glam::Vec3;
    let faces = [
        (Vec3::X, Vec3::Y, Vec3::Z),
        (Vec3::NEG_X, Vec3::Z, Vec3::Y),
        (Vec3::Y, Vec3::Z, Vec3::X),
        (Vec3::NEG_Y, Vec3::X, Vec3::Z),
        (Vec3::Z, Vec3::X, Vec3::Y),
        (Vec3::NEG_Z, Vec3::Y, Vec3::X),
    ];
    let mut triangles = Vec::new();
    for (n, u, v) in faces {
        let c = [n - u - v, n + u - v, n + u + v, n - u + v].map(|p| p * scale + offset);
        triangles.push([c[0], c[1], c[2]]);
        triangles.push([c[0], c[2], c[3]]);
    }
    triangles
}

/// Mean of each colour channel.
pub fn channel_means(image: &Image) -> [f64; 3] {
    let mut m = [0.0f64; 3];
    for p in &image.pixels {
        for (c, v) in m.iter_mut().enumerate() {
            *v += p[c] as f64;
        }
    }
    m.map(|v| v / image.pixels.len() as f64)
}

/// Means of each colour channel over the whole `block`×`block` pixel
/// blocks of `image` (a partial last row or column of blocks is left out),
/// row-major.
pub fn block_channel_means(image: &Image, block: usize) -> Vec<[f64; 3]> {
    let w = image.width as usize;
    let (bw, bh) = (w / block, image.height as usize / block);
    let mut means = vec![[0.0f64; 3]; bw * bh];
    for by in 0..bh {
        for bx in 0..bw {
            let m = &mut means[by * bw + bx];
            for y in by * block..(by + 1) * block {
                for x in bx * block..(bx + 1) * block {
                    let p = image.pixels[y * w + x];
                    for (c, v) in m.iter_mut().enumerate() {
                        *v += f64::from(p[c]);
                    }
                }
            }
            *m = m.map(|v| v / (block * block) as f64);
        }
    }
    means
}

/// The result of comparing a render with a converged reference.
#[derive(Debug, Clone, PartialEq)]
pub struct ReferenceCheck {
    /// Largest |mean(render)/mean(reference) − 1| over the colour channels.
    pub worst_channel_mean_error: f64,
    /// Largest relative difference of a block mean.
    pub worst_block_error: f64,
}

/// Compares `image` with `reference` by channel means and by the means of
/// `block`×`block` pixel blocks.
pub fn check_against(image: &Image, reference: &Image, block: u32) -> ReferenceCheck {
    assert_eq!(
        (image.width, image.height),
        (reference.width, reference.height)
    );
    let (a, b) = (channel_means(image), channel_means(reference));
    let worst_channel_mean_error = (0..3)
        .map(|c| (a[c] / b[c] - 1.0).abs())
        .fold(0.0, f64::max);
    let ba = radiant::compare::block_means(image, block);
    let bb = radiant::compare::block_means(reference, block);
    let worst_block_error = ba
        .iter()
        .zip(&bb)
        .filter(|(_, r)| **r > 1e-3)
        .map(|(x, r)| (x / r - 1.0).abs())
        .fold(0.0, f64::max);
    ReferenceCheck {
        worst_channel_mean_error,
        worst_block_error,
    }
}

/// Writes an OBJ grid of `n`×`n` vertices over [−1, 1]² rippled by
/// `phase` (z = 0.2·sin(3x + phase)), without its first face where
/// `drop_face` (a changed topology): one frame of a deforming mesh.
pub fn write_grid(path: &std::path::Path, n: usize, phase: f32, drop_face: bool) {
    let mut text = String::new();
    for j in 0..n {
        for i in 0..n {
            let (x, y) = (
                i as f32 / (n - 1) as f32 * 2.0 - 1.0,
                j as f32 / (n - 1) as f32 * 2.0 - 1.0,
            );
            let z = 0.2 * (3.0 * x + phase).sin();
            text.push_str(&format!("v {x} {y} {z}\n"));
        }
    }
    for j in 0..n - 1 {
        for i in 0..n - 1 {
            if drop_face && i == 0 && j == 0 {
                continue;
            }
            let a = j * n + i + 1;
            text.push_str(&format!(
                "f {} {} {}\nf {} {} {}\n",
                a,
                a + 1,
                a + n + 1,
                a,
                a + n + 1,
                a + n
            ));
        }
    }
    std::fs::write(path, text).expect("temporary files are writable");
}

/// SplitMix64: a small deterministic generator of test inputs (the GPU
/// tests' random records).
#[derive(Debug, Clone)]
pub struct SplitMix(pub u64);

impl SplitMix {
    /// The next 64 random bits.
    pub fn bits(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9e37_79b9_7f4a_7c15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
        z ^ (z >> 31)
    }

    /// Uniform in [0, 1).
    pub fn unit(&mut self) -> f32 {
        (self.bits() >> 40) as f32 / (1u64 << 24) as f32
    }

    /// Uniform in 0..n (n ≥ 1).
    pub fn below(&mut self, n: u32) -> u32 {
        (self.bits() % n as u64) as u32
    }

    /// Uniform on the unit sphere (z, then the azimuth).
    pub fn sphere(&mut self) -> glam::Vec3 {
        let z = 1.0 - 2.0 * self.unit();
        let r = (1.0 - z * z).max(0.0).sqrt();
        let phi = 2.0 * std::f32::consts::PI * self.unit();
        glam::Vec3::new(r * phi.cos(), r * phi.sin(), z)
    }
}

pub mod chi2;
pub mod gpu;
pub mod shading;

/// Tolerances of a comparison with a converged reference.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Tolerances {
    /// Allowed |mean ratio − 1| per colour channel.
    pub channel_mean: f64,
    /// Allowed relative error of a block mean.
    pub block: f64,
}

impl Tolerances {
    /// Whether `check` is within these tolerances.
    pub fn passes(&self, check: &ReferenceCheck) -> bool {
        check.worst_channel_mean_error < self.channel_mean && check.worst_block_error < self.block
    }

    /// Asserts that `image` matches `reference` (blocks of `block` pixels)
    /// and that the same comparison rejects the image with 3 % too little or
    /// too much energy, so the tolerances have power.
    pub fn assert_matches(&self, image: &Image, reference: &Image, block: u32) {
        let check = check_against(image, reference, block);
        eprintln!("{check:?}");
        assert!(
            self.passes(&check),
            "render differs from the reference: {check:?}"
        );
        for scale in [0.97f32, 1.03] {
            let scaled = Image {
                pixels: image.pixels.iter().map(|p| *p * scale).collect(),
                ..image.clone()
            };
            let check = check_against(&scaled, reference, block);
            assert!(
                !self.passes(&check),
                "a {scale}× energy error went unnoticed: {check:?}"
            );
        }
    }
}
