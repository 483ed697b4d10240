//! The GPU's wavefront kernel (`--gpu-kernel wavefront`) renders what the
//! CPU renders: the megakernel's estimator split into stages with queues,
//! stream compaction and regeneration, checked on the Cornell box, glass
//! and a textured mesh as `gpu_renders.rs` checks the megakernel. A small
//! pool of path slots makes every batch regenerate paths many times, and
//! with `--gpu-stats` each stage reports its GPU time where the adapter
//! has timestamp queries.

use radiant::backend::cpu::{Progress, render};
use radiant::backend::gpu::{GpuBackend, GpuKernel, GpuOptions};
use radiant::extract::Overrides;
use radiant_tests::gpu::extract_scene;
use radiant_tests::{Tolerances, check_against};
use std::sync::{Mutex, MutexGuard, OnceLock};

/// Path slots of the test pool: far fewer than a render's work items, and
/// not a multiple of the stages' workgroup size.
const POOL: u32 = 1000;

/// The test binary's wavefront backend, timing its stages.
fn wavefront() -> MutexGuard<'static, GpuBackend> {
    static BACKEND: OnceLock<Mutex<GpuBackend>> = OnceLock::new();
    let b =
        BACKEND.get_or_init(|| {
            let options = GpuOptions {
                kernel: GpuKernel::Wavefront,
                stats: true,
                wavefront_paths: Some(POOL),
                ..GpuOptions::default()
            };
            // `expect` in this test code is the assertion: CI installs lavapipe.
            Mutex::new(GpuBackend::new(&options).expect(
                "a GPU adapter (install mesa-vulkan-drivers for lavapipe, as .ci/run does)",
            ))
        });
    b.lock().unwrap_or_else(|e| e.into_inner())
}

/// Channel means within 0.6 %, 8×8 blocks within 6 % (as `gpu_renders.rs`).
const CLOSE: Tolerances = Tolerances {
    channel_mean: 0.006,
    block: 0.06,
};

/// Renders `scene` at 48² pixels and `spp` with the wavefront and on the
/// CPU, checks that the images agree, that every path was traced, and
/// that the stages were timed where the adapter can.
fn agrees(scene: &str, spp: u32) {
    let overrides = Overrides {
        width: Some(48),
        height: Some(48),
        spp: Some(spp),
        ..Overrides::default()
    };
    let r = extract_scene(scene, &overrides);
    let mut gpu = wavefront();
    let image = gpu
        .render(&r, &Progress::none())
        .unwrap_or_else(|e| panic!("{scene}: the wavefront render failed: {e}"));
    assert_eq!(image.invalid_samples, 0, "{scene}: NaN or infinite samples");
    let stats = gpu.last_stats();
    assert_eq!(stats.camera_rays, 48 * 48 * u64::from(spp));
    assert!(
        stats.shadow_rays > 0 && stats.nodes > 0,
        "{scene}: {stats:?}"
    );
    if gpu.times_stages() {
        let timed: Vec<&str> = stats.stages.millis().iter().map(|(s, _)| *s).collect();
        for stage in [
            "generate",
            "extend",
            "shade",
            "connect",
            "accumulate",
            "queues",
        ] {
            assert!(
                timed.contains(&stage),
                "{scene}: {stage} untimed: {timed:?}"
            );
        }
        assert!(!timed.contains(&"megakernel"), "{scene}: {timed:?}");
    }
    let cpu = render(&r, &Progress::none());
    let check = check_against(&image.image, &cpu.image, 8);
    eprintln!("{scene}: {check:?}; stages {:?}", stats.stages.millis());
    assert!(
        CLOSE.passes(&check),
        "{scene}: the wavefront render differs from the CPU's: {check:?}"
    );
}

#[test]
fn cornell_box() {
    agrees("scenes/cornell-box.yaml", 64);
}

#[test]
fn glass() {
    agrees("scenes/glass.yaml", 64);
}

#[test]
fn textured_mesh() {
    agrees("tests/data/uv/mesh.yaml", 64);
}
