//! `radiant render --aov`: the output variables come back from the EXR
//! under their layer names with the values the scene implies, alpha is
//! coverage, the beauty is the image a plain render gives, and bad requests
//! are refused before rendering.

// `unwrap`/`expect` in this test code is the assertion: the inputs are the
// test's own, so a failure is a bug, and the panic reports it.

#[allow(dead_code)]
mod common;

use exr::prelude::{FlatSamples, ReadChannels, ReadLayers};
use std::collections::HashMap;
use std::path::Path;
use std::process::{Command, Output};

/// A diffuse square (reflectance 0.2, 0.5, 0.8) seen head-on from 5 units
/// away by a camera that is not at the origin, filling the middle of a
/// 33×33 frame with background around it. The camera looks down −z at the
/// square's centre (1, 2, 0), so the middle pixel's ray meets it at
/// distance 5 and the square's normal is +z.
const SCENE: &str = "
integrator: {type: path, max_depth: 3}
film: {width: 33, height: 33}
sampler: {type: independent, spp: 4}
camera:
  type: perspective
  fov: 40
  look_at: {origin: [1, 2, 5], target: [1, 2, 0], up: [0, 1, 0]}
shapes:
  - type: rectangle
    material: {type: diffuse, reflectance: [0.2, 0.5, 0.8]}
    transform: {translate: [1, 2, 0]}
lights:
  - {type: point, position: [1, 2, 4], intensity: 10}
";

/// Runs `radiant` with `args`.
fn radiant(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_radiant"))
        .args(args)
        .output()
        .expect("radiant runs")
}

fn stderr(o: &Output) -> String {
    String::from_utf8_lossy(&o.stderr).into_owned()
}

fn arg(p: &Path) -> &str {
    p.to_str().expect("a UTF-8 temporary path")
}

/// The float channels of an EXR file by name.
fn channels(path: &Path) -> HashMap<String, Vec<f32>> {
    let image = exr::prelude::read()
        .no_deep_data()
        .largest_resolution_level()
        .all_channels()
        .first_valid_layer()
        .all_attributes()
        .from_file(path)
        .expect("an EXR");
    image
        .layer_data
        .channel_data
        .list
        .into_iter()
        .map(|c| {
            let FlatSamples::F32(values) = c.sample_data else {
                panic!("{} is not f32", c.name);
            };
            (c.name.to_string(), values)
        })
        .collect()
}

