//! Progressive renders end to end: `--time` stops within one pass of its
//! limit, `--checkpoint` files appear while the render runs and are valid,
//! a render interrupted by SIGINT after its first checkpoint and resumed
//! gives the uninterrupted render's image bit for bit (a plain render
//! too, its samples written when Ctrl-C stops it; a sequence, whose
//! finished frames stay and whose current frame keeps its samples beside
//! its file), a PNG render keeps
//! its state beside it (and is encoded as a plain render encodes it), and
//! wrong `--resume` inputs are refused naming the file.

// `unwrap`/`expect` in this test code is the assertion: the inputs are the
// test's own, so a failure is a bug, and the panic reports it.

#[allow(dead_code)]
mod common;

use common::{arg, radiant, read, shot, stderr, wait_for_sigint_handler};
use radiant::farm::partial;
use std::path::{Path, PathBuf};
use std::process::{Child, Command, Output, Stdio};
use std::time::{Duration, Instant};

/// The arguments of `radiant render SCENE -o OUT` on the CPU with two
/// threads and `extra`.
fn render_args<'a>(scene: &'a Path, out: &'a Path, extra: &[&'a str]) -> Vec<&'a str> {
    let mut args = vec![
        "render",
        arg(scene),
        "-o",
        arg(out),
        "--backend",
        "cpu",
        "--threads",
        "2",
    ];
    args.extend(extra);
    args
}

/// Runs `radiant render SCENE -o OUT` on the CPU with `extra` options.
fn render(scene: &Path, out: &Path, extra: &[&str]) -> Output {
    radiant(&render_args(scene, out, extra))
}

/// Like [`render`], and checks that it succeeded; returns its stderr.
fn rendered(scene: &Path, out: &Path, extra: &[&str]) -> String {
    let o = render(scene, out, extra);
    assert!(o.status.success(), "{extra:?}: {}", stderr(&o));
    stderr(&o)
}

/// The number after `key` in `text` (`key` ends just before it).
fn number_after(text: &str, key: &str) -> f64 {
    let at = text
        .find(key)
        .unwrap_or_else(|| panic!("`{key}` in {text}"))
        + key.len();
    let digits: String = text[at..]
        .chars()
        .take_while(|c| c.is_ascii_digit() || *c == '.')
        .collect();
    digits.parse().unwrap()
}

/// Samples per pixel the state file `path` holds.
fn samples_in(path: &Path) -> u32 {
    partial::read_header(path).unwrap().samples.end
}

#[test]
fn time_limited_renders_stop_within_a_pass_of_the_limit() {
    let dir = tempfile::tempdir().unwrap();
    let scene = shot(dir.path(), "shot.yaml", "independent");
    let out = dir.path().join("timed.exr");
    let limit = 2.0;
    let started = Instant::now();
    let e = rendered(&scene, &out, &["--time", "2s", "--spp", "1000000"]);
    let wall = started.elapsed().as_secs_f64();
    // "time up: N of 1000000 spp in P passes (longest L s)" and the
    // render's time "in T s".
    let samples = number_after(&e, "time up: ") as u32;
    let passes = number_after(&e, "spp in ");
    let longest = number_after(&e, "(longest ");
    let time = number_after(&e, &format!(", {samples} spp in "));
    eprintln!("{samples} spp in {passes} passes, longest {longest} s, {time} s; wall {wall:.2} s");
    assert!(passes >= 2.0, "{e}");
    // Whole passes until the time is up: not short of the limit by more
    // than a pass, and past it by at most one pass (and some slack for a
    // loaded machine).
    let slack = 0.25;
    assert!(time >= limit - longest - slack, "{e}");
    assert!(time <= limit + longest + slack, "{e}");
    assert!(wall <= limit + longest + 20.0, "{wall}");
    // The file holds what was said.
    assert_eq!(samples_in(&out), samples);
    assert!(read(&out).mean() > 0.0);
}

