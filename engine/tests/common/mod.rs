//! What the farm tests share: the binary, a small animated scene, and the
//! comparison of a merged frame with a single-machine render.

// `unwrap`/`expect` in this test code is the assertion: the inputs are the
// test's own, so a failure is a bug, and the panic reports it.

use radiant::film::Image;
use std::path::{Path, PathBuf};
use std::process::{Command, Output};
use std::time::{Duration, Instant};

/// A small animated room: a tumbling cube, a light that brightens and a
/// camera that moves over frames 1..12.
const SHOT: &str = "
integrator: {type: path, max_depth: 4}
film: {width: 32, height: 32}
sampler: {type: SAMPLER, spp: 16}
animation: {fps: 24, frames: [1, 12]}
camera:
  type: perspective
  fov: 40
  look_at:
    origin: {keyframes: [{frame: 1, value: [0, 0, 3.9]}, {frame: 12, value: [0.4, 0.2, 3.6]}]}
    target: [0, 0, 0]
materials:
  white: {type: diffuse, reflectance: 0.7}
  red: {type: diffuse, reflectance: [0.8, 0.1, 0.1]}
shapes:
  - {type: rectangle, material: white, transform: [{translate: [0, -1, 0]}, {rotate: {axis: [1, 0, 0], angle: -90}}]}
  - {type: rectangle, material: white, transform: {translate: [0, 0, -1]}}
  - type: cube
    material: red
    transform: {scale: 0.25}
    animation:
      translate: {keyframes: [{frame: 1, value: [-0.5, -0.5, 0]}, {frame: 12, value: [0.5, 0.2, 0]}]}
      rotate: {keyframes: [{frame: 1, value: {axis: [0, 1, 0], angle: 0}}, {frame: 12, value: {axis: [0, 1, 0], angle: 120}}]}
  - type: rectangle
    transform: [{translate: [0, 0.99, 0]}, {rotate: {axis: [1, 0, 0], angle: 90}}, {scale: 0.3}]
    emitter: {type: area, radiance: {keyframes: [{frame: 1, value: 8}, {frame: 12, value: 16}]}}
";

/// Runs `radiant` with `args` in the repository's root.
pub fn radiant(args: &[&str]) -> Output {
    radiant_with_path(args, None)
}

/// Runs `radiant` with `args`, and with `PATH` set to `path` where given.
pub fn radiant_with_path(args: &[&str], path: Option<&Path>) -> Output {
    let mut command = Command::new(env!("CARGO_BIN_EXE_radiant"));
    command
        .args(args)
        .current_dir(Path::new(env!("CARGO_MANIFEST_DIR")).join(".."));
    if let Some(path) = path {
        command.env("PATH", path);
    }
    command.output().expect("radiant runs")
}

/// Its standard error.
pub fn stderr(o: &Output) -> String {
    String::from_utf8_lossy(&o.stderr).into_owned()
}

/// Its standard output.
pub fn stdout(o: &Output) -> String {
    String::from_utf8_lossy(&o.stdout).into_owned()
}

/// Runs `radiant` and checks that it succeeded; returns its standard output.
pub fn ok(args: &[&str]) -> String {
    let o = radiant(args);
    assert!(
        o.status.success(),
        "radiant {args:?} failed: {}",
        stderr(&o)
    );
    stdout(&o)
}

/// Renders `frames` (`A..B` or `N`) of `scene` to `out` on this machine,
/// with `extra` options.
pub fn render(scene: &Path, frames: &str, out: &Path, extra: &[&str]) {
    let mut args = vec!["render", arg(scene), "--frames", frames, "-o", arg(out)];
    args.extend(extra);
    ok(&args);
}

/// `farm slurm SCENE -o OUT --frames FRAMES` and `extra` options.
pub fn farm_slurm<'a>(
    scene: &'a Path,
    out: &'a Path,
    frames: &'a str,
    extra: &[&'a str],
) -> Vec<&'a str> {
    let mut args = vec![
        "farm",
        "slurm",
        arg(scene),
        "-o",
        arg(out),
        "--frames",
        frames,
    ];
    args.extend(extra);
    args
}

/// Writes the animated scene with sampler `sampler` into `dir` as `name`.
pub fn shot(dir: &Path, name: &str, sampler: &str) -> PathBuf {
    let path = dir.join(name);
    std::fs::write(&path, SHOT.replace("SAMPLER", sampler)).expect("writes the scene");
    path
}

/// The path as text, for arguments.
pub fn arg(path: &Path) -> &str {
    path.to_str().expect("test paths are UTF-8")
}

/// The EXR image at `path`.
pub fn read(path: &Path) -> Image {
    radiant::film::output::read_exr(path).expect("an EXR image")
}

/// The largest difference between `a` and `b` relative to `b`'s brightest
/// channel value, and the number of bit-identical pixels.
pub fn difference(a: &Image, b: &Image) -> (f32, usize) {
    assert_eq!((a.width, a.height), (b.width, b.height));
    let peak = b
        .pixels
        .iter()
        .map(|p| p.max_element())
        .fold(0.0f32, f32::max);
    let largest = a
        .pixels
        .iter()
        .zip(&b.pixels)
        .map(|(p, q)| (*p - *q).abs().max_element())
        .fold(0.0f32, f32::max);
    let same = a
        .pixels
        .iter()
        .zip(&b.pixels)
        .filter(|(p, q)| p.to_array().map(f32::to_bits) == q.to_array().map(f32::to_bits))
        .count();
    (largest / peak, same)
}

/// Waits until process `pid` handles SIGINT (bit 1 of the `SigCgt` mask
/// in its /proc status), for at most 120 s.
#[allow(dead_code)] // The Ctrl-C tests' alone, not every test binary's.
pub fn wait_for_sigint_handler(pid: u32) {
    let deadline = Instant::now() + Duration::from_secs(120);
    loop {
        let status = std::fs::read_to_string(format!("/proc/{pid}/status")).unwrap();
        let caught = status
            .lines()
            .find_map(|l| l.strip_prefix("SigCgt:"))
            .map(|mask| u64::from_str_radix(mask.trim(), 16).unwrap())
            .unwrap();
        if caught & 2 != 0 {
            return;
        }
        assert!(Instant::now() < deadline, "SIGINT not handled in 120 s");
        std::thread::sleep(Duration::from_millis(20));
    }
}
