//! Motion blur on the GPU: rays carry a time in the shutter, moving
//! instances are placed where they are at that time, deforming meshes are
//! interpolated between their frames and a moving camera moves its rays.
//!
//! The traversal is checked ray by ray against the CPU's accelerator at
//! random times, and a blurred render against the CPU's render of the same
//! frame (same estimator and sampler dimensions, time included).

use glam::Vec3;
use radiant::backend::gpu::BvhLayout;
use radiant::extract::Overrides;
use radiant::film::Image;
use radiant_tests::gpu::{backend, extract_scene, render_both};
use radiant_tests::{Tolerances, check_against, write_grid};
use std::path::{Path, PathBuf};

/// A room with a tumbling cube, a spinning sphere, a rippling sheet (its
/// frames `wave_1.obj`, `wave_2.obj` written into `dir`) and a camera
/// dollying under a shutter open over the frame.
fn scene(dir: &Path) -> PathBuf {
    for f in 1..=2 {
        write_grid(
            &dir.join(format!("wave_{f}.obj")),
            12,
            f as f32 * 1.3,
            false,
        );
    }
    let text = "
animation: {fps: 24, frames: [1, 2]}
integrator: {type: path, max_depth: 4}
film: {width: 48, height: 48, filter: {type: gaussian, stddev: 0.5}}
sampler: {type: independent, spp: 64}
camera:
  type: perspective
  fov: 50
  shutter: [0, 1]
  look_at:
    origin: {keyframes: [{frame: 1, value: [0, 0.2, 3.6]}, {frame: 2, value: [0.4, 0.3, 3.4]}]}
    target: [0, 0, 0]
materials:
  white: {type: diffuse, reflectance: 0.7}
  red: {type: diffuse, reflectance: [0.7, 0.1, 0.1]}
  gold: {type: conductor, material: Au, alpha: 0.2}
shapes:
  - {type: rectangle, material: white, transform: [{translate: [0, -1, 0]}, {rotate: {axis: [1, 0, 0], angle: -90}}, {scale: 3}]}
  - {type: rectangle, material: white, transform: [{translate: [0, 0, -1.5]}, {scale: 3}]}
  - {type: rectangle, emitter: {type: area, radiance: 6}, transform: [{translate: [0, 1.4, 0]}, {rotate: {axis: [1, 0, 0], angle: 90}}, {scale: 0.5}]}
  - name: tumbling
    type: cube
    material: gold
    transform: {scale: 0.3}
    animation:
      translate: {keyframes: [{frame: 1, value: [-0.8, -0.4, 0]}, {frame: 2, value: [-0.2, 0.1, 0.3]}]}
      rotate: {keyframes: [{frame: 1, value: {axis: [1, 1, 0], angle: 0}}, {frame: 2, value: {axis: [1, 1, 0], angle: 150}}]}
  - name: spinning
    type: sphere
    radius: 0.3
    material: red
    animation:
      translate: {keyframes: [{frame: 1, value: [0.7, -0.5, 0]}, {frame: 2, value: [0.9, 0.2, -0.3]}]}
      scale: {keyframes: [{frame: 1, value: [1, 1, 1]}, {frame: 2, value: [1.5, 0.8, 1]}]}
  - type: mesh
    filename: wave_#.obj
    material: white
    transform: [{translate: [0, 0.3, -0.8]}, {scale: 0.5}]
";
    let path = dir.join("blur.yaml");
    // `expect` in this test code is the assertion: a temporary folder is
    // writable.
    std::fs::write(&path, text).expect("the test scene is written");
    path
}

/// Random rays through the room at random times in the shutter.
fn rays(n: usize) -> Vec<(Vec3, Vec3, f32, f32)> {
    let mut state = 0x9e37_79b9_7f4a_7c15u64;
    let mut next = move || {
        state ^= state << 13;
        state ^= state >> 7;
        state ^= state << 17;
        (state >> 40) as f32 / (1u64 << 24) as f32
    };
    (0..n)
        .map(|_| {
            // Render space is anchored at the camera: the room lies ahead
            // of it along −z.
            let o = Vec3::new(next() * 2.0 - 1.0, next() * 2.0 - 1.0, -3.6 + next() * 2.0);
            let z = 1.0 - 2.0 * next();
            let r = (1.0 - z * z).max(0.0).sqrt();
            let phi = std::f32::consts::TAU * next();
            let d = Vec3::new(r * phi.cos(), r * phi.sin(), z);
            (o, d, 0.05 + 2.95 * next(), next())
        })
        .collect()
}