/// Renders `scene` to `out` with `extra` options in a child process, sends
/// it SIGINT once `out` has appeared (its first checkpoint) and returns its
/// output.
fn interrupted(scene: &Path, out: &Path, extra: &[&str]) -> Output {
    let child = spawn_render(scene, out, extra);
    let deadline = Instant::now() + Duration::from_secs(120);
    while !out.exists() {
        assert!(Instant::now() < deadline, "no checkpoint in 120 s");
        std::thread::sleep(Duration::from_millis(20));
    }
    // A checkpoint is a valid image and state of some samples.
    let first = samples_in(out);
    assert!(first >= 1, "{first}");
    assert!(read(out).mean() > 0.0);
    interrupt(child)
}

/// Starts `radiant render SCENE -o OUT` with `extra` options on the CPU,
/// its stderr piped.
fn spawn_render(scene: &Path, out: &Path, extra: &[&str]) -> Child {
    Command::new(env!("CARGO_BIN_EXE_radiant"))
        .args(render_args(scene, out, extra))
        .current_dir(Path::new(env!("CARGO_MANIFEST_DIR")).join(".."))
        .stderr(Stdio::piped())
        .spawn()
        .unwrap()
}

/// Sends `child` SIGINT (Ctrl-C) and waits for it.
fn interrupt(child: Child) -> Output {
    let kill = Command::new("kill")
        .args(["-INT", &child.id().to_string()])
        .status()
        .unwrap();
    assert!(kill.success());
    child.wait_with_output().unwrap()
}

/// Enough samples per pixel for several seconds of `scene`: what one
/// second renders (a `--time` render into `dir`), times 8.
fn seconds_of_samples(scene: &Path, dir: &Path) -> String {
    let probe = dir.join("probe.exr");
    rendered(scene, &probe, &["--time", "1s", "--spp", "1000000"]);
    (samples_in(&probe) * 8).max(64).to_string()
}

#[test]
fn an_interrupted_render_resumes_into_the_uninterrupted_image() {
    let dir = tempfile::tempdir().unwrap();
    let scene = shot(dir.path(), "shot.yaml", "independent");
    let spp = seconds_of_samples(&scene, dir.path());

    let out = dir.path().join("frame.exr");
    let o = interrupted(&scene, &out, &["--spp", &spp, "--checkpoint", "0.2s"]);
    let e = stderr(&o);
    assert_eq!(o.status.code(), Some(130), "{e}");
    let held = samples_in(&out);
    assert!(held < spp.parse().unwrap(), "{e}");
    assert!(
        e.contains(&format!(
            "interrupted: {held} of {spp} spp written to {}; continue with --resume {}",
            out.display(),
            out.display()
        )),
        "{e}"
    );
    // No temporary file is left beside it.
    assert_eq!(std::fs::read_dir(dir.path()).unwrap().count(), 3);

    let e = rendered(
        &scene,
        &out,
        &["--spp", &spp, "--resume", arg(&out), "--checkpoint", "1s"],
    );
    assert!(e.contains(&format!("{spp} of {spp} spp")), "{e}");
    let single = dir.path().join("single.exr");
    rendered(&scene, &single, &["--spp", &spp]);
    let (resumed, single) = (read(&out), read(&single));
    assert!(resumed == single, "resumed image differs from one render");
    assert!(single.mean() > 0.0);
}

#[test]
fn a_plain_render_interrupted_keeps_its_samples_and_resumes() {
    let dir = tempfile::tempdir().unwrap();
    let scene = shot(dir.path(), "shot.yaml", "independent");
    let spp = seconds_of_samples(&scene, dir.path());

    // No --time, --checkpoint or --resume: a plain render, stopped by
    // Ctrl-C a second after it starts handling it.
    let out = dir.path().join("frame.png");
    let child = spawn_render(&scene, &out, &["--spp", &spp]);
    wait_for_sigint_handler(child.id());
    std::thread::sleep(Duration::from_secs(1));
    let o = interrupt(child);
    let e = stderr(&o);
    assert_eq!(o.status.code(), Some(130), "{e}");
    let state = dir.path().join("frame.png.resume.exr");
    let held = samples_in(&state);
    assert!(held >= 1 && held < spp.parse().unwrap(), "{held}: {e}");
    assert!(
        e.contains(&format!("interrupted: {held} of {spp} spp")),
        "{e}"
    );
    assert!(out.exists());

    // Resumed, it is the uninterrupted render, byte for byte; a plain
    // render that ends leaves no state beside its image.
    rendered(&scene, &out, &["--spp", &spp, "--resume", arg(&state)]);
    let single = dir.path().join("single.png");
    rendered(&scene, &single, &["--spp", &spp]);
    assert!(!dir.path().join("single.png.resume.exr").exists());
    assert!(std::fs::read(&out).unwrap() == std::fs::read(&single).unwrap());
}

