//! Rendering on a real Slurm cluster: a one-node cluster on this machine
//! (Debian's slurm-wlm and munge, started by `.ci/slurm-up`, which
//! `.ci/run` calls before the tests). A sequence goes out as a job array,
//! one of its tasks is killed mid-way and the resubmitted array fills the
//! gap; a partitioned frame goes out as an array and a dependent merge job.
//! Every frame is checked against a render on this machine. Without a
//! cluster these tests fail, saying how to start one; they never skip.

// `unwrap`/`expect` in this test code is the assertion: the inputs are the
// test's own, so a failure is a bug, and the panic reports it.

mod common;

use common::{arg, difference, farm_slurm, ok, read, render, shot};
use std::path::Path;
use std::process::Command;
use std::time::{Duration, Instant};

/// How long a job may take before the test fails with the queue's state.
const LIMIT: Duration = Duration::from_secs(180);

/// Samples per pixel of the sequence: enough for a 32×32 frame to take a
/// few tenths of a second on one core, so that a task can be killed
/// between its frames.
const SEQUENCE_SPP: &str = "1024";

/// Runs a Slurm command; returns its standard output and error.
fn slurm(command: &str, args: &[&str]) -> String {
    match Command::new(command).args(args).output() {
        Ok(o) => format!(
            "{}{}",
            String::from_utf8_lossy(&o.stdout),
            String::from_utf8_lossy(&o.stderr)
        ),
        Err(e) => format!("{command}: {e}"),
    }
}

/// Fails unless a Slurm node takes jobs.
fn cluster() {
    let state = slurm("sinfo", &["-h", "-o", "%T"]);
    assert!(
        state
            .lines()
            .any(|l| ["idle", "mixed", "allocated"].contains(&l.trim())),
        "no Slurm cluster takes jobs here; start the one-node cluster with `.ci/slurm-up` \
         (as root on Debian; `.ci/run` does). sinfo said: {state}"
    );
}

/// What the queue and the controller know of `jobs`, for a failure.
fn diagnostics(jobs: &[String]) -> String {
    let list = jobs.join(",");
    format!(
        "squeue:\n{}\nscontrol:\n{}\nsacct:\n{}",
        slurm("squeue", &["-a"]),
        jobs.iter()
            .map(|j| slurm("scontrol", &["show", "job", j]))
            .collect::<String>(),
        slurm("sacct", &["-j", &list])
    )
}

/// Waits (at most [`LIMIT`]) until `done` holds, failing with the state of
/// `jobs` if it does not.
fn wait_until(jobs: &[String], what: &str, done: impl Fn() -> bool) {
    let start = Instant::now();
    while !done() {
        assert!(
            start.elapsed() < LIMIT,
            "{what}: not after {LIMIT:?}\n{}",
            diagnostics(jobs)
        );
        std::thread::sleep(Duration::from_millis(50));
    }
}

/// Waits until `jobs` have left the queue.
fn wait_for(jobs: &[String]) {
    let list = jobs.join(",");
    wait_until(jobs, "the jobs are finished", || {
        slurm("squeue", &["-h", "-j", &list, "-o", "%i"])
            .trim()
            .is_empty()
    });
}

/// The `key=value` fields of each record of `scontrol -o show job JOB`
/// (one per array task).
fn records(job: &str) -> Vec<Vec<(String, String)>> {
    slurm("scontrol", &["-o", "show", "job", job])
        .lines()
        .map(|line| {
            line.split_whitespace()
                .filter_map(|f| f.split_once('='))
                .map(|(k, v)| (k.to_string(), v.to_string()))
                .collect()
        })
        .collect()
}

/// A field of a record.
fn field<'a>(record: &'a [(String, String)], key: &str) -> &'a str {
    record
        .iter()
        .find(|(k, _)| k == key)
        .map_or("", |(_, v)| v.as_str())
}

/// The state of each task of `job`, by array index (0 for a plain job).
fn states(job: &str) -> Vec<(u32, String)> {
    let mut states: Vec<(u32, String)> = records(job)
        .iter()
        .map(|r| {
            let task = field(r, "ArrayTaskId").parse().unwrap_or(0);
            (task, field(r, "JobState").to_string())
        })
        .collect();
    states.sort();
    states
}

/// Submits with `radiant farm slurm ARGS --submit`; returns the job ids.
fn submit(args: &[&str]) -> Vec<String> {
    let mut args = args.to_vec();
    args.push("--submit");
    ok(&args).lines().map(str::to_string).collect()
}

