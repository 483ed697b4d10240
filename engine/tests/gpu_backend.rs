//! The GPU backend's library-level contract: WGSL traversal finds what the
//! CPU's BVH finds, an adapter that lacks a needed limit and a kernel that
//! does not compile are clear errors naming what is missing.
//!
//! These run on whatever adapter is found (lavapipe in CI).

// `unwrap`/`expect` in this test code is the assertion: the inputs are the
// test's own, and CI provides an adapter, so a failure is a bug.

use glam::Vec3;
use radiant::backend::gpu::probe::{Probe, ProbeKind};
use radiant::backend::gpu::{BvhLayout, GpuBackend, GpuError, GpuOptions};
use radiant::extract::{Overrides, RenderScene, extract};
use radiant_core::{GpuModule, GpuParams, TextureTable};
use std::path::Path;

fn backend() -> GpuBackend {
    GpuBackend::new(&GpuOptions::default())
        .expect("a GPU adapter (install mesa-vulkan-drivers for lavapipe, as .ci/run does)")
}

/// A scene of every kind of geometry: the Cornell box's rectangles and
/// cubes, spheres, a mesh with degenerate triangles, and instances of a
/// cube and of a sphere scattered through the box.
fn geometry_scene(instanced: bool) -> RenderScene {
    geometry_scene_with(instanced, instanced)
}

fn geometry_scene_with(pebbles: bool, bricks: bool) -> RenderScene {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("..");
    let base = std::fs::read_to_string(root.join("scenes/cornell-box.yaml")).unwrap();
    let mesh = root.join("scenes/hard/meshes/degenerate.obj");
    let mut text = base
        + &format!(
            "  - {{name: ball, type: sphere, radius: 0.3, material: white, transform: {{translate: [0.2, 0.1, 0.3]}}}}\n\
             \x20 - {{name: soup, type: mesh, filename: '{}', material: white, transform: [{{translate: [-0.3, 0.2, -0.2]}}, {{scale: 0.4}}]}}\n",
            mesh.display()
        );
    if pebbles {
        text += "  - name: pebbles\n    type: sphere\n    radius: 0.05\n    material: white\n    \
                 instances: {scatter: {count: 60, min: [-0.9, -0.9, -0.9], max: [0.9, 0.9, 0.9], seed: 3, scale: [0.5, 1.5]}}\n";
    }
    if bricks {
        text += "  - name: bricks\n    type: cube\n    material: white\n    transform: {scale: 0.04}\n    \
                 instances: {scatter: {count: 60, min: [-0.9, -0.9, -0.9], max: [0.9, 0.9, 0.9], seed: 5, scale: [0.5, 2]}}\n";
    }
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("geometry.yaml");
    std::fs::write(&path, text).unwrap();
    let scene = radiant::scene::load(&path).expect("the test scene loads");
    extract(&scene, &radiant::builtin_registry(), &Overrides::default()).unwrap()
}

/// Random rays from inside the box in every direction, with occlusion
/// distances from 0.05 to 3. (Render space has the camera, 3.9 in front of
/// the box's centre, at its origin.)
fn rays(n: usize) -> Vec<(Vec3, Vec3, f32, f32)> {
    let mut state = 0x2545_f491_4f6c_dd1du64;
    let mut next = move || {
        state ^= state << 13;
        state ^= state >> 7;
        state ^= state << 17;
        (state >> 40) as f32 / (1u64 << 24) as f32
    };
    (0..n)
        .map(|_| {
            let o = Vec3::new(next(), next(), next()) * 1.9 - Vec3::new(0.95, 0.95, 4.85);
            let z = 1.0 - 2.0 * next();
            let r = (1.0 - z * z).max(0.0).sqrt();
            let phi = std::f32::consts::TAU * next();
            let d = Vec3::new(r * phi.cos(), r * phi.sin(), z);
            (o, d, 0.05 + 2.95 * next(), 0.0)
        })
        .collect()
}