/// Waits for at most 120 s until `path` exists.
fn wait_for(path: &Path) {
    let deadline = Instant::now() + Duration::from_secs(120);
    while !path.exists() {
        assert!(Instant::now() < deadline, "no {} in 120 s", path.display());
        std::thread::sleep(Duration::from_millis(20));
    }
}

/// Ctrl-C in a sequence: the finished frames stay, the frame in progress
/// keeps its samples as a state beside its file (and no image, so
/// `--skip-existing` would render it again), the later frames are not
/// started, the exit status is 130, and the kept frame resumed is the
/// uninterrupted render of that frame byte for byte.
#[test]
fn an_interrupted_sequence_keeps_its_frames_and_the_current_ones_samples() {
    let dir = tempfile::tempdir().unwrap();
    let scene = shot(dir.path(), "shot.yaml", "independent");
    // About two seconds of samples per frame.
    let probe = dir.path().join("probe.exr");
    rendered(&scene, &probe, &["--time", "1s", "--spp", "1000000"]);
    let spp = (samples_in(&probe) * 2).max(64).to_string();

    let out = dir.path().join("seq_####.png");
    let child = spawn_render(&scene, &out, &["--spp", &spp, "--frames", "1..3"]);
    let frame = |n: u32| dir.path().join(format!("seq_{n:04}.png"));
    wait_for(&frame(1));
    std::thread::sleep(Duration::from_millis(300));
    let o = interrupt(child);
    let e = stderr(&o);
    assert_eq!(o.status.code(), Some(130), "{e}");
    assert!(frame(1).exists(), "{e}");
    assert!(!frame(2).exists() && !frame(3).exists(), "{e}");
    let state = dir.path().join("seq_0002.png.resume.exr");
    let held = samples_in(&state);
    assert!(held >= 1 && held < spp.parse().unwrap(), "{held}: {e}");
    assert!(
        e.contains(&format!(
            "interrupted: frame 2's {held} of {spp} spp kept in {}",
            state.display()
        )),
        "{e}"
    );
    assert!(!dir.path().join("seq_0003.png.resume.exr").exists());

    rendered(
        &scene,
        &frame(2),
        &["--spp", &spp, "--frames", "2", "--resume", arg(&state)],
    );
    let single = dir.path().join("single.png");
    rendered(&scene, &single, &["--spp", &spp, "--frames", "2"]);
    assert!(std::fs::read(frame(2)).unwrap() == std::fs::read(&single).unwrap());
}

#[test]
fn a_png_render_keeps_its_state_beside_it() {
    let dir = tempfile::tempdir().unwrap();
    let scene = shot(dir.path(), "shot.yaml", "sobol");
    let png = dir.path().join("frame.png");
    let state = dir.path().join("frame.png.resume.exr");
    rendered(&scene, &png, &["--spp", "16", "--checkpoint", "10s"]);
    assert!(png.exists() && state.exists());
    assert_eq!(samples_in(&state), 16);
    // A PNG holds no state; the message points at the file beside it.
    let o = render(&scene, &png, &["--spp", "32", "--resume", arg(&png)]);
    assert!(!o.status.success());
    assert!(
        stderr(&o).contains(&format!(
            "cannot resume from `{}`: only EXR files hold a render's state; this render's state is in `{}`",
            png.display(),
            state.display()
        )),
        "{}",
        stderr(&o)
    );
    // Resumed from 16 to 32 samples, it is the 32-sample render (the
    // sobol sampler's samples do not depend on how many there are).
    rendered(&scene, &png, &["--spp", "32", "--resume", arg(&state)]);
    let exr = dir.path().join("single.exr");
    rendered(&scene, &exr, &["--spp", "32"]);
    assert_eq!(samples_in(&state), 32);
    assert!(read(&state) == read(&exr));
    // The PNG is encoded as the options say (16-bit, Reinhard), byte for
    // byte as a plain render of the same samples writes it.
    let encoded = ["--spp", "8", "--tonemap", "reinhard", "--bit-depth", "16"];
    let (checkpointed, plain) = (dir.path().join("kept.png"), dir.path().join("plain.png"));
    rendered(
        &scene,
        &checkpointed,
        &[&encoded[..], &["--checkpoint", "10s"]].concat(),
    );
    rendered(&scene, &plain, &encoded);
    assert!(std::fs::read(&checkpointed).unwrap() == std::fs::read(&plain).unwrap());
}

