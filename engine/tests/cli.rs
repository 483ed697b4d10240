//! The `radiant` command line, end to end.

// `unwrap` in this test code is the assertion: the inputs are the test's
// own, so a failure is a bug, and the panic reports it with the error.

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

fn radiant(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_radiant"))
        .args(args)
        .current_dir(Path::new(env!("CARGO_MANIFEST_DIR")).join(".."))
        .output()
        .expect("radiant runs")
}

fn stderr(o: &Output) -> String {
    String::from_utf8_lossy(&o.stderr).into_owned()
}

fn stdout(o: &Output) -> String {
    String::from_utf8_lossy(&o.stdout).into_owned()
}

fn temp(name: &str) -> (tempfile::TempDir, PathBuf) {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join(name);
    (dir, path)
}

#[test]
fn renders_the_default_scene_to_png_and_exr() {
    for ext in ["png", "exr"] {
        let (_dir, out) = temp(&format!("cornell.{ext}"));
        let o = radiant(&[
            "render",
            "scenes/cornell-box.yaml",
            "-o",
            out.to_str().unwrap(),
            "--spp",
            "2",
            "--width",
            "64",
            "--height",
            "48",
            "--threads",
            "2",
            "--seed",
            "3",
        ]);
        assert!(o.status.success(), "{}", stderr(&o));
        let last = stderr(&o).lines().last().unwrap_or_default().to_string();
        let pattern = regex_like(&last);
        assert!(pattern, "summary line malformed: {last}");
        assert!(last.starts_with("rendered 64x48, 2 spp in "), "{last}");
        assert!(out.exists());
    }
}

/// Checks `rendered WxH, N spp in T s (X Msamples/s, Y Mrays/s)`.
fn regex_like(line: &str) -> bool {
    let Some(rest) = line.strip_prefix("rendered ") else {
        return false;
    };
    let parts: Vec<&str> = rest.split_whitespace().collect();
    parts.len() == 10
        && parts[0].ends_with(',')
        && parts[1].parse::<u32>().is_ok()
        && parts[2] == "spp"
        && parts[3] == "in"
        && parts[4].parse::<f64>().is_ok()
        && parts[5] == "s"
        && parts[6].trim_start_matches('(').parse::<f64>().is_ok()
        && parts[7] == "Msamples/s,"
        && parts[8].parse::<f64>().is_ok()
        && parts[9] == "Mrays/s)"
}

#[test]
fn a_bad_scene_fails_with_its_location_and_writes_nothing() {
    let (dir, out) = temp("x.png");
    let scene = dir.path().join("bad.yaml");
    std::fs::write(&scene, "camera:\n  type: perspective\n  fov: wide\n").unwrap();
    let o = radiant(&[
        "render",
        scene.to_str().unwrap(),
        "-o",
        out.to_str().unwrap(),
    ]);
    assert!(!o.status.success());
    let err = stderr(&o);
    assert!(err.contains("bad.yaml:3:8"), "{err}");
    assert!(err.contains("expected a number"), "{err}");
    assert!(!out.exists());
    assert_eq!(
        std::fs::read_dir(dir.path()).unwrap().count(),
        1,
        "only the scene is there"
    );
}

#[test]
fn bad_arguments_are_refused_before_rendering() {
    let (_dir, out) = temp("x.bmp");
    let png = out.with_extension("png");
    let o = radiant(&[
        "render",
        "scenes/cornell-box.yaml",
        "-o",
        out.to_str().unwrap(),
    ]);
    assert!(!o.status.success());
    assert!(stderr(&o).contains(".exr or .hdr"), "{}", stderr(&o));
    assert!(!out.exists());

    let o = radiant(&[
        "render",
        "scenes/cornell-box.yaml",
        "-o",
        "/nonexistent/dir/x.png",
    ]);
    assert!(!o.status.success());
    assert!(stderr(&o).contains("does not exist"), "{}", stderr(&o));

    let o = radiant(&[
        "render",
        "scenes/cornell-box.yaml",
        "-o",
        png.to_str().unwrap(),
        "--spp",
        "0",
    ]);
    assert!(!o.status.success());
    assert!(stderr(&o).contains("--spp"), "{}", stderr(&o));
    assert!(!png.exists());
    let o = radiant(&["render", "scenes/missing.yaml", "-o", "x.png"]);
    assert!(!o.status.success());
    assert!(
        stderr(&o).contains("cannot read the scene file"),
        "{}",
        stderr(&o)
    );
    let o = radiant(&["render"]);
    assert_eq!(o.status.code(), Some(2), "usage errors exit with 2");
}