/// The GPU's closest hits and occlusion answers at each ray's time
/// through hierarchies of `layout` agree with the CPU's accelerator at that
/// time, on all but a few rays (edges and ties within rounding). Distances
/// agree to 1e-4 relative, or 1e-5 absolute near the origin: the GPU makes
/// a moving placement in f32 with its own sin and acos (the slerp) and
/// inverts it there, the CPU in f64, which moves hits on a moving shape by
/// up to about 5e-6.
fn traversal_at_ray_times_agrees(layout: BvhLayout) {
    let dir = tempfile::tempdir().expect("a temporary folder");
    let scene = extract_scene(&scene(dir.path()).to_string_lossy(), &Overrides::default());
    assert!(scene.motion_blur() && scene.stats.deforming_meshes == 1);
    let rays = rays(20_000);
    let gpu = backend()
        .trace_rays(&scene, &rays, layout)
        .unwrap_or_else(|e| panic!("the GPU traces: {e}"));
    let (mut prim, mut dist, mut occl, mut hits, mut moving) = (0, 0, 0, 0, 0);
    for (&(o, d, tmax, tau), g) in rays.iter().zip(&gpu) {
        match scene.accel.intersect_at(o, d, f32::INFINITY, tau) {
            Some(h) => {
                hits += 1;
                moving += usize::from(scene.accel.instances().len() > 1 && h.inst > 0);
                if g.prim != h.prim && (g.t - h.t).abs() > 1e-6 * h.t {
                    prim += 1;
                }
                if (g.t - h.t).abs() > 1e-4 * h.t.max(0.1) {
                    dist += 1;
                }
            }
            None => prim += usize::from(g.prim != u32::MAX),
        }
        occl += usize::from(g.occluded != scene.accel.occluded_at(o, d, tmax, tau));
    }
    eprintln!(
        "{layout:?}: {hits} hits of {} rays ({moving} on moving or deforming shapes); mismatches: primitive {prim}, distance {dist}, occlusion {occl}",
        rays.len()
    );
    assert!(hits > rays.len() / 2, "the rays should mostly hit");
    assert!(moving > rays.len() / 50, "the rays should meet what moves");
    let allowed = rays.len() / 500;
    assert!(
        prim <= allowed && dist <= allowed && occl <= allowed,
        "GPU traversal at ray times disagrees with the CPU's: primitive {prim}, distance {dist}, occlusion {occl}"
    );
}

#[test]
fn traversal_at_ray_times_matches_the_cpu() {
    traversal_at_ray_times_agrees(BvhLayout::Binary);
}

#[test]
fn wide_bvh_traversal_at_ray_times_matches_the_cpu() {
    traversal_at_ray_times_agrees(BvhLayout::Wide);
}

/// The blurred frame renders on the GPU as on the CPU, and a 2 % energy
/// error would be noticed.
#[test]
fn motion_blurred_frame_matches_the_cpu() {
    let dir = tempfile::tempdir().expect("a temporary folder");
    let path = scene(dir.path());
    let (gpu, cpu) = render_both(&path.to_string_lossy(), &Overrides::default());
    let tolerances = Tolerances {
        channel_mean: 0.006,
        block: 0.06,
    };
    let check = check_against(&gpu, &cpu, 8);
    eprintln!("motion blur: {check:?}");
    assert!(tolerances.passes(&check), "{check:?}");
    for scale in [0.98f32, 1.02] {
        let scaled = Image {
            pixels: gpu.pixels.iter().map(|p| *p * scale).collect(),
            ..gpu.clone()
        };
        assert!(!tolerances.passes(&check_against(&scaled, &cpu, 8)));
    }
}

/// Frames reuse what did not change: a camera move keeps the geometry's
/// buffers (one upload for two frames) and lays out no bottom level again;
/// a moving shape and a deforming mesh upload their frame's geometry, and
/// only the deforming mesh's bottom level (and any after it whose place in
/// the arrays moved) is laid out again.
#[test]
fn frames_upload_only_changed_geometry() {
    use radiant::backend::cpu::Progress;
    use radiant::extract::{Sequence, SequenceOptions};
    let dir = tempfile::tempdir().expect("a temporary folder");
    let moving = std::fs::read_to_string(scene(dir.path())).expect("the scene reads");
    // The same scene with only the camera moving, and no shutter.
    let still = moving
        .replace("  shutter: [0, 1]\n", "")
        .split("  - name: tumbling")
        .next()
        .expect("the shapes precede the animated ones")
        .to_string();
    let registry = radiant::builtin_registry();
    let mut gpu = backend();
    for (text, uploads) in [(still, 1), (moving, 2)] {
        let mut loaded = radiant::scene::from_str(&text, Path::new("frames.yaml"), dir.path())
            .expect("the scene parses");
        let options = SequenceOptions::default();
        let (mut sequence, _) =
            Sequence::new(&mut loaded, &registry, &Overrides::default(), &options, 1)
                .expect("the scene extracts");
        let before = gpu.geometry_uploads();
        let built = gpu.levels_built();
        gpu.render(sequence.scene(), &Progress::none())
            .expect("frame 1 renders");
        let first = gpu.levels_built() - built;
        let levels = sequence.scene().accel.blases().len() as u64;
        sequence
            .go_to(&mut loaded, &registry, 2)
            .expect("frame 2 extracts");
        gpu.render(sequence.scene(), &Progress::none())
            .expect("frame 2 renders");
        let second = gpu.levels_built() - built - first;
        eprintln!("{levels} bottom levels: frame 1 laid out {first}, frame 2 {second}");
        assert_eq!(gpu.geometry_uploads() - before, uploads);
        assert_eq!(first, levels, "a new scene lays out every level");
        if uploads == 1 {
            assert_eq!(second, 0, "a camera move lays out no level again");
        } else {
            assert!((1..levels).contains(&second), "frame 2 laid out {second}");
        }
    }
}