/// Runs a render resuming from `from` with `extra` options, expects it to
/// fail with each of `needles` in its message, and checks that it wrote
/// nothing.
fn refused(scene: &Path, from: &Path, extra: &[&str], needles: &[&str]) {
    let out = from.with_file_name("out.exr");
    let mut options = vec!["--resume", arg(from)];
    options.extend(extra);
    let o = render(scene, &out, &options);
    assert!(!o.status.success(), "{extra:?} succeeded");
    let e = stderr(&o);
    for needle in needles {
        assert!(e.contains(needle), "`{needle}` not in: {e}");
    }
    assert!(!out.exists(), "an output was left");
}

#[test]
fn wrong_resume_inputs_name_the_file() {
    let dir = tempfile::tempdir().unwrap();
    let scene = shot(dir.path(), "shot.yaml", "independent");
    let state = dir.path().join("state.exr");
    rendered(&scene, &state, &["--spp", "8", "--time", "60s"]);
    let name = |p: &PathBuf| format!("cannot resume from `{}`", p.display());
    // Another scene: the same file edited.
    let edited = dir.path().join("edited.yaml");
    let text = std::fs::read_to_string(&scene).unwrap();
    std::fs::write(&edited, text.replace("0.7", "0.6")).unwrap();
    refused(
        &edited,
        &state,
        &[],
        &[&name(&state), "it renders a different scene"],
    );
    refused(
        &scene,
        &state,
        &["--width", "16"],
        &[&name(&state), "different size (32x32 there, 16x32 here)"],
    );
    refused(
        &scene,
        &state,
        &["--seed", "99"],
        &[&name(&state), "different seed"],
    );
    refused(
        &scene,
        &state,
        &["--spp", "4"],
        &[
            &name(&state),
            "it holds 8 samples per pixel, more than the 4",
        ],
    );
    // A plain EXR and a PNG hold no state; a missing file is named.
    let plain = dir.path().join("plain.exr");
    rendered(&scene, &plain, &["--spp", "2"]);
    refused(
        &scene,
        &plain,
        &[],
        &[&name(&plain), "has no `radiant.", "--resume takes the EXR"],
    );
    let png = dir.path().join("plain.png");
    rendered(&scene, &png, &["--spp", "2"]);
    refused(
        &scene,
        &png,
        &[],
        &[&name(&png), "only EXR files hold a render's state"],
    );
    let missing = dir.path().join("missing.exr");
    refused(&scene, &missing, &[], &[&name(&missing)]);
    // A sample partition goes to `radiant merge`.
    let part = dir.path().join("part.exr");
    rendered(&scene, &part, &["--spp", "8", "--partition", "1/2"]);
    refused(
        &scene,
        &part,
        &["--spp", "8"],
        &[&name(&part), "it is sample partition 1/2 of a frame"],
    );
}

/// The options of a banded render of the shot, 64×512 pixels: with
/// `--whole-film-pixels 0` every frame renders in bands, as frames over
/// 16 Mpixels do (on 2 threads, groups of 8 tile rows: 128 rows).
const BANDED: [&str; 6] = [
    "--width",
    "64",
    "--height",
    "512",
    "--whole-film-pixels",
    "0",
];

