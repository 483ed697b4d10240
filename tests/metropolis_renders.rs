//! The Metropolis integrators (`pssmlt`, `erpt`) against `path`: the same
//! image in expectation on the Cornell box, with and without smoke, and
//! finite, terminating renders of every torture scene.
//!
//! Why the Cornell box comparison is sound although Metropolis noise is
//! correlated: a chain's deposits cluster, neighbouring pixels and blocks
//! err together, and pssmlt's bootstrap scales a whole image by its error
//! in b, so the spread of pixels within one image says nothing about the
//! error of its blocks. The test therefore renders independent replicates
//! (different seeds) of each integrator and of `path`, and takes each
//! block's variance from the spread of that block's means *between*
//! replicates, which are independent whatever happens within one image.
//! Each block mean then gives Welch's t = (mean_A − mean_path) /
//! √(s²_A/K + s²_path/K); with K replicates of each it is at most as
//! heavy-tailed as Student's t with K − 1 degrees of freedom, whose
//! quantile at a Bonferroni-shared 1 % is the threshold (conservative).
//! The global mean, over replicates, must be within 1 % of path's, and
//! the same data scaled by 0.97 or 1.03 must fail that, so it has power.
//!
//! The whole-image splat film normalises a splat by the filter's whole
//! integral, while `path`'s tile film divides by the weights that landed:
//! the two differ within the filter's radius of the image's edge (the
//! outermost row is ~16 % darker with the Cornell box's Gaussian), so the
//! comparison leaves out a border of that width.

use radiant::extract::Overrides;
use radiant::film::Image;
use radiant_tests::{render_edited, root};
use statrs::distribution::{ContinuousCDF, StudentsT};

const SCENE: &str = "scenes/cornell-box.yaml";
/// Image size of the comparison.
const SIZE: u32 = 64;
/// Border left out (the Gaussian filter's radius, 2 pixels).
const BORDER: usize = 2;
/// Block edge in pixels: the interior (60 × 60) in 6 × 6 blocks.
const BLOCK: usize = 10;
/// Independent replicates of each integrator.
const REPLICATES: u64 = 16;

/// `text` with its integrator's `type: path` replaced by `integrator`
/// (flow or block style).
fn with_integrator(text: &str, integrator: &str) -> String {
    if text.contains("{type: path,") {
        text.replacen("{type: path,", &format!("{{type: {integrator},"), 1)
    } else if text.contains("{type: path}") {
        text.replacen("{type: path}", &format!("{{type: {integrator}}}"), 1)
    } else {
        let block = integrator.replace(", ", "\n  ");
        assert!(
            text.contains("\n  type: path\n"),
            "no integrator to replace"
        );
        text.replacen("\n  type: path\n", &format!("\n  type: {block}\n"), 1)
    }
}

fn render(scene: &str, integrator: &str, overrides: Overrides) -> radiant::backend::Rendered {
    render_edited(scene, |t| with_integrator(t, integrator), overrides)
}

/// Per block of the interior and channel, the block means of each image.
fn block_means(images: &[Image]) -> Vec<Vec<f64>> {
    let w = SIZE as usize;
    let blocks = (w - 2 * BORDER) / BLOCK;
    let mut out = vec![Vec::new(); blocks * blocks * 3];
    for image in images {
        for by in 0..blocks {
            for bx in 0..blocks {
                let mut sum = [0.0f64; 3];
                for y in BORDER + by * BLOCK..BORDER + (by + 1) * BLOCK {
                    for x in BORDER + bx * BLOCK..BORDER + (bx + 1) * BLOCK {
                        let p = image.pixels[y * w + x];
                        for (c, s) in sum.iter_mut().enumerate() {
                            *s += f64::from(p[c]);
                        }
                    }
                }
                for (c, s) in sum.iter().enumerate() {
                    out[(by * blocks + bx) * 3 + c].push(s / (BLOCK * BLOCK) as f64);
                }
            }
        }
    }
    out
}

fn mean_var(v: &[f64]) -> (f64, f64) {
    let m = v.iter().sum::<f64>() / v.len() as f64;
    let var = v.iter().map(|x| (x - m).powi(2)).sum::<f64>() / (v.len() - 1) as f64;
    (m, var)
}

/// Mean of the interior over all images.
fn interior_mean(images: &[Image]) -> f64 {
    let blocks = block_means(images);
    blocks.iter().flatten().sum::<f64>() / blocks.iter().map(Vec::len).sum::<usize>() as f64
}

fn replicates(integrator: &str, spp: u32) -> Vec<Image> {
    replicates_of(SCENE, integrator, spp)
}

fn replicates_of(scene: &str, integrator: &str, spp: u32) -> Vec<Image> {
    (0..REPLICATES)
        .map(|seed| {
            let r = render(
                scene,
                integrator,
                Overrides {
                    width: Some(SIZE),
                    height: Some(SIZE),
                    spp: Some(spp),
                    seed: Some(1000 + seed),
                    ..Default::default()
                },
            );
            assert!(r.image.pixels.iter().all(|p| p.is_finite()));
            r.image
        })
        .collect()
}

