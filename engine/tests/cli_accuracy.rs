//! `radiant accuracy` end to end: a small sweep writes its files, and bad
//! arguments are clear errors with a non-zero exit, never a panic.

use std::path::Path;
use std::process::{Command, Output};

fn radiant(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_radiant"))
        .args(args)
        .current_dir(Path::new(env!("CARGO_MANIFEST_DIR")).join(".."))
        .output()
        .expect("radiant runs")
}

fn fails_with(args: &[&str], needles: &[&str]) {
    let o = radiant(args);
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(!o.status.success(), "{args:?} succeeded");
    assert!(!err.contains("panicked"), "{err}");
    for n in needles {
        assert!(err.contains(n), "`{n}` missing from: {err}");
    }
}

const SMALL: &[&str] = &["--width", "16", "--height", "16", "--max-spp", "8"];

#[test]
fn a_small_sweep_writes_csv_plot_summary_and_reference() {
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
    let err = String::from_utf8_lossy(&o.stderr);
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
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let md = std::fs::read_to_string(out.join("accuracy.md")).unwrap();
    assert!(md.contains("read from a file"), "{md}");
}

#[test]
fn bad_arguments_are_clear_errors() {
    let scene = "scenes/cornell-box.yaml";
    fails_with(
        &["accuracy", scene, "--budget", "0"],
        &["--budget", "positive"],
    );
    fails_with(&["accuracy", scene, "--budget", "-3"], &["--budget"]);
    fails_with(
        &["accuracy", scene, "--budget", "inf"],
        &["--budget", "positive"],
    );
    fails_with(
        &["accuracy", scene, "--reference-time", "0"],
        &["--reference-time"],
    );
    fails_with(
        &["accuracy", scene, "--only", "spp,depth"],
        &["unknown axis `depth`", "max_depth", "light_selection"],
    );
    fails_with(&["accuracy", scene, "--max-spp", "1"], &["--max-spp"]);
    fails_with(&["accuracy", scene, "--width", "0"], &["--width"]);
    fails_with(&["accuracy", scene, "--threads", "0"], &["--threads"]);
    fails_with(
        &["accuracy", "scenes/missing.yaml"],
        &["scenes/missing.yaml"],
    );
    fails_with(
        &["accuracy", scene, "--reference", "missing.exr"],
        &["missing.exr"],
    );
    fails_with(
        &["accuracy", scene, "--out", "scenes/cornell-box.yaml"],
        &["not a folder"],
    );
}

#[test]
fn a_reference_of_another_size_is_rejected() {
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
    fails_with(&args, &["8x8", "16x16", "--width"]);
}