/// Samples per pixel for about `seconds` seconds of a banded render of
/// `scene` (a one-second `--time` render of the same size into `dir`).
fn banded_samples(scene: &Path, dir: &Path, seconds: u32) -> String {
    let probe = dir.join("probe.exr");
    rendered(
        scene,
        &probe,
        &[&BANDED[..4], &["--time", "1s", "--spp", "1000000"]].concat(),
    );
    let spp = samples_in(&probe) * seconds;
    std::fs::remove_file(&probe).unwrap();
    spp.max(16).to_string()
}

/// Ctrl-C in a banded render: the file is written (atomically: nothing
/// else is left in the folder) with the rows of the bands finished so
/// far, those of the uninterrupted render bit for bit, and black below;
/// the render says how many rows and samples it holds and exits with 130.
#[test]
fn an_interrupted_banded_render_keeps_its_finished_rows() {
    let dir = tempfile::tempdir().unwrap();
    let scene = shot(dir.path(), "shot.yaml", "independent");
    let spp = banded_samples(&scene, dir.path(), 6);
    let options = [&BANDED[..], &["--spp", &spp]].concat();

    let out = dir.path().join("frame.exr");
    let child = spawn_render(&scene, &out, &options);
    wait_for_sigint_handler(child.id());
    std::thread::sleep(Duration::from_secs(2));
    let o = interrupt(child);
    let e = stderr(&o);
    assert_eq!(o.status.code(), Some(130), "{e}");
    let rows = number_after(&e, "interrupted: the top ") as usize;
    assert!(
        rows > 0 && rows < 512 && rows.is_multiple_of(128),
        "{rows}: {e}"
    );
    let samples = rows * 64 * spp.parse::<usize>().unwrap();
    assert!(
        e.contains(&format!(
            "interrupted: the top {rows} of 512 rows finished, {samples} samples ({spp} spp a \
             pixel), written to {}; the rows below are black",
            out.display()
        )),
        "{e}"
    );
    assert_eq!(std::fs::read_dir(dir.path()).unwrap().count(), 2, "{e}");

    let whole = dir.path().join("whole.exr");
    rendered(&scene, &whole, &options);
    let (cut, whole) = (read(&out), read(&whole));
    let at = rows * 64;
    // The last rows lack only the next band's splats; those above it are
    // the uninterrupted render's.
    let above = (rows - 4) * 64;
    assert!(cut.pixels[..above] == whole.pixels[..above]);
    let sum = |image: &radiant::film::Image| -> f32 {
        image.pixels[above..at]
            .iter()
            .map(|p| p.element_sum())
            .sum()
    };
    let (edge, whole_edge) = (sum(&cut), sum(&whole));
    assert!(
        (edge - whole_edge).abs() <= 0.25 * whole_edge,
        "{edge} {whole_edge}"
    );
    assert!(cut.pixels[at..].iter().all(|p| *p == glam::Vec3::ZERO));
}

/// Ctrl-C in a sequence of banded frames: the finished frames stay, the
/// frame in progress writes nothing (no file, no temporary file), and the
/// exit status is 130.
#[test]
fn an_interrupted_banded_sequence_keeps_only_its_finished_frames() {
    let dir = tempfile::tempdir().unwrap();
    let scene = shot(dir.path(), "shot.yaml", "independent");
    let spp = banded_samples(&scene, dir.path(), 2);
    let options = [&BANDED[..], &["--spp", &spp, "--frames", "1..3"]].concat();

    let out = dir.path().join("seq_####.exr");
    let child = spawn_render(&scene, &out, &options);
    let frame = |n: u32| dir.path().join(format!("seq_{n:04}.exr"));
    wait_for(&frame(1));
    std::thread::sleep(Duration::from_millis(500));
    let o = interrupt(child);
    let e = stderr(&o);
    assert_eq!(o.status.code(), Some(130), "{e}");
    assert!(frame(1).exists(), "{e}");
    assert!(!frame(2).exists() && !frame(3).exists(), "{e}");
    assert!(e.contains("interrupted: this frame is not written"), "{e}");
    assert_eq!(std::fs::read_dir(dir.path()).unwrap().count(), 2, "{e}");
}
