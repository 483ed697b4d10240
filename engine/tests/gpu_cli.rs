//! The GPU backend from the command line: what a scene's kernel compiles
//! in, and the clear errors (a module without GPU code, no adapter) that
//! exit non-zero and write no image.
//!
//! The kernel-content tests need no adapter (the kernel is planned on the
//! CPU); the rest run on whatever adapter is found (lavapipe in CI).

// `unwrap` in this test code is the assertion: the inputs are the test's
// own, so a failure is a bug, and the panic reports it with the error.

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

fn root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("..")
}

fn radiant(args: &[&str], env: &[(&str, &str)]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_radiant"))
        .args(args)
        .envs(env.iter().copied())
        .current_dir(root())
        .output()
        .expect("radiant runs")
}

fn stderr(o: &Output) -> String {
    String::from_utf8_lossy(&o.stderr).into_owned()
}

/// The kernel `radiant info --dump-wgsl` writes for `scene`.
fn kernel_of(scene: &Path) -> String {
    let dir = tempfile::tempdir().unwrap();
    let o = radiant(
        &[
            "info",
            scene.to_str().unwrap(),
            "--dump-wgsl",
            dir.path().to_str().unwrap(),
        ],
        &[],
    );
    assert!(o.status.success(), "{}", stderr(&o));
    let out = String::from_utf8_lossy(&o.stdout);
    assert!(out.contains("gpu shaders"), "{out}");
    std::fs::read_to_string(dir.path().join("kernel.wgsl")).unwrap()
}

/// `scenes/cornell-box.yaml` with `edit` applied, written into `dir`.
fn edited_cornell(dir: &Path, edit: impl FnOnce(String) -> String) -> PathBuf {
    let text = std::fs::read_to_string(root().join("scenes/cornell-box.yaml")).unwrap();
    let path = dir.join("scene.yaml");
    std::fs::write(&path, edit(text)).unwrap();
    path
}

#[test]
fn a_diffuse_scene_compiles_no_code_it_does_not_use_and_glass_brings_the_dielectric_in() {
    let diffuse = kernel_of(&root().join("scenes/cornell-box.yaml"));
    assert!(diffuse.contains("fn bsdf_sample_diffuse("));
    for absent in [
        "dielectric",
        "fn texture_bitmap",
        "fn texture_checkerboard",
        "thin_lens",
        "light_escaped",
        "escaped_radiance",
        "hit_sphere",
        "trace_scene",
        "ggx_",
    ] {
        assert!(
            !diffuse.contains(absent),
            "`{absent}` in a diffuse-only kernel"
        );
    }
    let dir = tempfile::tempdir().unwrap();
    let glass = edited_cornell(dir.path(), |t| {
        t.replace(
            "materials:\n",
            "materials:\n  glass: {type: dielectric, int_ior: 1.5}\n",
        )
        .replace(
            "  - name: small box\n    type: cube\n    material: white",
            "  - name: small box\n    type: cube\n    material: glass",
        )
    });
    let kernel = kernel_of(&glass);
    assert!(
        kernel.contains("fn bsdf_sample_dielectric("),
        "no dielectric"
    );
    assert!(
        kernel.contains("fn fresnel_dielectric("),
        "no Fresnel library"
    );
    assert!(!kernel.contains("fn bsdf_sample_conductor("));
}

#[test]
fn no_adapter_is_a_clear_error_and_auto_falls_back_to_the_cpu() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("out.png");
    let args = |backend| {
        [
            "render",
            "scenes/cornell-box.yaml",
            "-o",
            out.to_str().unwrap(),
            "--spp",
            "1",
            "--width",
            "16",
            "--height",
            "16",
            "--backend",
            backend,
        ]
        .map(str::to_string)
    };
    // No Vulkan driver to be found, and no other backend allowed.
    let no_driver = [
        ("WGPU_BACKEND", "vulkan"),
        ("VK_DRIVER_FILES", "/nonexistent/icd.json"),
        ("VK_ICD_FILENAMES", "/nonexistent/icd.json"),
    ];
    let gpu = args("gpu");
    let o = radiant(&gpu.each_ref().map(String::as_str), &no_driver);
    let err = stderr(&o);
    assert!(!o.status.success());
    assert!(err.contains("no GPU adapter found"), "{err}");
    assert!(!out.exists(), "an image was written");
    let auto = args("auto");
    let o = radiant(&auto.each_ref().map(String::as_str), &no_driver);
    let err = stderr(&o);
    assert!(o.status.success(), "{err}");
    assert!(err.contains("backend: cpu (no GPU adapter found"), "{err}");
    assert!(out.exists());
}

#[test]
fn the_gpu_renders_the_default_scene_from_the_command_line() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("out.exr");
    let o = radiant(
        &[
            "render",
            "scenes/cornell-box.yaml",
            "-o",
            out.to_str().unwrap(),
            "--spp",
            "4",
            "--width",
            "32",
            "--height",
            "24",
            "--backend",
            "gpu",
        ],
        &[],
    );
    assert!(o.status.success(), "{}", stderr(&o));
    assert!(
        stderr(&o).contains("rendered 32x24, 4 spp"),
        "{}",
        stderr(&o)
    );
    assert!(out.exists());
}