#[test]
fn layers_hold_albedo_normal_depth_position_spp_and_alpha() {
    let dir = tempfile::tempdir().unwrap();
    let scene = dir.path().join("square.yaml");
    std::fs::write(&scene, SCENE).unwrap();
    let out = dir.path().join("passes.exr");
    let o = radiant(&[
        "render",
        arg(&scene),
        "-o",
        arg(&out),
        "--aov",
        "spp,albedo,normal,depth,position",
        "--threads",
        "2",
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let ch = channels(&out);
    let mut names: Vec<&str> = ch.keys().map(String::as_str).collect();
    names.sort();
    assert_eq!(
        names,
        [
            "A",
            "B",
            "G",
            "R",
            "albedo.B",
            "albedo.G",
            "albedo.R",
            "depth.Z",
            "normal.X",
            "normal.Y",
            "normal.Z",
            "position.X",
            "position.Y",
            "position.Z",
            "spp.Y"
        ]
    );
    let at = |name: &str, x: usize, y: usize| ch[name][y * 33 + x];
    // The middle pixel and its neighbours lie well inside the square.
    for (x, y) in [(16, 16), (14, 17), (18, 15)] {
        assert_eq!(at("A", x, y), 1.0, "alpha at ({x}, {y})");
        for (c, v) in [("albedo.R", 0.2), ("albedo.G", 0.5), ("albedo.B", 0.8)] {
            assert!((at(c, x, y) - v).abs() < 1e-5, "{c} {}", at(c, x, y));
        }
        for (c, v) in [("normal.X", 0.0), ("normal.Y", 0.0), ("normal.Z", 1.0)] {
            assert!((at(c, x, y) - v).abs() < 1e-5, "{c} {}", at(c, x, y));
        }
        // A ray d pixels off the axis travels 5/cos θ; here within 0.3 %.
        assert!(
            (at("depth.Z", x, y) - 5.0).abs() < 0.015,
            "{}",
            at("depth.Z", x, y)
        );
        assert!(at("position.Z", x, y).abs() < 1e-4);
        assert!((at("position.X", x, y) - 1.0).abs() < 0.35);
        assert!((at("position.Y", x, y) - 2.0).abs() < 0.35);
    }
    // The middle pixel's samples fall about the axis, within the filter's
    // reach (2 pixels of 0.11 units): their mean hit is the square's
    // centre to within a pixel.
    assert!(
        (at("position.X", 16, 16) - 1.0).abs() < 0.11,
        "{}",
        at("position.X", 16, 16)
    );
    assert!(
        (at("position.Y", 16, 16) - 2.0).abs() < 0.11,
        "{}",
        at("position.Y", 16, 16)
    );
    // Depth grows with the angle off the axis: 5/cos θ at the square's edge.
    assert!(at("depth.Z", 10, 16) > at("depth.Z", 16, 16));
    // Corners see the background: nothing there, alpha 0.
    for (x, y) in [(0, 0), (32, 0), (0, 32), (32, 32)] {
        assert_eq!(at("A", x, y), 0.0, "alpha at ({x}, {y})");
        assert_eq!(at("depth.Z", x, y), 0.0);
        assert_eq!(at("albedo.G", x, y), 0.0);
    }
    // Edges are partly covered.
    let row: Vec<f32> = (0..33).map(|x| at("A", x, 16)).collect();
    assert!(row.iter().any(|&a| a > 0.0 && a < 1.0), "{row:?}");
    assert!(ch["spp.Y"].iter().all(|&n| n == 4.0));

    // The beauty is the image a plain render writes, bit for bit.
    let plain = dir.path().join("plain.exr");
    let o = radiant(&["render", arg(&scene), "-o", arg(&plain), "--threads", "2"]);
    assert!(o.status.success(), "{}", stderr(&o));
    let plain = channels(&plain);
    for c in ["R", "G", "B"] {
        assert!(plain[c] == ch[c], "channel {c}");
    }
    assert!(plain["G"][16 * 33 + 16] > 0.0);
}

#[test]
fn bad_requests_are_refused_before_rendering() {
    let dir = tempfile::tempdir().unwrap();
    let scene = dir.path().join("square.yaml");
    std::fs::write(&scene, SCENE).unwrap();
    let cases: [(&[&str], &str, &str); 4] = [
        (
            &["--aov", "albedo,nromal"],
            "a.exr",
            "unknown output variable `nromal`; expected one of albedo, normal, depth, position, spp",
        ),
        (&["--aov", "albedo"], "a.png", "name the output .exr"),
        (
            &["--aov", "depth", "--backend", "gpu"],
            "a.exr",
            "--aov needs the CPU backend",
        ),
        (
            &["--aov", "depth", "--time", "5s"],
            "a.exr",
            "--aov cannot be combined with --time",
        ),
    ];
    for (extra, name, message) in cases {
        assert_refused(&scene, &dir.path().join(name), extra, message);
    }
}

/// Asserts that rendering `scene` to `out` with `extra` arguments fails
/// with `message` and leaves no file.
fn assert_refused(scene: &Path, out: &Path, extra: &[&str], message: &str) {
    let mut args = vec!["render", arg(scene), "-o", arg(out)];
    args.extend_from_slice(extra);
    let o = radiant(&args);
    assert!(!o.status.success(), "{extra:?} succeeded");
    assert!(stderr(&o).contains(message), "{extra:?}: {}", stderr(&o));
    assert!(!out.exists(), "{extra:?} left a file");
}

/// `film: {aovs: […]}` asks for the layers in the scene; `--aov` replaces
/// the scene's list (`--aov ""` writes none); names are checked where they
/// are written, and the scene's layers need an EXR as the flag's do.
#[test]
fn the_scene_asks_for_layers_with_film_aovs() {
    let dir = tempfile::tempdir().unwrap();
    let scene = dir.path().join("square.yaml");
    let with_aovs = |aovs: &str| {
        let text = SCENE.replace(
            "film: {width: 33, height: 33}",
            &format!("film: {{width: 33, height: 33, aovs: {aovs}}}"),
        );
        assert!(text.contains("aovs"));
        std::fs::write(&scene, text).unwrap();
    };
    let layers = |extra: &[&str]| {
        let out = dir.path().join("layers.exr");
        let _ = std::fs::remove_file(&out);
        let mut args = vec!["render", arg(&scene), "-o", arg(&out), "--threads", "2"];
        args.extend_from_slice(extra);
        let o = radiant(&args);
        assert!(o.status.success(), "{extra:?}: {}", stderr(&o));
        let mut names: Vec<String> = channels(&out)
            .into_keys()
            .filter(|n| n.contains('.'))
            .collect();
        names.sort();
        names
    };
    with_aovs("[depth, albedo]");
    assert_eq!(
        layers(&[]),
        ["albedo.B", "albedo.G", "albedo.R", "depth.Z"],
        "the scene's list"
    );
    assert_eq!(
        layers(&["--aov", "normal"]),
        ["normal.X", "normal.Y", "normal.Z"],
        "--aov replaces the scene's list"
    );
    assert!(layers(&["--aov", ""]).is_empty(), "--aov \"\" writes none");

    let refused = |extra: &[&str], name: &str, message: &str| {
        assert_refused(&scene, &dir.path().join(name), extra, message);
    };
    refused(&[], "a.png", "film: {aovs: […]}");
    refused(&[], "a.png", "name the output .exr");
    refused(&["--backend", "gpu"], "a.exr", "needs the CPU backend");
    with_aovs("[albedo, nromal]");
    // The film line is the scene's third; `nromal` is its 46th column.
    refused(
        &[],
        "a.exr",
        "square.yaml:3:46: film aovs: unknown output variable `nromal`; expected one of albedo, normal, depth, position, spp",
    );
    with_aovs("{albedo: true}");
    refused(
        &[],
        "a.exr",
        "film aovs must be a list of output variable names",
    );
}

/// Ctrl-C stops a render with passes after the pass in progress and
/// writes the image and its layers of the samples so far (exit status
/// 130): every pixel's `spp.Y` is the count it reports, and the beauty is
/// a render of that many samples, bit for bit.
#[test]
fn an_interrupted_render_with_passes_keeps_its_samples() {
    use std::process::{Command, Stdio};
    let dir = tempfile::tempdir().unwrap();
    let scene = dir.path().join("square.yaml");
    std::fs::write(&scene, SCENE).unwrap();
    let out = dir.path().join("passes.exr");
    let spp = "100000000";
    let child = Command::new(env!("CARGO_BIN_EXE_radiant"))
        .args(["render", arg(&scene), "-o", arg(&out), "--threads", "2"])
        .args(["--aov", "albedo,spp", "--spp", spp])
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    common::wait_for_sigint_handler(child.id());
    std::thread::sleep(std::time::Duration::from_millis(500));
    let kill = Command::new("kill")
        .args(["-INT", &child.id().to_string()])
        .status()
        .unwrap();
    assert!(kill.success());
    let o = child.wait_with_output().unwrap();
    let e = stderr(&o);
    assert_eq!(o.status.code(), Some(130), "{e}");
    let ch = channels(&out);
    let held = ch["spp.Y"][0];
    assert!((1.0..1e8).contains(&held), "{held}");
    assert!(ch["spp.Y"].iter().all(|&n| n == held));
    let held = (held as u32).to_string();
    assert!(
        e.contains(&format!(
            "interrupted: {held} of {spp} spp written to {}",
            out.display()
        )),
        "{e}"
    );
    assert!(ch.contains_key("albedo.R"));
    let plain = dir.path().join("plain.exr");
    let o = radiant(&[
        "render",
        arg(&scene),
        "-o",
        arg(&plain),
        "--threads",
        "2",
        "--spp",
        &held,
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let plain = channels(&plain);
    for c in ["R", "G", "B"] {
        assert!(plain[c] == ch[c], "channel {c}");
    }
}
