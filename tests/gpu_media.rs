//! Participating media on the GPU backend render what the CPU renders:
//! homogeneous smoke behind a `null` boundary, a spot light's beam in a
//! global atmosphere the camera sits in (homogeneous and height fog), a
//! heterogeneous cloud grid, glowing fog, and a chromatic absorbing liquid
//! inside glass; and a scene without media gets a kernel without any
//! medium code.
//!
//! Both backends run the same estimator with the same sampler dimensions
//! (hero channel and distance per bounce, delta tracking's hashed streams
//! keyed alike), so their sample paths mostly coincide and the images
//! differ far less than their noise: a 2 % error in σs on the GPU side
//! moves the comparison out of its tolerances, which each test checks.

// `unwrap`/`expect` in this test code is the assertion: the scenes are the
// repository's own and CI provides an adapter (lavapipe), so a failure is
// a bug.

use radiant::backend::cpu::{Progress, render};
use radiant::backend::gpu::{GpuError, GpuKernel, GpuOptions, Plan};
use radiant::extract::{Overrides, RenderScene, extract};
use radiant::film::Image;
use radiant_tests::gpu::backend;
use radiant_tests::{Tolerances, check_against, root};
use std::path::Path;

/// `scene` (relative to the workspace root) with `edit` applied to its
/// text, at `size`² pixels and `spp`.
fn scene_edited(scene: &str, edit: &dyn Fn(&str) -> String, size: u32, spp: u32) -> RenderScene {
    let path = root().join(scene);
    let text = std::fs::read_to_string(&path).unwrap();
    let edited = edit(&text);
    let loaded =
        radiant::scene::from_str(&edited, Path::new(scene), path.parent().unwrap()).unwrap();
    let overrides = Overrides {
        width: Some(size),
        height: Some(size),
        spp: Some(spp),
        ..Overrides::default()
    };
    extract(&loaded, &radiant::builtin_registry(), &overrides).unwrap()
}

fn gpu_image(scene: &RenderScene) -> Image {
    let r = backend().render(scene, &Progress::none()).unwrap();
    assert_eq!(r.invalid_samples, 0, "NaN or infinite GPU samples");
    r.image
}

/// Means of every colour channel within 1 %, blocks of 8×8 pixels within
/// `block` (each test's own: the noise its scene leaves in the difference
/// of the two renders).
fn tolerances(block: f64) -> Tolerances {
    Tolerances {
        channel_mean: 0.01,
        block,
    }
}

/// Renders `scene` (edited by `edit`) on both backends and checks that the
/// GPU image matches the CPU one within the tolerances, and that the GPU
/// image of the scene with every `sigma_s: S` written as `sigma_s: 1.02·S`
/// (and 0.98·S) does not.
fn agrees(scene: &str, edit: &dyn Fn(&str) -> String, size: u32, spp: u32, block: f64) {
    let tolerances = tolerances(block);
    let r = scene_edited(scene, edit, size, spp);
    let cpu = render(&r, &Progress::none()).image;
    let gpu = gpu_image(&r);
    let check = check_against(&gpu, &cpu, 8);
    eprintln!("{scene}: {check:?}");
    assert!(
        tolerances.passes(&check),
        "{scene}: the GPU render differs from the CPU's: {check:?}"
    );
    for factor in [0.98, 1.02] {
        let wrong = scene_edited(scene, &|t: &str| scale_sigma_s(&edit(t), factor), size, spp);
        let check = check_against(&gpu_image(&wrong), &cpu, 8);
        eprintln!("{scene} with σs × {factor}: {check:?}");
        assert!(
            !tolerances.passes(&check),
            "{scene}: a {factor}× error in σs went unnoticed: {check:?}"
        );
    }
}

/// `text` with the value of every `sigma_s:` key (a number or a list of
/// three) multiplied by `factor`.
fn scale_sigma_s(text: &str, factor: f64) -> String {
    let mut out = String::new();
    let mut rest = text;
    let mut found = false;
    while let Some(at) = rest.find("sigma_s: ") {
        found = true;
        let (head, tail) = rest.split_at(at + "sigma_s: ".len());
        out.push_str(head);
        let end = tail.find(['\n', ',', '}']).unwrap();
        let (value, after) = if tail.starts_with('[') {
            let close = tail.find(']').unwrap() + 1;
            tail.split_at(close)
        } else {
            tail.split_at(end)
        };
        let scaled = |v: &str| (v.trim().parse::<f64>().unwrap() * factor).to_string();
        if let Some(list) = value.strip_prefix('[') {
            let items: Vec<String> = list.trim_end_matches(']').split(',').map(scaled).collect();
            out.push_str(&format!("[{}]", items.join(", ")));
        } else {
            out.push_str(&scaled(value));
        }
        rest = after;
    }
    assert!(found, "the scene has no sigma_s");
    out.push_str(rest);
    out
}