/// The GPU's closest hits and occlusion answers through hierarchies of
/// `layout` agree with the CPU's on all but a few rays (those within
/// rounding of an edge or a tie).
fn traversal_agrees(instanced: bool, layout: BvhLayout) {
    let scene = geometry_scene(instanced);
    assert_eq!(scene.accel.instances().len() > 1, instanced);
    let rays = rays(20_000);
    let gpu = backend().trace_rays(&scene, &rays, layout).unwrap();
    let (mut prim_mismatch, mut t_mismatch, mut occlusion_mismatch, mut hits) = (0, 0, 0, 0);
    for ((o, d, tmax, _), g) in rays.iter().zip(&gpu) {
        let cpu = scene.accel.intersect(*o, *d, f32::INFINITY);
        match cpu {
            Some(h) => {
                hits += 1;
                // Another primitive at the same distance is a tie (coplanar
                // faces, duplicated triangles), not an error.
                if g.prim != h.prim && (g.t - h.t).abs() > 1e-6 * h.t {
                    prim_mismatch += 1;
                }
                if (g.t - h.t).abs() > 1e-4 * h.t.max(1e-3) {
                    t_mismatch += 1;
                }
            }
            None => {
                if g.prim != u32::MAX {
                    prim_mismatch += 1;
                }
            }
        }
        if g.occluded != scene.accel.occluded(*o, *d, *tmax) {
            occlusion_mismatch += 1;
        }
    }
    eprintln!(
        "{layout:?}, instanced {instanced}: {hits} hits of {} rays; mismatches: primitive {prim_mismatch}, distance {t_mismatch}, occlusion {occlusion_mismatch}",
        rays.len()
    );
    assert!(hits > rays.len() * 8 / 10, "the rays should mostly hit");
    let allowed = rays.len() / 1000;
    assert!(
        prim_mismatch <= allowed && t_mismatch <= allowed && occlusion_mismatch <= allowed,
        "GPU traversal disagrees with the CPU's: primitive {prim_mismatch}, distance {t_mismatch}, occlusion {occlusion_mismatch} of {} rays",
        rays.len()
    );
}

#[test]
fn traversal_matches_the_cpu_on_meshes_and_spheres() {
    traversal_agrees(false, BvhLayout::Binary);
}

#[test]
fn traversal_matches_the_cpu_through_instances() {
    traversal_agrees(true, BvhLayout::Binary);
}

#[test]
fn wide_bvh_traversal_matches_the_cpu_on_meshes_and_spheres() {
    traversal_agrees(false, BvhLayout::Wide);
}

#[test]
fn wide_bvh_traversal_matches_the_cpu_through_instances() {
    traversal_agrees(true, BvhLayout::Wide);
}

#[test]
fn an_adapter_without_a_needed_limit_is_refused_naming_the_limit() {
    let options = GpuOptions {
        storage_buffer_bytes: Some(u64::MAX),
        ..GpuOptions::default()
    };
    match GpuBackend::new(&options) {
        Err(e @ GpuError::Limit { .. }) => {
            let message = e.to_string();
            assert!(
                message.contains("max_storage_buffer_binding_size"),
                "{message}"
            );
        }
        Err(e) => panic!("expected a limit error, got: {e}"),
        Ok(_) => panic!("an impossible limit was granted"),
    }
}

#[test]
fn a_compile_error_names_the_module_whose_code_caused_it() {
    let broken = GpuModule::new(
        "broken",
        "fn texture_broken(p: u32, uv: vec2f) -> vec3f {\n    return undefined_name;\n}\n",
        GpuParams::new(),
    );
    let textures = TextureTable::default();
    let probe = Probe {
        module: broken,
        kind: ProbeKind::Texture,
        textures: &textures,
        body: "output(i, 0u, texture_broken(P, vec2f(0.0)).x);",
        inputs_per_record: 1,
        outputs_per_record: 1,
    };
    match backend().probe(&probe, &[0.0]) {
        Err(GpuError::Compile { module, message }) => {
            assert_eq!(
                module.as_deref(),
                Some("the texture module `broken`"),
                "{message}"
            );
            assert!(message.contains("undefined_name"), "{message}");
        }
        Err(e) => panic!("expected a compile error, got: {e}"),
        Ok(_) => panic!("broken WGSL compiled"),
    }
}

#[test]
fn progressive_passes_add_up_to_one_render() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("..");
    let scene = radiant::scene::load(root.join("scenes/cornell-box.yaml")).unwrap();
    let overrides = Overrides {
        width: Some(24),
        height: Some(16),
        spp: Some(8),
        ..Overrides::default()
    };
    let r = extract(&scene, &radiant::builtin_registry(), &overrides).unwrap();
    let mut gpu = backend();
    let none = radiant::backend::Progress::none();
    let whole = gpu.render(&r, &none).unwrap().image;
    let mut film = radiant::film::Film::new(24, 16);
    for range in [0..3, 3..4, 4..8] {
        gpu.render_samples(&r, &mut film, range, &none).unwrap();
    }
    let passes = film.develop();
    for (a, b) in whole.pixels.iter().zip(&passes.pixels) {
        assert!(
            (*a - *b).abs().max_element() <= 1e-4 * a.max_element().max(1.0),
            "{a} against {b}"
        );
    }
    assert!(whole.mean() > 0.0);
}
