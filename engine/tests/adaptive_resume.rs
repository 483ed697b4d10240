//! Adaptive sampling in passes end to end: a `--time` render stopped
//! early and finished with `--resume` gives the uninterrupted render's
//! image bit for bit (the resumed run decides every pixel's count again,
//! the same, and renders the rest of each pixel's share).

// `unwrap`/`expect` in this test code is the assertion: the inputs are the
// test's own, so a failure is a bug, and the panic reports it.

#[allow(dead_code)]
mod common;

use common::{arg, radiant, read, shot, stderr};
use radiant::farm::partial;

#[test]
fn an_adaptive_render_stopped_by_time_resumes_into_the_uninterrupted_image() {
    let dir = tempfile::tempdir().unwrap();
    let scene = shot(
        dir.path(),
        "shot.yaml",
        "independent, adaptive: {threshold: 0.02, batch: 16, min_spp: 16}",
    );
    let spp = "20000";
    let run = |out: &std::path::Path, extra: &[&str]| {
        let mut args = vec!["render", arg(&scene), "-o", arg(out), "--backend", "cpu"];
        args.extend(["--threads", "2", "--spp", spp]);
        args.extend(extra);
        let o = radiant(&args);
        assert!(o.status.success(), "{extra:?}: {}", stderr(&o));
        stderr(&o)
    };
    let out = dir.path().join("frame.exr");
    // A limit shorter than any pass stops the render after its first pass
    // on any machine (a wall-clock limit of seconds let a fast, idle
    // machine finish all the passes).
    let e = run(&out, &["--time", "1ms"]);
    let held = partial::read_header(&out).unwrap().samples.end;
    assert!(held < 20000, "the render finished within its time: {e}");
    let e = run(&out, &["--resume", arg(&out)]);
    assert!(e.contains("20000 of 20000 spp"), "{e}");
    let single = dir.path().join("single.exr");
    run(&single, &[]);
    let (resumed, single) = (read(&out), read(&single));
    assert!(single.mean() > 0.0);
    assert!(
        resumed == single,
        "the resumed image differs from one render"
    );
}
