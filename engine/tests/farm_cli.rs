//! `radiant render --partition`, `radiant merge` and `radiant farm` end to
//! end, without a Slurm cluster (`slurm.rs` has the tests on one).

// `unwrap`/`expect` in this test code is the assertion: the inputs are the
// test's own, so a failure is a bug, and the panic reports it.

mod common;

use common::{
    arg, difference, farm_slurm, ok, radiant, radiant_with_path, read, render, shot, stderr, stdout,
};
use std::path::{Path, PathBuf};

/// A difference, relative to the brightest value, far below what a frame
/// of other samples differs by (percents): merged frames equal the
/// single-machine render bit for bit, and another seed's frame differing by
/// many times this shows that the comparison can fail.
const ROUNDING: f32 = 1e-5;

/// Renders partitions `indices` of `count` of frame 5 of `scene` into `dir`
/// (with `extra` options); returns the files.
fn partitions(
    scene: &Path,
    dir: &Path,
    count: u32,
    indices: &[u32],
    extra: &[&str],
) -> Vec<PathBuf> {
    indices
        .iter()
        .map(|k| {
            let out = dir.join(format!("part{k}of{count}.exr"));
            let partition = format!("{k}/{count}");
            let options = [
                &["--partition", partition.as_str(), "--threads", "2"],
                extra,
            ]
            .concat();
            render(scene, "5", &out, &options);
            out
        })
        .collect()
}

/// `radiant merge FILES -o OUT`.
fn merge(files: &[PathBuf], out: &Path) -> std::process::Output {
    let mut args = vec!["merge"];
    args.extend(files.iter().map(|f| arg(f)));
    args.extend(["-o", arg(out)]);
    radiant(&args)
}

#[test]
fn partitions_merge_into_the_single_machine_image() {
    let dir = tempfile::tempdir().unwrap();
    for sampler in ["independent", "sobol"] {
        let scene = shot(dir.path(), &format!("{sampler}.yaml"), sampler);
        let single = dir.path().join(format!("{sampler}-single.exr"));
        render(&scene, "5", &single, &["--threads", "1"]);
        let mut parts = partitions(&scene, dir.path(), 3, &[2, 3, 1], &[]);
        parts.reverse();
        let merged = dir.path().join(format!("{sampler}-merged.exr"));
        let o = merge(&parts, &merged);
        assert!(o.status.success(), "{}", stderr(&o));
        assert!(
            stderr(&o).contains("merged 3 files of frame 5 (32x32, 16 spp)"),
            "{}",
            stderr(&o)
        );
        // The film's sums are exact, so the merge is the single render bit
        // for bit, whatever the sampler (each draws sample i of a pixel from
        // the seed, the pixel and i alone).
        let (largest, same) = difference(&read(&merged), &read(&single));
        assert_eq!(
            same, 1024,
            "{sampler}: largest difference {largest:e} of the peak"
        );
        // One partition is the whole frame, bit for bit.
        let whole = partitions(&scene, dir.path(), 1, &[1], &[]);
        let alone = dir.path().join(format!("{sampler}-alone.exr"));
        assert!(merge(&whole, &alone).status.success());
        assert_eq!(read(&alone), read(&single), "{sampler}");
    }
    // A merged PNG is encoded as merge's options say, byte for byte as the
    // single render writes it with the same options.
    let encoded = ["--tonemap", "aces", "--bit-depth", "16"];
    let scene = dir.path().join("independent.yaml");
    let single = dir.path().join("single.png");
    render(&scene, "5", &single, &encoded);
    let parts = partitions(&scene, dir.path(), 3, &[1, 2, 3], &[]);
    let merged = dir.path().join("merged.png");
    let mut args = vec!["merge"];
    args.extend(parts.iter().map(|f| arg(f)));
    args.extend(["-o", arg(&merged)]);
    args.extend(encoded);
    let o = radiant(&args);
    assert!(o.status.success(), "{}", stderr(&o));
    assert!(std::fs::read(&merged).unwrap() == std::fs::read(&single).unwrap());
    // The tolerance has power: the same frame with another seed is far off.
    let scene = shot(dir.path(), "seeded.yaml", "independent");
    let other = dir.path().join("other-seed.exr");
    render(&scene, "5", &other, &["--seed", "9"]);
    let single = dir.path().join("independent-single.exr");
    let (largest, _) = difference(&read(&other), &read(&single));
    assert!(largest > 100.0 * ROUNDING, "{largest}");
}

