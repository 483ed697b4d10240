//! Motion blur against its definition: a render with the shutter open over
//! a motion must equal (in expectation) the average of renders of the
//! scene held still at times spread evenly over the shutter.
//!
//! The scenes make blur measurable: an orthographic camera looks at a
//! glowing backdrop (an area light seen directly, `max_depth: 1`, so every
//! sample is exact but for where and when it falls) with a black bar in
//! front that moves. A pixel's darkness is the fraction of the exposure
//! during which the bar covers it, so it measures how far the bar travels:
//! a motion 2 % too long darkens the swept region 2 % less. The motions
//! keep their speed beyond the shutter, so a shutter open 2 % longer is
//! such a motion: each test also renders it and asserts that the
//! comparison sees it.

use radiant::backend::cpu::{Progress, render};
use radiant::extract::{Overrides, Sequence, SequenceOptions};
use radiant::film::Image;
use std::path::Path;

/// Frames of the still reference (times (k + ½)/K of the shutter).
const STILL_FRAMES: u32 = 64;

/// Samples per pixel of the blurred render; each still frame gets
/// `BLUR_SPP / STILL_FRAMES`, so both averages hold as many samples.
const BLUR_SPP: u32 = 2048;

/// The scene: `camera` (with `look_at` and options), the bar's `bar`
/// shape keys, the animation block.
fn scene(animation: &str, camera: &str, bar: &str, spp: u32) -> String {
    format!(
        "integrator: {{type: path, max_depth: 1}}
film: {{width: 64, height: 16, filter: {{type: box}}}}
sampler: {{type: stratified, spp: {spp}}}
animation: {animation}
camera: {camera}
shapes:
  - type: rectangle
    transform: {{scale: [4, 4, 1]}}
    emitter: {{type: area, radiance: 1}}
  - type: rectangle
    material: {{type: diffuse, reflectance: 0}}
{bar}
"
    )
}

/// Renders frame `frame` of `text`.
fn render_frame(text: &str, frame: i64) -> Image {
    let mut scene = radiant::scene::from_str(text, Path::new("blur.yaml"), Path::new("."))
        .expect("the test scene parses");
    let registry = radiant::builtin_registry();
    let (sequence, _) = Sequence::new(
        &mut scene,
        &registry,
        &Overrides::default(),
        &SequenceOptions::default(),
        frame,
    )
    .expect("the test scene extracts");
    render(sequence.scene(), &Progress::none()).image
}

/// The darkness 1 − L of every pixel.
fn darkness(image: &Image) -> Vec<f64> {
    image.pixels.iter().map(|p| 1.0 - f64::from(p.x)).collect()
}

/// The average darkness of `STILL_FRAMES` still renders at times evenly
/// spread over the shutter [0, 1] s: frames 1, 3, …, 2K − 1 at 2K fps.
fn still_average(camera: &str, bar: &str) -> Vec<f64> {
    let k = STILL_FRAMES;
    let text = scene(
        &format!("{{fps: {}, frames: [1, {}]}}", 2 * k, 2 * k - 1),
        camera,
        bar,
        BLUR_SPP / k,
    );
    let mut sum = vec![0.0; 64 * 16];
    for i in 0..k {
        for (s, d) in sum
            .iter_mut()
            .zip(darkness(&render_frame(&text, 2 * i as i64 + 1)))
        {
            *s += d / k as f64;
        }
    }
    sum
}

/// The darkness of one render with the shutter open from time 0 to
/// `close` seconds (frame 0 at 1 fps).
fn blurred(camera: &str, bar: &str, close: f64) -> Vec<f64> {
    let open = camera
        .strip_suffix('}')
        .expect("the camera is a flow mapping");
    let camera = format!("{open}, shutter: [0, {close}]}}");
    let text = scene("{fps: 1, frames: [0, 0]}", &camera, bar, BLUR_SPP);
    darkness(&render_frame(&text, 0))
}