#[test]
fn info_reports_counts_modules_and_effects() {
    let o = radiant(&["info", "scenes/cornell-box.yaml"]);
    assert!(o.status.success(), "{}", stderr(&o));
    let out = stdout(&o);
    for needle in [
        "triangles    36",
        "lights       1 (1 on shapes)",
        "camera perspective",
        "light area",
        "filter gaussian",
        "shader diffuse",
        "sampler independent",
        "AREA_LIGHTS",
    ] {
        assert!(out.contains(needle), "`{needle}` missing from:\n{out}");
    }
}

#[test]
fn modules_lists_every_type_with_parameters() {
    let o = radiant(&["modules"]);
    assert!(o.status.success());
    let out = stdout(&o);
    for needle in [
        "cameras:",
        "perspective",
        "fov_axis",
        "lights:",
        "area",
        "point",
        "intensity",
        "filters:",
        "box",
        "gaussian",
        "stddev",
        "shaders:",
        "diffuse",
        "reflectance",
        "samplers:",
        "independent",
        "textures:",
        "constant",
    ] {
        assert!(out.contains(needle), "`{needle}` missing from:\n{out}");
    }
}

#[test]
fn compare_prints_metrics_and_rejects_size_mismatches() {
    let (dir, a) = temp("a.exr");
    let (b, wide) = (dir.path().join("b.exr"), dir.path().join("wide.exr"));
    for (path, w, seed) in [(&a, "16", "1"), (&b, "16", "2"), (&wide, "32", "1")] {
        let o = radiant(&[
            "render",
            "scenes/cornell-box.yaml",
            "-o",
            path.to_str().unwrap(),
            "--spp",
            "2",
            "--seed",
            seed,
            "--width",
            w,
            "--height",
            "16",
        ]);
        assert!(o.status.success(), "{}", stderr(&o));
    }
    // Two seeds: the printed metrics are the library's, and not zero.
    let o = radiant(&["compare", a.to_str().unwrap(), b.to_str().unwrap()]);
    assert!(o.status.success(), "{}", stderr(&o));
    let out = stdout(&o);
    let read = |p: &Path| radiant::film::output::read_exr(p).unwrap();
    let c = radiant::compare::compare(&read(&a), &read(&b)).unwrap();
    assert!(c.rmse > 1e-3, "different seeds give different images");
    for line in [
        format!("rmse {:.6}", c.rmse),
        format!("relative_mse {:.6}", c.relative_mse),
        format!("mean_ratio {:.6}", c.mean_ratio),
    ] {
        assert!(out.contains(&line), "`{line}` missing from:\n{out}");
    }
    let o = radiant(&["compare", a.to_str().unwrap(), wide.to_str().unwrap()]);
    assert!(!o.status.success());
    assert!(stderr(&o).contains("differ in size"), "{}", stderr(&o));
}