/// The largest |Welch t| over blocks and channels of `a` against `b`, and
/// the threshold it must stay below.
fn worst_t(a: &[Image], b: &[Image]) -> (f64, f64) {
    let (ma, mb) = (block_means(a), block_means(b));
    let worst = ma
        .iter()
        .zip(&mb)
        .map(|(x, y)| {
            let ((mx, vx), (my, vy)) = (mean_var(x), mean_var(y));
            (mx - my).abs() / (vx / x.len() as f64 + vy / y.len() as f64).sqrt()
        })
        .fold(0.0, f64::max);
    // 1 % shared over both integrators' block tests.
    let alpha = 0.01 / (2 * ma.len()) as f64;
    let t = StudentsT::new(0.0, 1.0, (REPLICATES - 1) as f64).expect("dof > 0");
    (worst, t.inverse_cdf(1.0 - alpha / 2.0))
}

#[test]
fn metropolis_integrators_converge_to_path_on_the_cornell_box() {
    let path = replicates("path", 256);
    let path_mean = interior_mean(&path);
    for integrator in [
        "pssmlt, bootstrap: 200000",
        "erpt, seeds: 64, chain_length: 16, bootstrap: 20000",
    ] {
        let images = replicates(integrator, 64);
        let mean = interior_mean(&images);
        let ratio = mean / path_mean;
        let (worst, threshold) = worst_t(&images, &path);
        let per: Vec<f64> = images
            .iter()
            .map(|i| interior_mean(std::slice::from_ref(i)))
            .collect();
        let per_path: Vec<f64> = path
            .iter()
            .map(|i| interior_mean(std::slice::from_ref(i)))
            .collect();
        let ((_, va), (_, vp)) = (mean_var(&per), mean_var(&per_path));
        let se = (va / per.len() as f64 + vp / per_path.len() as f64).sqrt() / path_mean;
        eprintln!(
            "{integrator}: interior mean {mean:.5} / path {path_mean:.5} = {ratio:.4} ± {se:.4}; \
             worst block |t| {worst:.2} (threshold {threshold:.2})"
        );
        assert!(
            (ratio - 1.0).abs() < 0.01,
            "{integrator}: mean ratio {ratio}"
        );
        assert!(
            worst < threshold,
            "{integrator}: a block mean differs: |t| = {worst}"
        );
        for scale in [0.97, 1.03] {
            assert!(
                (ratio * scale - 1.0).abs() >= 0.01,
                "a {scale}× energy error would pass"
            );
        }
    }
}

#[test]
fn metropolis_integrators_render_torture_scenes_finite_with_unlimited_depth() {
    let mut scenes: Vec<_> = std::fs::read_dir(root().join("scenes/hard"))
        .expect("scenes/hard exists")
        .map(|e| e.expect("readable entry").path())
        .filter(|p| p.extension().is_some_and(|e| e == "yaml"))
        .collect();
    scenes.sort();
    assert!(scenes.len() >= 15, "the suite has {} scenes", scenes.len());
    for path in scenes {
        let name = format!(
            "scenes/hard/{}",
            path.file_name().unwrap_or_default().to_string_lossy()
        );
        for integrator in [
            "pssmlt, bootstrap: 256, chains: 16",
            "erpt, bootstrap: 256, chain_length: 8",
        ] {
            let r = render(
                &name,
                integrator,
                Overrides {
                    max_depth: Some(-1),
                    spp: Some(4),
                    width: Some(8),
                    height: Some(8),
                    seed: Some(1),
                    ..Default::default()
                },
            );
            assert_eq!(
                r.invalid_samples, 0,
                "{name} ({integrator}): invalid splats"
            );
            assert!(
                r.image
                    .pixels
                    .iter()
                    .all(|p| p.is_finite() && p.min_element() >= 0.0),
                "{name} ({integrator}): non-finite or negative pixels"
            );
        }
    }
}

/// Media: the wavefront draws free-flight distances from the scene's
/// sampler, not from the chains, with numbers fresh for every proposal, so
/// the chains are a pseudo-marginal Metropolis method (the current
/// state keeps its own noisy estimate) and still converge to `path`'s
/// image. The smoky Cornell box (`scenes/media/cornell-smoke.yaml`), its
/// interior mean over independent replicates within 4 standard errors and
/// 2 % of path's.
#[test]
fn metropolis_integrators_converge_to_path_with_media() {
    let scene = "scenes/media/cornell-smoke.yaml";
    let per_image = |images: &[Image]| -> Vec<f64> {
        images
            .iter()
            .map(|i| interior_mean(std::slice::from_ref(i)))
            .collect()
    };
    let path = per_image(&replicates_of(scene, "path", 128));
    let (mp, vp) = mean_var(&path);
    for integrator in [
        "pssmlt, bootstrap: 50000",
        "erpt, seeds: 64, chain_length: 16, bootstrap: 20000",
    ] {
        let (m, v) = mean_var(&per_image(&replicates_of(scene, integrator, 32)));
        let se = (v / REPLICATES as f64 + vp / REPLICATES as f64).sqrt();
        eprintln!("{integrator}, smoke: interior mean {m:.5} / path {mp:.5} (± {se:.5})");
        assert!(
            (m - mp).abs() < 4.0 * se && (m / mp - 1.0).abs() < 0.02,
            "{integrator}: mean {m} against path's {mp} ± {se}"
        );
    }
}