fn as_written(text: &str) -> String {
    text.to_string()
}

#[test]
fn smoke_in_the_cornell_box() {
    // Chromatic homogeneous smoke (HG g = 0.3) behind a `null` sphere.
    agrees(
        "scenes/media/cornell-smoke.yaml",
        &as_written,
        32,
        64,
        0.005,
    );
}

#[test]
fn fog_beam_in_a_homogeneous_atmosphere() {
    // The camera in a global atmosphere, a spot light in a vacuum bubble
    // (a `null` sphere with only an exterior), a ball's shadow in the beam.
    agrees("scenes/media/fog-beam.yaml", &as_written, 32, 64, 0.005);
}

#[test]
fn fog_beam_in_height_fog() {
    // The same beam in fog thinning upwards (closed-form optical depth
    // and its inverse).
    let fog = |t: &str| {
        assert!(t.contains("    type: homogeneous\n    sigma_s: 0.25\n"));
        t.replace(
            "    type: homogeneous\n    sigma_s: 0.25\n",
            "    type: height_fog\n    height: 0.5\n    scale_height: 1.5\n    sigma_s: 0.25\n",
        )
    };
    agrees("scenes/media/fog-beam.yaml", &fog, 32, 64, 0.005);
}

#[test]
fn cloud_grid() {
    // A 32³ density grid in a `null` cube under a sun and a sky: delta
    // tracking for distances, ratio tracking for shadow rays, through the
    // majorant grid's DDA.
    agrees("scenes/media/cloud.yaml", &as_written, 32, 256, 0.014);
}

#[test]
fn glowing_height_fog() {
    // Emission (σa·Le, the collision estimator) in height fog.
    // The fog box is lifted off the ground: coplanar faces are ties that
    // the two traversals may break differently (the path then leaves the
    // fog or not), which is not what this test is about.
    let lifted = |t: &str| {
        assert!(t.contains("{translate: [0, 0.8, 0]}"));
        t.replace("{translate: [0, 0.8, 0]}", "{translate: [0, 0.81, 0]}")
    };
    agrees("scenes/media/glowing-fog.yaml", &lifted, 32, 32, 0.005);
}

#[test]
fn chromatic_liquid_in_glass() {
    // Juice in a glass: a chromatic absorbing and weakly scattering medium
    // inside a dielectric sphere, under a sky and a spherical light.
    let juice = |t: &str| {
        t.replace("sigma_s: [6, 9, 7]", "sigma_s: [0.4, 0.3, 0.2]")
            .replace("sigma_a: [0.6, 0.1, 0.4]", "sigma_a: [0.1, 1.2, 3]")
            .replace("int_ior: 1.5", "int_ior: 1.33")
    };
    assert!(
        juice(&std::fs::read_to_string(root().join("scenes/media/jade.yaml")).unwrap())
            .contains("[0.1, 1.2, 3]")
    );
    agrees("scenes/media/jade.yaml", &juice, 32, 64, 0.005);
}

#[test]
fn a_scene_without_media_has_no_medium_code_in_its_kernel() {
    let overrides = Overrides::default();
    let plain = radiant_tests::gpu::extract_scene("scenes/cornell-box.yaml", &overrides);
    let source = Plan::new(&plain).unwrap().kernel.source;
    for word in [
        "medium_",
        "Medium",
        "MEDIUM",
        "media_",
        "phase_",
        "Stream",
        "shadow_transmittance",
        "BOUNCE_DIMS: u32 = 10u",
    ] {
        assert!(
            !source.contains(word),
            "the Cornell box's kernel contains `{word}`"
        );
    }
    let smoky = radiant_tests::gpu::extract_scene("scenes/media/cornell-smoke.yaml", &overrides);
    let plan = Plan::new(&smoky).unwrap();
    assert!(plan.kernel.features.media);
    for word in [
        "fn medium_flight_homogeneous(",
        "fn phase_sample_hg(",
        "fn bsdf_sample_null(",
        "fn shadow_transmittance(",
    ] {
        assert!(
            plan.kernel.source.contains(word),
            "the smoky Cornell box's kernel lacks `{word}`"
        );
    }
}

#[test]
fn the_wavefront_kernel_refuses_media_by_name() {
    let options = GpuOptions {
        kernel: GpuKernel::Wavefront,
        ..GpuOptions::default()
    };
    let mut gpu = radiant::backend::gpu::GpuBackend::new(&options).unwrap();
    let scene = scene_edited("scenes/media/smoke-dark.yaml", &as_written, 8, 1);
    let e = gpu.render(&scene, &Progress::none()).err().unwrap();
    assert!(matches!(e, GpuError::Unsupported { .. }), "{e}");
    let message = e.to_string();
    assert!(
        message.contains("participating media") && message.contains("--gpu-kernel megakernel"),
        "{message}"
    );
}