/// Runs `merge` on `files`, expects it to fail with a message containing
/// each of `needles`, and checks that no output was left.
fn refused(files: &[PathBuf], needles: &[String]) {
    let out = files[0].with_file_name("merged.exr");
    let o = merge(files, &out);
    assert!(!o.status.success(), "merge of {files:?} succeeded");
    let e = stderr(&o);
    for needle in needles {
        assert!(e.contains(needle.as_str()), "`{needle}` not in: {e}");
    }
    assert!(!out.exists(), "an output was left");
}

#[test]
fn bad_merges_name_the_files_and_write_nothing() {
    let dir = tempfile::tempdir().unwrap();
    let scene = shot(dir.path(), "shot.yaml", "independent");
    let parts = partitions(&scene, dir.path(), 4, &[1, 2, 3, 4], &[]);
    let name = |p: &PathBuf| format!("`{}`", p.display());
    // The first three quarters and `last`.
    let with = |last: &PathBuf| [&parts[..3], std::slice::from_ref(last)].concat();
    // A gap.
    refused(
        &[parts[0].clone(), parts[1].clone(), parts[3].clone()],
        &[
            "samples 8..12 of the frame's 16 are in none of the files".into(),
            name(&parts[1]),
            name(&parts[3]),
        ],
    );
    // An overlap: a half over a quarter.
    let half = partitions(&scene, dir.path(), 2, &[2], &[]);
    refused(
        &with(&half[0]),
        &[format!(
            "{} (samples 8..12) and {} (samples 8..16) overlap",
            name(&parts[2]),
            name(&half[0])
        )],
    );
    // Another scene, another size.
    let elsewhere = dir.path().join("elsewhere");
    std::fs::create_dir(&elsewhere).unwrap();
    let edited = elsewhere.join("shot.yaml");
    std::fs::write(
        &edited,
        std::fs::read_to_string(&scene)
            .unwrap()
            .replace("0.7", "0.6"),
    )
    .unwrap();
    let other_scene = partitions(&edited, &elsewhere, 4, &[4], &[]);
    refused(
        &with(&other_scene[0]),
        &[
            "are not partitions of the same frame: their scene differ".into(),
            name(&parts[0]),
            name(&other_scene[0]),
        ],
    );
    let small = dir.path().join("small");
    std::fs::create_dir(&small).unwrap();
    let other_size = partitions(&scene, &small, 4, &[4], &["--width", "16"]);
    refused(
        &with(&other_size[0]),
        &[
            "their size differ (32x32 and 16x32)".into(),
            name(&other_size[0]),
        ],
    );
    // A whole render is not a partition.
    let plain = dir.path().join("plain.exr");
    render(&scene, "5", &plain, &[]);
    refused(
        &[parts[0].clone(), plain.clone()],
        &[format!(
            "{} is not a sample partition of a frame",
            name(&plain)
        )],
    );
    // A partial file cut short (a copy that did not finish).
    let cut = dir.path().join("cut.exr");
    let bytes = std::fs::read(&parts[3]).unwrap();
    std::fs::write(&cut, &bytes[..bytes.len() * 2 / 3]).unwrap();
    refused(&with(&cut), &[format!("cannot read {}", name(&cut))]);
    // An output that cannot be written is refused before any reading.
    let o = merge(&parts, &dir.path().join("merged.bmp"));
    assert!(
        stderr(&o).contains("must end in .png, .jpg, .jpeg, .exr or .hdr"),
        "{}",
        stderr(&o)
    );
    // And what was whole still merges.
    let o = merge(&parts, &dir.path().join("merged.exr"));
    assert!(o.status.success(), "{}", stderr(&o));
}

#[test]
fn partition_arguments_are_checked() {
    let dir = tempfile::tempdir().unwrap();
    let scene = shot(dir.path(), "shot.yaml", "independent");
    let out = dir.path().join("p.exr");
    let fails = |extra: &[&str], needle: &str| {
        let mut args = vec!["render", arg(&scene), "-o", arg(&out)];
        args.extend(extra);
        let o = radiant(&args);
        assert!(!o.status.success(), "{extra:?}");
        assert!(stderr(&o).contains(needle), "{extra:?}: {}", stderr(&o));
        assert!(!out.exists());
    };
    fails(&["--partition", "5/4"], "partition 5/4 does not exist");
    fails(
        &["--partition", "3"],
        "`3` is not a partition; expected K/N",
    );
    fails(
        &["--partition", "3/32"],
        "32 partitions of 16 samples per pixel would leave some empty",
    );
    fails(
        &["--partition", "1/2", "--frames", "1..3"],
        "--partition renders one frame, not frames 1..3",
    );
    let png = dir.path().join("p.png");
    let o = radiant(&["render", arg(&scene), "--partition", "1/2", "-o", arg(&png)]);
    assert!(stderr(&o).contains("name it .exr"), "{}", stderr(&o));
    assert!(!png.exists());
}