#[test]
fn mesh_repairs_are_warned_about_and_listed_by_info() {
    let (_dir, out) = temp("degenerate.exr");
    let scene = "scenes/hard/degenerate-mesh.yaml";
    let o = radiant(&[
        "render",
        scene,
        "-o",
        out.to_str().unwrap(),
        "--spp",
        "1",
        "--threads",
        "1",
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let warning = "bad mesh (scenes/hard/meshes/degenerate.obj): dropped 2 triangles with \
                   non-finite coordinates and 3 triangles of zero area, replaced 1 vertex normal";
    assert!(
        stderr(&o).contains(&format!("warning: {warning}")),
        "{}",
        stderr(&o)
    );
    let o = radiant(&["info", scene]);
    assert!(o.status.success(), "{}", stderr(&o));
    let text = stdout(&o);
    assert!(
        text.contains("repairs      2 non-finite and 4 degenerate triangles dropped, 1 vertex normals replaced, 1 texture coordinates reset"),
        "{text}"
    );
    assert!(text.contains(warning), "{text}");
}

// `radiant accuracy`: a small sweep writes its files; bad arguments are
// clear errors with a non-zero exit.

/// Asserts that `radiant accuracy …` fails without a panic, saying `needles`.
fn accuracy_fails_with(args: &[&str], needles: &[&str]) {
    let o = radiant(args);
    let err = stderr(&o);
    assert!(!o.status.success(), "{args:?} succeeded");
    assert!(!err.contains("panicked"), "{err}");
    for n in needles {
        assert!(err.contains(n), "`{n}` missing from: {err}");
    }
}

/// A film and spp cap that keep `radiant accuracy` runs short.
const SMALL: &[&str] = &["--width", "16", "--height", "16", "--max-spp", "8"];

#[test]
fn accuracy_small_sweep_writes_csv_plot_summary_and_reference() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("report");
    let mut args = vec![
        "accuracy",
        "scenes/cornell-box.yaml",
        "--only",
        "max_depth",
        "--budget",
        "60",
        "--out",
        out.to_str().unwrap(),
    ];
    args.extend_from_slice(SMALL);
    let o = radiant(&args);
    let err = stderr(&o);
    assert!(o.status.success(), "{err}");
    assert!(err.contains("reference: 128 spp"), "{err}");
    assert!(err.contains("max_depth=2: 8 spp"), "{err}");
    for f in [
        "accuracy.csv",
        "accuracy.png",
        "accuracy.md",
        "reference.exr",
    ] {
        assert!(out.join(f).is_file(), "{f} missing");
    }
    // The written reference is accepted back.
    let reference = out.join("reference.exr");
    let mut again = vec![
        "accuracy",
        "scenes/cornell-box.yaml",
        "--only",
        "spp",
        "--reference",
        reference.to_str().unwrap(),
        "--out",
        out.to_str().unwrap(),
    ];
    again.extend_from_slice(SMALL);
    let o = radiant(&again);
    assert!(o.status.success(), "{}", stderr(&o));
    let md = std::fs::read_to_string(out.join("accuracy.md")).unwrap();
    assert!(md.contains("read from a file"), "{md}");
}

#[test]
fn accuracy_bad_arguments_are_clear_errors() {
    let scene = "scenes/cornell-box.yaml";
    accuracy_fails_with(
        &["accuracy", scene, "--budget", "0"],
        &["--budget", "positive"],
    );
    accuracy_fails_with(&["accuracy", scene, "--budget", "-3"], &["--budget"]);
    accuracy_fails_with(
        &["accuracy", scene, "--budget", "inf"],
        &["--budget", "positive"],
    );
    accuracy_fails_with(
        &["accuracy", scene, "--reference-time", "0"],
        &["--reference-time"],
    );
    accuracy_fails_with(
        &["accuracy", scene, "--only", "spp,depth"],
        &["unknown axis `depth`", "max_depth", "light_selection"],
    );
    accuracy_fails_with(&["accuracy", scene, "--max-spp", "1"], &["--max-spp"]);
    accuracy_fails_with(&["accuracy", scene, "--width", "0"], &["--width"]);
    accuracy_fails_with(&["accuracy", scene, "--threads", "0"], &["--threads"]);
    accuracy_fails_with(
        &["accuracy", "scenes/missing.yaml"],
        &["scenes/missing.yaml"],
    );
    accuracy_fails_with(
        &["accuracy", scene, "--reference", "missing.exr"],
        &["missing.exr"],
    );
    accuracy_fails_with(
        &["accuracy", scene, "--out", "scenes/cornell-box.yaml"],
        &["not a folder"],
    );
}

#[test]
fn accuracy_reference_of_another_size_is_rejected() {
    let dir = tempfile::tempdir().unwrap();
    let reference = dir.path().join("ref.exr");
    let o = radiant(&[
        "render",
        "scenes/cornell-box.yaml",
        "-o",
        reference.to_str().unwrap(),
        "--spp",
        "1",
        "--width",
        "8",
        "--height",
        "8",
    ]);
    assert!(o.status.success());
    let mut args = vec![
        "accuracy",
        "scenes/cornell-box.yaml",
        "--reference",
        reference.to_str().unwrap(),
    ];
    args.extend_from_slice(SMALL);
    accuracy_fails_with(&args, &["8x8", "16x16", "--width"]);
}

#[test]
fn out_of_range_arguments_are_refused_with_the_allowed_range() {
    let (_dir, out) = temp("x.exr");
    let out = out.to_str().unwrap();
    for (flag, value, range) in [
        ("--width", "10000000", "1..=32768"),
        ("--height", "40000", "1..=32768"),
        ("--threads", "10000", "1..=1024"),
        ("--spp", "0", "1.."),
        ("--spp", "-4", "1.."),
        ("--spp", "2.5", "whole number"),
        ("--width", "-3", "1..=32768"),
        ("--threads", "-1", "1..=1024"),
        ("--max-depth", "-2", "-1.."),
    ] {
        let o = radiant(&["render", "scenes/cornell-box.yaml", "-o", out, flag, value]);
        assert_eq!(o.status.code(), Some(2), "{flag} {value}: {}", stderr(&o));
        let err = stderr(&o);
        assert!(err.contains(flag) && err.contains(range), "{err}");
        assert!(!Path::new(out).exists());
    }
    let o = radiant(&["accuracy", "scenes/cornell-box.yaml", "--width", "40000"]);
    assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
}

#[test]
fn output_paths_that_cannot_be_files_are_refused_before_rendering() {
    let dir = tempfile::tempdir().unwrap();
    let folder = dir.path().join("image.png");
    std::fs::create_dir(&folder).unwrap();
    let o = radiant(&[
        "render",
        "scenes/cornell-box.yaml",
        "-o",
        folder.to_str().unwrap(),
    ]);
    assert!(!o.status.success());
    assert!(stderr(&o).contains("it is a folder"), "{}", stderr(&o));

    let file = dir.path().join("plain");
    std::fs::write(&file, "").unwrap();
    let inside = file.join("x.png");
    let o = radiant(&[
        "render",
        "scenes/cornell-box.yaml",
        "-o",
        inside.to_str().unwrap(),
    ]);
    assert!(!o.status.success());
    assert!(stderr(&o).contains("is not a folder"), "{}", stderr(&o));
}

#[test]
fn a_scene_of_only_a_camera_and_a_sky_renders_the_sky() {
    let dir = tempfile::tempdir().unwrap();
    let scene = dir.path().join("sky.yaml");
    std::fs::write(
        &scene,
        "camera: {type: perspective}\nlights:\n  - {type: environment, radiance: 0.25}\n",
    )
    .unwrap();
    let out = dir.path().join("sky.exr");
    let o = radiant(&[
        "render",
        scene.to_str().unwrap(),
        "-o",
        out.to_str().unwrap(),
        "--width",
        "8",
        "--height",
        "8",
        "--spp",
        "2",
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let image = radiant::film::output::read_exr(&out).unwrap();
    for p in &image.pixels {
        assert!(
            (p.x - 0.25).abs() < 1e-6 && (p.z - 0.25).abs() < 1e-6,
            "{p}"
        );
    }
}

#[test]
fn compare_refuses_non_finite_images_and_names_both_sizes() {
    use radiant::film::Image;
    use radiant_core::Rgb;
    let dir = tempfile::tempdir().unwrap();
    let (nan, one, wide) = (
        dir.path().join("nan.exr"),
        dir.path().join("one.exr"),
        dir.path().join("wide.exr"),
    );
    let image = |width, value| Image {
        width,
        height: 2,
        pixels: vec![Rgb::splat(value); width as usize * 2],
    };
    radiant::film::output::write(&nan, &image(2, f32::NAN)).unwrap();
    radiant::film::output::write(&one, &image(2, 1.0)).unwrap();
    radiant::film::output::write(&wide, &image(3, 1.0)).unwrap();
    let o = radiant(&["compare", nan.to_str().unwrap(), one.to_str().unwrap()]);
    assert!(!o.status.success());
    assert!(
        stderr(&o).contains("4 pixels are NaN or infinite"),
        "{}",
        stderr(&o)
    );
    let o = radiant(&["compare", one.to_str().unwrap(), wide.to_str().unwrap()]);
    assert!(!o.status.success());
    let err = stderr(&o);
    assert!(
        err.contains("one.exr` is 2x2") && err.contains("wide.exr` is 3x2"),
        "{err}"
    );
}

/// A small animated scene: a cube sliding in front of a lit wall.
const ANIMATED: &str = "
animation: {fps: 24, frames: [1, 3]}
film: {width: 24, height: 24}
sampler: {type: independent, spp: 2}
camera: {type: perspective, look_at: {origin: [0, 0, 4], target: [0, 0, 0]}}
shapes:
  - {type: rectangle, transform: {translate: [0, 0, -1]}}
  - type: cube
    transform: {scale: 0.3}
    animation:
      translate: {keyframes: [{frame: 1, value: [-0.5, 0, 0]}, {frame: 3, value: [0.5, 0, 0]}]}
lights:
  - {type: point, position: [0, 0, 3], intensity: 10}
";

/// Writes the animated scene into a new folder; returns both.
fn animated_scene() -> (tempfile::TempDir, PathBuf) {
    let (dir, path) = temp("anim.yaml");
    std::fs::write(&path, ANIMATED).unwrap();
    (dir, path)
}

#[test]
fn frame_ranges_render_each_frame_to_its_numbered_file() {
    let (dir, scene) = animated_scene();
    let pattern = dir.path().join("f_##.exr");
    let o = radiant(&[
        "render",
        scene.to_str().unwrap(),
        "--frames",
        "1..3",
        "-o",
        pattern.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let err = stderr(&o);
    for f in 1..=3 {
        assert!(dir.path().join(format!("f_0{f}.exr")).exists(), "frame {f}");
        assert!(
            err.contains(&format!("frame {f}: rendered 24x24, 2 spp")),
            "{err}"
        );
    }
    let last = err.lines().last().unwrap_or_default();
    assert!(
        last.starts_with("sequence: 3 frames in ")
            && last.contains("scene update")
            && last.contains("BVH update")
            && last.contains("rendering"),
        "{last}"
    );
    // Frame 2 alone is frame 2 of the sequence, byte for byte.
    let single = dir.path().join("alone_#.exr");
    let o = radiant(&[
        "render",
        scene.to_str().unwrap(),
        "--frames",
        "2",
        "-o",
        single.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    assert_eq!(
        std::fs::read(dir.path().join("alone_2.exr")).unwrap(),
        std::fs::read(dir.path().join("f_02.exr")).unwrap()
    );
}

#[test]
fn skip_existing_resumes_a_sequence() {
    let (dir, scene) = animated_scene();
    let done = dir.path().join("f_2.png");
    std::fs::write(&done, b"finished earlier").unwrap();
    let o = radiant(&[
        "render",
        scene.to_str().unwrap(),
        "--frames",
        "1..3",
        "--skip-existing",
        "-o",
        dir.path().join("f_#.png").to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    assert_eq!(std::fs::read(&done).unwrap(), b"finished earlier");
    assert!(dir.path().join("f_1.png").exists() && dir.path().join("f_3.png").exists());
    let err = stderr(&o);
    assert!(!err.contains("frame 2:"), "{err}");
    assert!(
        err.contains("2 frames") && err.contains("1 existing frames skipped"),
        "{err}"
    );
}

#[test]
fn bad_frame_requests_fail_and_write_nothing() {
    let (dir, scene) = animated_scene();
    let s = scene.to_str().unwrap();
    let pattern = dir.path().join("f_#.png");
    let p = pattern.to_str().unwrap();
    for (args, needle) in [
        (
            vec!["--frames", "0..2", "-o", p],
            "outside the scene's frames 1..3",
        ),
        (
            vec!["--frames", "2..9", "-o", p],
            "outside the scene's frames 1..3",
        ),
        (vec!["--frames", "3..1", "-o", p], "empty"),
        (vec!["--frames", "x", "-o", p], "not a frame number"),
    ] {
        let mut full = vec!["render", s];
        full.extend(args);
        let o = radiant(&full);
        assert!(!o.status.success());
        assert!(stderr(&o).contains(needle), "{}", stderr(&o));
    }
    // Several frames need a run of `#` in the output name.
    let plain = dir.path().join("one.png");
    let o = radiant(&[
        "render",
        s,
        "--frames",
        "1..3",
        "-o",
        plain.to_str().unwrap(),
    ]);
    assert!(!o.status.success());
    assert!(stderr(&o).contains("put a run of `#`"), "{}", stderr(&o));
    let files: Vec<_> = std::fs::read_dir(dir.path()).unwrap().collect();
    assert_eq!(files.len(), 1, "only the scene file: {files:?}");
}

#[test]
fn info_reports_the_animation() {
    let (_dir, scene) = animated_scene();
    let o = radiant(&["info", scene.to_str().unwrap()]);
    assert!(o.status.success(), "{}", stderr(&o));
    let out = stdout(&o);
    assert!(
        out.contains("animation    frames 1..3 (3 at 24 fps), no shutter"),
        "{out}"
    );
    assert!(
        out.contains("animated     1 shapes moving, 0 deforming meshes"),
        "{out}"
    );
    assert!(out.contains("instances    2 in the top level"), "{out}");
}

#[test]
fn a_missing_frame_of_a_deforming_mesh_fails_before_any_frame_renders() {
    let (dir, scene) = temp("mesh.yaml");
    let grid = "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n";
    for f in [1, 2, 4] {
        std::fs::write(dir.path().join(format!("m_{f}.obj")), grid).unwrap();
    }
    std::fs::write(
        &scene,
        "animation: {frames: [1, 4]}\nfilm: {width: 8, height: 8}\nsampler: {type: independent, spp: 1}\n\
         camera: {type: perspective, look_at: {origin: [0, 0, 4], target: [0, 0, 0]}}\n\
         shapes:\n  - {type: mesh, filename: 'm_#.obj'}\n",
    )
    .unwrap();
    let o = radiant(&[
        "render",
        scene.to_str().unwrap(),
        "--frames",
        "1..4",
        "-o",
        dir.path().join("f_#.png").to_str().unwrap(),
    ]);
    assert!(!o.status.success());
    let err = stderr(&o);
    assert!(
        err.contains("frame 3") && err.contains("m_3.obj") && err.contains(":6:"),
        "{err}"
    );
    assert!(!dir.path().join("f_1.png").exists(), "a frame was written");
}

/// A frame whose film does not fit under the process's memory limit is
/// refused before rendering with what it needs and what would fit, exit
/// code 1 (not an allocation abort's 134), and no output file.
/// A trivial scene: one emitting sphere seen directly (1 segment), a box
/// filter; what a test of frame size renders fast.
const TRIVIAL_SCENE: &str = "\
integrator: {type: path, max_depth: 1}
film: {width: 64, height: 64, filter: {type: box}}
sampler: {type: independent, spp: 1}
camera:
  type: perspective
  fov: 40
  look_at: {origin: [0, 0, 4], target: [0, 0, 0], up: [0, 1, 0]}
shapes:
  - type: sphere
    center: [0, 0, 0]
    radius: 1
    material: {type: diffuse, reflectance: 0.5}
    emitter: {type: area, radiance: [1, 0.5, 0.25]}
";

/// Runs `radiant COMMAND TRIVIAL_SCENE ARGS…` under an address-space limit
/// of `limit` bytes (`prlimit`), the scene written into `dir`.
fn trivial_under_limit(dir: &Path, limit: u64, command: &str, args: &[&str]) -> Output {
    let scene = dir.join("trivial.yaml");
    std::fs::write(&scene, TRIVIAL_SCENE).expect("the scene is written");
    Command::new("prlimit")
        .arg(format!("--as={limit}"))
        .arg(env!("CARGO_BIN_EXE_radiant"))
        .arg(command)
        .arg(&scene)
        .args(args)
        .output()
        .expect("prlimit (util-linux) runs")
}

#[test]
fn a_frame_larger_than_memory_renders_in_bands() {
    // The whole film of 8192² pixels needs 1.75 GiB; under a 1.2 GB
    // address-space limit the CPU backend renders it in bands of rows and
    // streams them to the file.
    let (dir, out) = temp("huge.exr");
    let size = ["--backend", "cpu", "--width", "8192", "--height", "8192"];
    let o = trivial_under_limit(
        dir.path(),
        1_200_000_000,
        "render",
        &[&size[..], &["-o", out.to_str().expect("a UTF-8 path")]].concat(),
    );
    let err = stderr(&o);
    assert_eq!(o.status.code(), Some(0), "{err}");
    assert!(err.contains("rendered 8192x8192, 1 spp"), "{err}");
    let image = radiant::film::output::read_exr(&out).expect("the EXR reads back");
    assert_eq!((image.width, image.height), (8192, 8192));
    assert!(image.pixels.iter().all(|p| p.is_finite()));
    // The sphere is in the middle, the corners see nothing.
    let at = |x: usize, y: usize| image.pixels[y * 8192 + x];
    assert_eq!(at(4096, 4096).x, 1.0);
    assert_eq!(at(0, 0).x, 0.0);
    assert_eq!(std::fs::read_dir(dir.path()).expect("listed").count(), 2);
}

#[test]
fn a_band_larger_than_memory_is_a_clear_error() {
    // A band of a 32768-pixel-wide frame (one tile row with the filter's
    // border, the rows on their way to the file, a group of tiles and the
    // encoder's blocks) needs about 160 MB (the film's and the tiles' exact
    // sums take 64 bytes a pixel), more than a 60 MB
    // address-space limit leaves after the program itself (about 30 MB
    // with two threads).
    let (dir, out) = temp("huge.exr");
    let size = [
        "--backend",
        "cpu",
        "--threads",
        "2",
        "--width",
        "32768",
        "--height",
        "32768",
    ];
    let o = trivial_under_limit(
        dir.path(),
        60_000_000,
        "render",
        &[&size[..], &["-o", out.to_str().expect("a UTF-8 path")]].concat(),
    );
    let err = stderr(&o);
    assert_eq!(o.status.code(), Some(1), "{err}");
    assert!(
        err.contains("a 32768×32768 frame rendered in bands of"),
        "{err}"
    );
    assert!(err.contains("GiB for the band's weighted sums"), "{err}");
    assert!(err.contains("pixels wide"), "{err}");
    assert!(!out.exists(), "no output may be left behind");
    assert_eq!(std::fs::read_dir(dir.path()).expect("listed").count(), 1);
}

#[test]
fn adaptive_decisions_larger_than_memory_are_a_clear_error() {
    // Adaptive sampling toward the least MSE decides the whole frame first:
    // 8192² pixels × 52 bytes is 3.25 GiB, more than a 1.2 GB address-space
    // limit, where the band itself (as in the test above) fits.
    let (dir, out) = temp("huge.exr");
    let scene = dir.path().join("adaptive.yaml");
    let text = TRIVIAL_SCENE.replace(
        "sampler: {type: independent, spp: 1}",
        "sampler: {type: independent, spp: 4, adaptive: {error: mse}}",
    );
    assert!(text.contains("error: mse"));
    std::fs::write(&scene, text).expect("the scene is written");
    let o = Command::new("prlimit")
        .arg("--as=1200000000")
        .arg(env!("CARGO_BIN_EXE_radiant"))
        .arg("render")
        .arg(&scene)
        .args([
            "--backend",
            "cpu",
            "--width",
            "8192",
            "--height",
            "8192",
            "-o",
        ])
        .arg(&out)
        .output()
        .expect("prlimit (util-linux) runs");
    let err = stderr(&o);
    assert_eq!(o.status.code(), Some(1), "{err}");
    assert!(
        err.contains("GiB for adaptive sampling's per-pixel decisions (error: mse)"),
        "{err}"
    );
    assert!(!out.exists(), "no output may be left behind");
}

#[test]
fn a_whole_film_larger_than_memory_is_a_clear_error() {
    // The accuracy report keeps whole films: 8192² pixels need 4.75 GiB
    // (64 bytes of exact sums and 12 of image a pixel), more than a 1.2 GB
    // address-space limit allows.
    let (dir, report) = temp("report");
    let args = [
        "--width", "8192", "--height", "8192", "--budget", "1", "--out",
    ];
    let report = report.to_str().expect("a UTF-8 path");
    let o = trivial_under_limit(
        dir.path(),
        1_200_000_000,
        "accuracy",
        &[&args[..], &[report]].concat(),
    );
    let err = stderr(&o);
    assert_eq!(o.status.code(), Some(1), "{err}");
    assert!(
        err.contains("the accuracy report needs whole films in memory"),
        "{err}"
    );
    assert!(
        err.contains("a 8192×8192 frame needs 4.75 GiB of memory"),
        "{err}"
    );
    assert!(err.contains("rows at this width"), "{err}");
}

/// `scenes/hard/caustic.yaml` rendered by `bdpt`, written into `dir`.
fn bdpt_caustic(dir: &Path) -> PathBuf {
    let scene = dir.join("caustic.yaml");
    let text = std::fs::read_to_string(
        Path::new(env!("CARGO_MANIFEST_DIR")).join("../scenes/hard/caustic.yaml"),
    )
    .unwrap()
    .replace(
        "integrator: {type: path, max_depth: 8}",
        "integrator: {type: bdpt}",
    );
    assert!(text.contains("type: bdpt"));
    std::fs::write(&scene, text).unwrap();
    scene
}

#[test]
fn strategies_writes_one_image_per_bdpt_strategy() {
    let (dir, out) = temp("caustic.exr");
    let strategies = dir.path().join("by-strategy");
    let scene = bdpt_caustic(dir.path());
    let o = radiant(&[
        "render",
        scene.to_str().unwrap(),
        "-o",
        out.to_str().unwrap(),
        "--spp",
        "4",
        "--max-depth",
        "3",
        "--strategies",
        strategies.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    assert!(out.exists());
    // Paths of 1, 2 and 3 segments: 2 + 3 + 4 strategies.
    let mut names: Vec<String> = std::fs::read_dir(&strategies)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    names.sort();
    assert_eq!(
        names,
        [
            "s0_t2", "s0_t3", "s0_t4", "s1_t1", "s1_t2", "s1_t3", "s2_t1", "s2_t2", "s3_t1"
        ]
        .map(|n| format!("{n}.exr")),
        "{}",
        stderr(&o)
    );
    assert!(
        stderr(&o).contains("9 per-strategy images"),
        "{}",
        stderr(&o)
    );
}

#[test]
fn strategies_refuses_what_it_cannot_split() {
    let (dir, out) = temp("out.exr");
    let strategies = dir.path().join("by-strategy");
    let caustic = bdpt_caustic(dir.path());
    let caustic = caustic.to_str().unwrap();
    let edited = |name: &str, from: &str, to: &str| {
        let path = dir.path().join(name);
        let text = std::fs::read_to_string(caustic).unwrap().replace(from, to);
        assert!(text.contains(to), "{name}");
        std::fs::write(&path, text).unwrap();
        path.to_str().unwrap().to_string()
    };
    let adaptive = edited(
        "adaptive.yaml",
        "spp: 16}",
        "spp: 16, adaptive: {error: mse}}",
    );
    let importance = edited(
        "importance.yaml",
        "filter: {type: box}}",
        "filter: {type: box}, filter_sampling: importance}",
    );
    let cases: [(&[&str], &str); 10] = [
        (&["scenes/cornell-box.yaml"], "the scene's `path` has none"),
        (
            &[caustic, "--max-depth", "-1"],
            "per-strategy images need a finite max_depth",
        ),
        (&[caustic, "--max-depth", "0"], "need max_depth ≥ 1"),
        (
            &[&adaptive, "--max-depth", "3"],
            "per-strategy images need a fixed spp",
        ),
        (
            &[&importance, "--max-depth", "3"],
            "need `film: {filter_sampling: splat}`",
        ),
        (
            &[caustic, "--backend", "gpu"],
            "--strategies cannot be combined with --backend gpu",
        ),
        (
            &[caustic, "--spp-map", "map.png"],
            "--spp-map cannot be combined with --strategies",
        ),
        (
            &[caustic, "--partition", "1/2"],
            "--strategies cannot be combined with --partition",
        ),
        (
            &[caustic, "--time", "10"],
            "--strategies cannot be combined with --time",
        ),
        (
            &[caustic, "--frames", "0..1", "-o", "f_#.exr"],
            "cannot write several frames' --strategies",
        ),
    ];
    for (args, message) in cases {
        let mut all = vec!["render"];
        all.extend_from_slice(args);
        if !args.contains(&"-o") {
            all.extend_from_slice(&["-o", out.to_str().unwrap()]);
        }
        all.extend_from_slice(&[
            "--spp",
            "1",
            "--width",
            "8",
            "--height",
            "8",
            "--strategies",
            strategies.to_str().unwrap(),
        ]);
        let o = radiant(&all);
        let err = stderr(&o);
        assert_eq!(o.status.code(), Some(1), "{args:?}: {err}");
        assert!(err.contains(message), "{args:?}: {err}");
        assert!(!out.exists(), "{args:?}: no output may be left behind");
        assert!(
            !strategies.exists(),
            "{args:?}: no folder may be left behind"
        );
    }
}

/// `--max-isa` caps the traversal's instruction set without changing the
/// image: the baseline's render is byte for byte the widest one's (the
/// levels give the same hits). An unknown set is refused with the allowed
/// ones, before anything is written.
#[test]
fn the_instruction_set_limit_keeps_the_image() {
    let (dir, _) = temp("x.exr");
    let render = |isa: &str| {
        let out = dir.path().join(format!("{isa}.exr"));
        let o = radiant(&[
            "render",
            "scenes/cornell-box.yaml",
            "-o",
            out.to_str().unwrap(),
            "--spp",
            "2",
            "--width",
            "48",
            "--height",
            "48",
            "--backend",
            "cpu",
            "--max-isa",
            isa,
        ]);
        (o, out)
    };
    let (o, widest) = render("avx512");
    assert!(o.status.success(), "{}", stderr(&o));
    let (o, baseline) = render("baseline");
    assert!(o.status.success(), "{}", stderr(&o));
    assert_eq!(
        std::fs::read(&widest).unwrap(),
        std::fs::read(&baseline).unwrap()
    );

    let (o, out) = render("sse9");
    assert!(!o.status.success());
    let err = stderr(&o);
    assert!(err.contains("baseline, avx2, avx512"), "{err}");
    assert!(!out.exists());
}
