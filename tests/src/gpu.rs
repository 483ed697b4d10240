//! Helpers of the GPU backend's tests: one adapter per test binary (the
//! tests of a binary take turns on it), and renders of the same scene by
//! both backends.
//!
//! CI has no GPU: `.ci/run` installs Mesa's lavapipe, on which these run.
//! Without any adapter the tests fail, saying so.

use crate::{Tolerances, check_against};
use radiant::backend::cpu::{Progress, render};
use radiant::backend::gpu::{BvhLayout, GpuBackend, GpuOptions};
use radiant::extract::{Overrides, RenderScene, extract};
use radiant::film::Image;
use std::sync::{Mutex, MutexGuard, OnceLock};

/// The test binary's GPU backend.
pub fn backend() -> MutexGuard<'static, GpuBackend> {
    static BACKEND: OnceLock<Mutex<GpuBackend>> = OnceLock::new();
    let b =
        BACKEND.get_or_init(|| {
            // `expect` in this test code is the assertion: CI installs lavapipe,
            // so an adapter must be found.
            Mutex::new(GpuBackend::new(&GpuOptions::default()).expect(
                "a GPU adapter (install mesa-vulkan-drivers for lavapipe, as .ci/run does)",
            ))
        });
    // A test that panicked while holding the lock leaves a usable backend.
    b.lock().unwrap_or_else(|e| e.into_inner())
}

/// `scene` (relative to the workspace root) extracted with `overrides`.
pub fn extract_scene(scene: &str, overrides: &Overrides) -> RenderScene {
    let loaded = radiant::scene::load(crate::root().join(scene)).expect("scene loads");
    extract(&loaded, &radiant::builtin_registry(), overrides).expect("scene extracts")
}

/// The GPU's and the CPU's renders of `scene`: the same estimator, sampler
/// and filter sampling (the scene's, or `overrides.filter_sampling`), so the
/// same expectation.
pub fn render_both(scene: &str, overrides: &Overrides) -> (Image, Image) {
    render_both_on(&mut backend(), scene, overrides)
}

/// [`render_both`] with the GPU's hierarchies in `layout` (on an adapter
/// opened for it).
pub fn render_both_with_bvh(
    scene: &str,
    overrides: &Overrides,
    layout: BvhLayout,
) -> (Image, Image) {
    let options = GpuOptions {
        bvh: layout,
        ..GpuOptions::default()
    };
    // `expect` in this test code is the assertion, as in `backend`.
    let mut gpu = GpuBackend::new(&options)
        .expect("a GPU adapter (install mesa-vulkan-drivers for lavapipe, as .ci/run does)");
    render_both_on(&mut gpu, scene, overrides)
}

fn render_both_on(gpu: &mut GpuBackend, scene: &str, overrides: &Overrides) -> (Image, Image) {
    render_extracted_on(gpu, scene, &extract_scene(scene, overrides))
}

/// The GPU's and the CPU's renders of the extracted scene `r` (called
/// `name` in failures).
pub fn render_extracted(name: &str, r: &RenderScene) -> (Image, Image) {
    render_extracted_on(&mut backend(), name, r)
}

fn render_extracted_on(gpu: &mut GpuBackend, name: &str, r: &RenderScene) -> (Image, Image) {
    let gpu = gpu
        .render(r, &Progress::none())
        .unwrap_or_else(|e| panic!("{name}: the GPU render failed: {e}"));
    assert_eq!(
        gpu.invalid_samples, 0,
        "{name}: NaN or infinite GPU samples"
    );
    let cpu = render(r, &Progress::none());
    (gpu.image, cpu.image)
}

/// Checks that the GPU image matches the CPU one within `tolerances`
/// (8×8-pixel blocks), and that a 2 % scale of the GPU image would not.
pub fn assert_agrees(name: &str, (gpu, cpu): (Image, Image), tolerances: Tolerances) {
    let check = check_against(&gpu, &cpu, 8);
    eprintln!("{name}: {check:?}");
    assert!(
        tolerances.passes(&check),
        "{name}: the GPU render differs from the CPU's: {check:?}"
    );
    for scale in [0.98f32, 1.02] {
        let scaled = Image {
            pixels: gpu.pixels.iter().map(|p| *p * scale).collect(),
            ..gpu.clone()
        };
        let check = check_against(&scaled, &cpu, 8);
        assert!(
            !tolerances.passes(&check),
            "{name}: a {scale}× energy error would go unnoticed: {check:?}"
        );
    }
}