/// Checks that every task of `job` completed.
fn completed(job: &str, tasks: usize) {
    let states = states(job);
    assert_eq!(
        states.len(),
        tasks,
        "{states:?}\n{}",
        diagnostics(&[job.to_string()])
    );
    assert!(
        states.iter().all(|(_, s)| s == "COMPLETED"),
        "{states:?}\n{}",
        diagnostics(&[job.to_string()])
    );
}

fn modified(path: &Path) -> std::time::SystemTime {
    std::fs::metadata(path).unwrap().modified().unwrap()
}

#[test]
fn a_job_array_renders_a_sequence_and_its_resubmission_fills_a_killed_tasks_gap() {
    cluster();
    let dir = tempfile::tempdir().unwrap();
    let scene = shot(dir.path(), "shot.yaml", "independent");
    std::fs::create_dir(dir.path().join("farm")).unwrap();
    let out = dir.path().join("farm/frame_####.exr");
    let frame = |f: i64| dir.path().join(format!("farm/frame_{f:04}.exr"));
    let args = farm_slurm(
        &scene,
        &out,
        "1..12",
        &[
            "--chunk",
            "4",
            "--cpus-per-task",
            "1",
            "--time",
            "00:05:00",
            "--spp",
            SEQUENCE_SPP,
        ],
    );
    let jobs = submit(&args);
    assert_eq!(jobs.len(), 1, "{jobs:?}");
    let job = &jobs[0];
    // Task 1 renders frames 5..8: kill it once frame 5 is written.
    wait_until(&jobs, "task 1 wrote frame 5", || frame(5).exists());
    let killed = slurm("scancel", &[&format!("{job}_1")]);
    assert!(killed.trim().is_empty(), "scancel: {killed}");
    wait_for(&jobs);
    let first = states(job);
    assert_eq!(first[1], (1, "CANCELLED".to_string()), "{first:?}");
    assert!(
        first[0].1 == "COMPLETED" && first[2].1 == "COMPLETED",
        "{first:?}"
    );
    let gap: Vec<i64> = (1..=12).filter(|&f| !frame(f).exists()).collect();
    assert!(
        !gap.is_empty() && gap.iter().all(|f| (6..=8).contains(f)),
        "the kill left frames {gap:?} missing; expected some of 6..8 (was the task finished before scancel?)"
    );
    let status = ok(&["farm", "status", arg(&out), "--frames", "1..12"]);
    assert!(
        status.starts_with(&format!(
            "12 frames: {} done, {} missing, 0 partial",
            12 - gap.len(),
            gap.len()
        )),
        "{status}"
    );
    let kept = modified(&frame(5));

    // The same array again renders only the gap.
    let again = submit(&args);
    wait_for(&again);
    completed(&again[0], 3);
    let status = ok(&["farm", "status", arg(&out), "--frames", "1..12"]);
    assert!(
        status.starts_with("12 frames: 12 done, 0 missing, 0 partial"),
        "{status}"
    );
    assert_eq!(modified(&frame(5)), kept, "frame 5 was rendered again");

    // Every frame is the frame this machine renders.
    let local = dir.path().join("local_####.exr");
    render(&scene, "1..12", &local, &["--spp", SEQUENCE_SPP]);
    for f in 1..=12 {
        let here = read(&dir.path().join(format!("local_{f:04}.exr")));
        assert!(
            read(&frame(f)) == here,
            "frame {f} differs from this machine's render"
        );
    }
}

#[test]
fn a_partitioned_frame_is_merged_after_its_array_into_the_single_machine_image() {
    cluster();
    let dir = tempfile::tempdir().unwrap();
    let scene = shot(dir.path(), "shot.yaml", "independent");
    let out = dir.path().join("frame_####.exr");
    let jobs = submit(&farm_slurm(
        &scene,
        &out,
        "7",
        &["--partitions", "4", "--cpus-per-task", "1", "--spp", "64"],
    ));
    assert_eq!(jobs.len(), 2, "an array and a merge job: {jobs:?}");
    wait_for(&jobs);
    completed(&jobs[0], 4);
    completed(&jobs[1], 1);
    // The merge started after the last partition ended.
    let ended = records(&jobs[0])
        .iter()
        .map(|r| field(r, "EndTime").to_string())
        .max()
        .unwrap();
    let merge = records(&jobs[1]);
    let started = field(&merge[0], "StartTime");
    assert!(
        started >= ended.as_str(),
        "merge started {started}, partitions ended {ended}"
    );

    let single = dir.path().join("single.exr");
    render(&scene, "7", &single, &["--spp", "64"]);
    let (largest, same) = difference(&read(&dir.path().join("frame_0007.exr")), &read(&single));
    assert_eq!(
        same, 1024,
        "merged on Slurm: largest difference {largest:e} of the peak"
    );
}
