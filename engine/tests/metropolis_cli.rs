//! The Metropolis integrators through the command line: the image does not
//! depend on the number of threads, and bad keys are located errors.

// `unwrap` in this test code is the assertion: the inputs are the test's
// own, so a failure is a bug, and the panic reports it with the error.

use std::path::Path;
use std::process::{Command, Output};

fn radiant(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_radiant"))
        .args(args)
        .current_dir(Path::new(env!("CARGO_MANIFEST_DIR")).join(".."))
        .output()
        .expect("radiant runs")
}

/// The Cornell box with its integrator replaced by `integrator` (the
/// lines of a YAML block mapping), written into `dir`.
fn scene(dir: &Path, integrator: &str) -> String {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("..");
    let text = std::fs::read_to_string(root.join("scenes/cornell-box.yaml")).unwrap();
    let text = text.replacen("  type: path\n", integrator, 1);
    let path = dir.join("scene.yaml");
    std::fs::write(&path, text).unwrap();
    path.to_str().unwrap().to_string()
}

#[test]
fn metropolis_images_do_not_depend_on_the_thread_count() {
    // pssmlt batches its chains by the thread count (512 a batch on one
    // thread, 256 on two here), erpt by its seed paths; both hash every
    // random number from (chain, step) and splat into exact sums.
    for integrator in [
        "  type: pssmlt\n  bootstrap: 5000\n  chains: 1024\n",
        "  type: erpt\n  bootstrap: 5000\n  seeds: 2\n  chain_length: 16\n",
    ] {
        let dir = tempfile::tempdir().unwrap();
        let scene = scene(dir.path(), integrator);
        let images: Vec<Vec<u8>> = ["1", "2"]
            .iter()
            .map(|threads| {
                let out = dir.path().join(format!("out-{threads}.exr"));
                let o = radiant(&[
                    "render",
                    &scene,
                    "-o",
                    out.to_str().unwrap(),
                    "--spp",
                    "8",
                    "--width",
                    "48",
                    "--height",
                    "48",
                    "--threads",
                    threads,
                ]);
                assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
                std::fs::read(out).unwrap()
            })
            .collect();
        assert!(images[0] == images[1], "{integrator}: images differ");
    }
}

#[test]
fn bad_metropolis_keys_are_located_errors() {
    for (integrator, key, line) in [
        ("  type: pssmlt\n  large_step: 1.5\n", "large_step", 5),
        ("  type: pssmlt\n  chains: 0\n", "chains", 5),
        ("  type: erpt\n  sigma: 0\n", "sigma", 5),
        ("  type: erpt\n  seeds: 0\n", "seeds", 5),
        ("  type: erpt\n  chain_lenght: 8\n", "chain_lenght", 5),
    ] {
        let dir = tempfile::tempdir().unwrap();
        let scene = scene(dir.path(), integrator);
        let out = dir.path().join("out.png");
        let o = radiant(&["render", &scene, "-o", out.to_str().unwrap()]);
        let err = String::from_utf8_lossy(&o.stderr);
        assert!(!o.status.success(), "{key}: accepted");
        assert!(err.contains(key), "{key}: {err}");
        assert!(
            err.contains(&format!(":{line}:")),
            "{key}: no line {line}: {err}"
        );
        assert!(!out.exists(), "{key}: an output was written");
    }
}
