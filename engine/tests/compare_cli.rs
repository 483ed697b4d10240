//! `radiant compare` across formats: a render written as EXR, HDR, PNG
//! (8 and 16 bit) and JPEG compares with its own EXR within each format's
//! precision, FLIP is printed, `--diff` writes a heat map, and bad input is
//! refused before anything is written.

// `unwrap`/`expect` in this test code is the assertion: the inputs are the
// test's own, so a failure is a bug, and the panic reports it.

use std::collections::HashMap;
use std::path::Path;
use std::process::{Command, Output};

fn radiant(dir: &Path, args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_radiant"))
        .args(args)
        .current_dir(dir)
        .output()
        .expect("radiant runs")
}

fn stderr(o: &Output) -> String {
    String::from_utf8_lossy(&o.stderr).into_owned()
}

/// The `name value` lines of `compare`'s output.
fn metrics(o: &Output) -> HashMap<String, f64> {
    String::from_utf8_lossy(&o.stdout)
        .lines()
        .filter_map(|l| l.split_once(' '))
        .filter_map(|(k, v)| Some((k.to_string(), v.parse().ok()?)))
        .collect()
}

#[test]
fn compare_reads_every_format_and_writes_a_heat_map() {
    let dir = tempfile::tempdir().unwrap();
    let scene = Path::new(env!("CARGO_MANIFEST_DIR")).join("../scenes/cornell-box.yaml");
    let scene = scene.to_str().unwrap();
    let small = ["--width", "32", "--height", "24", "--spp", "4"];
    let render = |out: &str, extra: &[&str]| {
        let o = radiant(
            dir.path(),
            &[&["render", scene, "-o", out][..], &small, extra].concat(),
        );
        assert!(o.status.success(), "{out}: {}", stderr(&o));
    };
    render("ref.exr", &[]);
    render("a.hdr", &[]);
    render("a.png", &[]);
    render("b.png", &["--bit-depth", "16"]);
    render("a.jpg", &[]);
    render("other.exr", &["--seed", "9"]);

    let o = radiant(dir.path(), &["compare", "ref.exr", "ref.exr"]);
    assert!(o.status.success(), "{}", stderr(&o));
    let same = metrics(&o);
    assert_eq!((same["rmse"], same["flip"]), (0.0, 0.0));

    // The same render in each format: its error is the format's rounding
    // (and the PNG/JPEG clamp of the light), far below another seed's noise.
    let noise = metrics(&radiant(dir.path(), &["compare", "other.exr", "ref.exr"]));
    assert!(noise["flip"] > 0.0 && noise["rmse"] > 0.0);
    let mut rmse = HashMap::new();
    for name in ["a.hdr", "a.png", "b.png", "a.jpg"] {
        let o = radiant(dir.path(), &["compare", name, "ref.exr"]);
        assert!(o.status.success(), "{name}: {}", stderr(&o));
        let m = metrics(&o);
        assert!(m["flip"] < noise["flip"], "{name}: {m:?} {noise:?}");
        rmse.insert(name, m["rmse"]);
    }
    // RGBE keeps 8 bits of each pixel's largest channel: an error of at
    // most 1/128 of it.
    let reference = radiant::film::output::read(dir.path().join("ref.exr")).unwrap();
    let rms_max = (reference
        .pixels
        .iter()
        .map(|p| (p.max_element() as f64).powi(2))
        .sum::<f64>()
        / reference.pixels.len() as f64)
        .sqrt();
    assert!(rmse["a.hdr"] <= rms_max / 128.0, "{rmse:?} {rms_max}");
    assert!(rmse["a.hdr"] < noise["rmse"], "{rmse:?} {noise:?}");
    // The 16-bit PNG differs from the EXR by the clamp alone, as the 8-bit
    // one does up to its rounding.
    assert!(rmse["b.png"] <= rmse["a.png"], "{rmse:?}");

    let o = radiant(
        dir.path(),
        &["compare", "other.exr", "ref.exr", "--diff", "diff.png"],
    );
    assert!(o.status.success(), "{}", stderr(&o));
    let map = image::open(dir.path().join("diff.png")).unwrap().to_rgb8();
    assert_eq!(map.dimensions(), (32, 24));
    // Magma: not one colour where the images differ.
    let first = map.get_pixel(0, 0);
    assert!(map.pixels().any(|p| p != first));
}

#[test]
fn compare_refuses_what_it_cannot_read() {
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(dir.path().join("notes.txt"), "not an image").unwrap();
    let o = radiant(dir.path(), &["compare", "notes.txt", "notes.txt"]);
    assert!(!o.status.success());
    assert!(stderr(&o).contains("notes.txt"), "{}", stderr(&o));
    let o = radiant(
        dir.path(),
        &["compare", "a.exr", "b.exr", "--diff", "diff.bmp"],
    );
    assert!(!o.status.success());
    assert!(stderr(&o).contains("must end in .png"), "{}", stderr(&o));
    assert!(!dir.path().join("diff.bmp").exists());
}

#[test]
fn compare_into_a_closed_pipe_is_not_a_panic() {
    // `radiant compare a b | head -1`: the reader is gone before the
    // report is written (its end of the pipe is closed at once, while the
    // images are still being read), which must end quietly with status 0.
    let dir = tempfile::tempdir().unwrap();
    let scene = Path::new(env!("CARGO_MANIFEST_DIR")).join("../scenes/cornell-box.yaml");
    let o = radiant(
        dir.path(),
        &[
            "render",
            scene.to_str().unwrap(),
            "-o",
            "a.exr",
            "--width",
            "256",
            "--height",
            "256",
            "--spp",
            "1",
        ],
    );
    assert!(o.status.success(), "{}", stderr(&o));
    let mut child = Command::new(env!("CARGO_BIN_EXE_radiant"))
        .args(["compare", "a.exr", "a.exr"])
        .current_dir(dir.path())
        .stdout(std::process::Stdio::piped())
        .stderr(std::process::Stdio::piped())
        .spawn()
        .expect("radiant runs");
    drop(child.stdout.take());
    let o = child.wait_with_output().expect("radiant ends");
    assert!(o.status.success(), "{}", stderr(&o));
    assert!(!stderr(&o).contains("panicked"), "{}", stderr(&o));
}