/// Compares blurred and still darkness where the motion sweeps: the
/// relative difference of the mean darkness over the pixels darker than
/// `floor` times the darkest (for a slide, the plateau whose darkness is
/// the bar's width over its travel), and the largest difference of a 4×4
/// block's mean.
fn compare(blur: &[f64], still: &[f64], floor: f64) -> (f64, f64) {
    let darkest = still
        .iter()
        .copied()
        .filter(|&d| d < 0.98)
        .fold(0.0, f64::max);
    let plateau: Vec<usize> = (0..still.len())
        .filter(|&i| still[i] >= floor * darkest && still[i] < 0.98)
        .collect();
    assert!(
        plateau.len() > 40,
        "the motion sweeps only {} pixels",
        plateau.len()
    );
    let mean = |d: &[f64]| plateau.iter().map(|&i| d[i]).sum::<f64>() / plateau.len() as f64;
    let relative = mean(blur) / mean(still) - 1.0;
    let mut worst_block: f64 = 0.0;
    for by in 0..4 {
        for bx in 0..16 {
            let block = |d: &[f64]| {
                let mut s = 0.0;
                for y in 0..4 {
                    for x in 0..4 {
                        s += d[(by * 4 + y) * 64 + bx * 4 + x];
                    }
                }
                s / 16.0
            };
            worst_block = worst_block.max((block(blur) - block(still)).abs());
        }
    }
    (relative, worst_block)
}

/// The largest difference of a 4×4 block's mean darkness that passes
/// (measured: at most 0.0033 for right blur, at least 0.0169 for a motion
/// 2 % too long).
const BLOCK_TOLERANCE: f64 = 0.008;

/// Asserts that blur with the shutter open over the whole motion matches
/// the still average, and that a shutter 2 % too long does not.
fn check(name: &str, camera: &str, bar: &str, floor: f64) {
    let still = still_average(camera, bar);
    let (relative, block) = compare(&blurred(camera, bar, 1.0), &still, floor);
    eprintln!(
        "{name}: plateau darkness {:+.3} %, worst block {block:.4}",
        relative * 100.0
    );
    assert!(
        relative.abs() < 0.004,
        "{name}: blur differs by {:.2} %",
        relative * 100.0
    );
    assert!(
        block < BLOCK_TOLERANCE,
        "{name}: a block differs by {block}"
    );
    // A shutter 2 % longer moves the bar 2 % farther in the exposure.
    let (wrong, wrong_block) = compare(&blurred(camera, bar, 1.02), &still, floor);
    eprintln!(
        "{name}: with a 2 % longer shutter {:+.3} %, worst block {wrong_block:.4}",
        wrong * 100.0
    );
    assert!(
        wrong.abs() > 0.008 || wrong_block > BLOCK_TOLERANCE,
        "{name}: a 2 % longer shutter went unnoticed ({:+.2} %, block {wrong_block})",
        wrong * 100.0
    );
}

const FRONT_CAMERA: &str = "{type: orthographic, width: 4, look_at: {origin: [0, 0, 5], target: [0, 0, 0], up: [0, 1, 0]}}";

#[test]
fn a_sliding_bar_blurs_as_the_average_of_its_positions() {
    // From x = −1.2 at time 0 to 1.2 at time 1, at constant speed.
    let bar = "    transform: [{translate: [0, 0, 1]}, {scale: [0.25, 3, 1]}]
    animation:
      translate:
        keyframes: [{time: -1, value: [-3.6, 0, 0]}, {time: 2, value: [3.6, 0, 0]}]";
    check("sliding bar", FRONT_CAMERA, bar, 0.7);
}

#[test]
fn a_turning_instance_blurs_as_the_average_of_its_poses() {
    // An instanced bar turning a quarter about its centre and the view
    // axis (slerp); where it is darker than a quarter of its darkest
    // (inside the sector it sweeps), darkness is its angular width over
    // the angle turned.
    let bar = "    transform: {scale: [0.3, 1.2, 1]}
    instances:
      - transform: {translate: [0, 0, 1]}
    animation:
      rotate:
        keyframes:
          - {time: -1, value: {axis: [0, 0, 1], angle: -130}}
          - {time: 0, value: {axis: [0, 0, 1], angle: -40}}
          - {time: 1, value: {axis: [0, 0, 1], angle: 50}}
          - {time: 2, value: {axis: [0, 0, 1], angle: 140}}";
    check("turning instance", FRONT_CAMERA, bar, 0.25);
}

#[test]
fn a_moving_camera_blurs_as_the_average_of_its_views() {
    let camera = "{type: orthographic, width: 4, look_at: {origin: {keyframes: [{time: -1, value: [-3, 0, 5]}, {time: 2, value: [3, 0, 5]}]}, target: {keyframes: [{time: -1, value: [-3, 0, 0]}, {time: 2, value: [3, 0, 0]}]}}}";
    let bar = "    transform: [{translate: [0, 0, 1]}, {scale: [0.3, 3, 1]}]";
    check("moving camera", camera, bar, 0.7);
}