#[test]
fn farm_slurm_writes_the_scripts_and_explains_a_missing_sbatch() {
    let dir = tempfile::tempdir().unwrap();
    let scene = shot(dir.path(), "shot.yaml", "independent");
    let out = dir.path().join("frame_####.exr");
    let with = |extra| farm_slurm(&scene, &out, "1..12", extra);
    ok(&with(&[
        "--chunk",
        "5",
        "--queue",
        "short",
        "--time",
        "00:10:00",
        "--cpus-per-task",
        "2",
        "--mem",
        "1G",
        "--spp",
        "4",
    ]));
    let script = std::fs::read_to_string(dir.path().join("shot.sbatch")).unwrap();
    for line in [
        "#SBATCH --job-name=radiant-shot",
        "#SBATCH --array=0-2",
        "#SBATCH --partition=short",
        "#SBATCH --time=00:10:00",
        "#SBATCH --cpus-per-task=2",
        "#SBATCH --mem=1G",
        "first=$((1 + $SLURM_ARRAY_TASK_ID * 5))",
    ] {
        assert!(
            script.lines().any(|l| l == line),
            "no `{line}` in:\n{script}"
        );
    }
    let exec = script.lines().last().unwrap();
    assert!(
        exec.contains(" render ") && exec.contains("--spp 4 --threads \"$SLURM_CPUS_PER_TASK\""),
        "{exec}"
    );
    assert!(
        exec.ends_with("--frames \"$first..$last\" --skip-existing"),
        "{exec}"
    );

    ok(&with(&["--partitions", "4", "--slurm-partition", "short"]));
    let script = std::fs::read_to_string(dir.path().join("shot.sbatch")).unwrap();
    assert!(
        script.contains("#SBATCH --array=0-47\n") && script.contains("#SBATCH --partition=short\n"),
        "{script}"
    );
    let merge = std::fs::read_to_string(dir.path().join("shot.merge.sbatch")).unwrap();
    assert_eq!(merge.matches(" merge ").count(), 12, "{merge}");

    // `--partition` would be ambiguous here.
    let o = radiant(&with(&["--partition", "gpu"]));
    assert!(!o.status.success());
    assert!(
        stderr(&o).contains("use `--queue gpu` (or `--slurm-partition`) for the Slurm partition"),
        "{}",
        stderr(&o)
    );
    // More partitions than samples.
    let o = radiant(&with(&["--partitions", "32"]));
    assert!(
        stderr(&o).contains("32 partitions of 16 samples"),
        "{}",
        stderr(&o)
    );

    // No sbatch on PATH: how to install it, and a failure.
    let empty = tempfile::tempdir().unwrap();
    let o = radiant_with_path(&with(&["--submit"]), Some(empty.path()));
    assert!(!o.status.success());
    let e = stderr(&o);
    assert!(
        e.contains("`sbatch` was not found on PATH") && e.contains("apt-get install slurm-client"),
        "{e}"
    );
    assert!(stdout(&o).is_empty());
}

#[test]
fn farm_status_lists_done_missing_and_partial_frames() {
    let dir = tempfile::tempdir().unwrap();
    let scene = shot(dir.path(), "shot.yaml", "independent");
    let out = dir.path().join("frame_####.exr");
    render(&scene, "1..3", &out, &["--spp", "1"]);
    render(&scene, "6", &out, &["--spp", "1"]);
    // Frame 3 cut short, frame 5 half its partitions.
    let three = dir.path().join("frame_0003.exr");
    let bytes = std::fs::read(&three).unwrap();
    std::fs::write(&three, &bytes[..bytes.len() / 2]).unwrap();
    let part = dir.path().join("frame_0005.part-1-of-2.exr");
    render(&scene, "5", &part, &["--partition", "1/2"]);
    let listing = ok(&[
        "farm",
        "status",
        arg(&out),
        "--frames",
        "1..7",
        "--partitions",
        "2",
    ]);
    let lines: Vec<&str> = listing.lines().collect();
    assert_eq!(
        lines[..4],
        [
            "7 frames: 3 done, 2 missing, 2 partial",
            "done: 1..2, 6",
            "missing: 4, 7",
            "partial: 3, 5"
        ],
        "{listing}"
    );
    assert!(
        lines[4].starts_with("  frame 3: ") && lines[4].contains("frame_0003.exr"),
        "{listing}"
    );
    assert_eq!(
        lines[5],
        "  frame 5: 1 of 2 partitions rendered, not merged"
    );
}
