//! `radiant farm`: rendering on a cluster. `farm slurm` writes (and with
//! `--submit` submits) the Slurm job scripts of a sequence or of a
//! partitioned frame (`radiant::farm::slurm`); `farm status` lists which
//! frames of a sequence are done, missing or partial.

use super::diagnostic::report;
use super::film_args::FilmArgs;
use super::render::{check_frames, check_output, frame_path, parse_frames};
use super::sampling_args::SamplingArgs;
use clap::{Args, Subcommand, ValueEnum};
use radiant::backend::BackendKind;
use radiant::farm::partition::Partition;
use radiant::farm::slurm::{self, Job, Resources, Split};
use radiant::farm::status::{FrameState, frame_states, ranges};
use std::path::{Path, PathBuf};

/// The farm subcommands.
#[derive(Subcommand)]
pub enum FarmCommand {
    /// Write a Slurm job array that renders a sequence (chunks of frames
    /// per task) or frames split into sample partitions (and a merge job);
    /// `--submit` submits it with sbatch and prints the job ids.
    Slurm(Box<SlurmArgs>),
    /// List which frames of a sequence are done, missing or partial.
    Status(StatusArgs),
}

/// Options of `radiant farm slurm`.
#[derive(Args)]
pub struct SlurmArgs {
    /// The scene file (YAML).
    scene: PathBuf,
    /// The output, with a run of `#` for the frame number
    /// (`out/frame_####.exr`).
    #[arg(short, long)]
    output: PathBuf,
    /// The frames: `A..B` or `N` (default: all the scene's frames).
    #[arg(long, value_parser = parse_frames)]
    frames: Option<(i64, i64)>,
    /// Frames each array task renders (default 1).
    #[arg(long, value_parser = clap::value_parser!(u32).range(1..), conflicts_with = "partitions")]
    chunk: Option<u32>,
    /// Split each frame into N sample partitions, one array task each, and
    /// merge them in a job that runs when all succeeded.
    #[arg(long, value_parser = clap::value_parser!(u32).range(1..))]
    partitions: Option<u32>,
    /// The Slurm partition (queue) to run in: sbatch's `--partition`,
    /// named apart from the sample partitions of `--partitions`.
    #[arg(long, visible_alias = "slurm-partition")]
    queue: Option<String>,
    /// Wall-time limit per task (`01:00:00`).
    #[arg(long)]
    time: Option<String>,
    /// CPU cores per task; each render uses that many threads.
    #[arg(long, value_parser = clap::value_parser!(u32).range(1..))]
    cpus_per_task: Option<u32>,
    /// Memory per task's node (`16G`).
    #[arg(long)]
    mem: Option<String>,
    /// Not an option here: ambiguous between Slurm's queue and a sample
    /// partition.
    #[arg(long, hide = true, allow_hyphen_values = true)]
    partition: Option<String>,
    /// Submit the scripts with sbatch and print the job ids.
    #[arg(long)]
    submit: bool,
    /// Where to write the script (default: `SCENE.sbatch` beside the
    /// output; the merge job's is `.merge.sbatch`). Slurm's logs go beside
    /// it.
    #[arg(long)]
    script: Option<PathBuf>,
    /// The radiant binary the nodes run (default: this one; it must be on
    /// a file system the nodes share).
    #[arg(long)]
    radiant: Option<PathBuf>,
    #[command(flatten)]
    sampling: SamplingArgs,
    /// The same noise pattern in every frame (passed to each render).
    #[arg(long)]
    lock_noise: bool,
    /// Which backend each render uses.
    #[arg(long, value_enum)]
    backend: Option<BackendKind>,
    #[command(flatten)]
    film: FilmArgs,
}

/// Options of `radiant farm status`.
#[derive(Args)]
pub struct StatusArgs {
    /// The sequence's output, with a run of `#` (`out/frame_####.exr`).
    output: PathBuf,
    /// The frames to look at: `A..B` or `N`.
    #[arg(long, value_parser = parse_frames)]
    frames: (i64, i64),
    /// Count frames with some of these N sample partitions rendered (and
    /// no merged file) as partial.
    #[arg(long, value_parser = clap::value_parser!(u32).range(1..))]
    partitions: Option<u32>,
}

/// Runs a farm subcommand.
pub fn run(command: &FarmCommand) -> miette::Result<()> {
    match command {
        FarmCommand::Slurm(args) => slurm_job(args),
        FarmCommand::Status(args) => status(args),
    }
}

/// `path` made absolute (so that every node finds it) as UTF-8 text.
fn absolute(path: &Path) -> miette::Result<String> {
    let absolute = std::path::absolute(path)
        .map_err(|e| miette::miette!("cannot resolve `{}`: {e}", path.display()))?;
    absolute.to_str().map(str::to_string).ok_or_else(|| {
        miette::miette!(
            "`{}` is not valid UTF-8, which a job script needs",
            path.display()
        )
    })
}

/// The options every render of the job takes.
fn render_options(args: &SlurmArgs) -> Vec<String> {
    let mut options = Vec::new();
    let mut add = |name: &str, value: Option<String>| {
        if let Some(value) = value {
            options.push(format!("--{name}"));
            options.push(value);
        }
    };
    let sampling = &args.sampling;
    add("spp", sampling.spp.map(|v| v.to_string()));
    add("max-depth", sampling.max_depth.map(|v| v.to_string()));
    add("seed", sampling.seed.map(|v| v.to_string()));
    add("width", args.film.width.map(|v| v.to_string()));
    add("height", args.film.height.map(|v| v.to_string()));
    add("threads", args.film.threads.map(|v| v.to_string()));
    add(
        "backend",
        args.backend
            .and_then(|b| b.to_possible_value())
            .map(|v| v.get_name().to_string()),
    );
    if args.lock_noise {
        options.push("--lock-noise".into());
    }
    options
}

/// The job `args` describe, checked against the scene.
fn job(args: &SlurmArgs) -> miette::Result<Job> {
    if let Some(value) = &args.partition {
        miette::bail!(
            "`farm slurm --partition {value}` is ambiguous: use `--queue {value}` (or `--slurm-partition`) for the Slurm partition to run in, or `--partitions N` to split each frame into N sample partitions"
        );
    }
    if args.film.threads.is_some() && args.cpus_per_task.is_some() {
        miette::bail!(
            "give --cpus-per-task or --threads, not both: with --cpus-per-task each render uses that many threads"
        );
    }
    check_output(&frame_path(&args.output, 0))?;
    let scene = radiant::scene::load(&args.scene).map_err(report)?;
    let timeline = scene.timeline;
    let (first, last) = args.frames.unwrap_or((timeline.start, timeline.end));
    check_frames(&args.scene, &timeline, (first, last))?;
    let split = match args.partitions {
        Some(count) => {
            let spp = args.sampling.spp.unwrap_or(scene.settings.spp);
            Partition::new(count, count)
                .and_then(|p| p.samples(spp))
                .map_err(|e| miette::miette!("{e}"))?;
            Split::Partitions(count)
        }
        None => Split::Chunks(args.chunk.unwrap_or(1)),
    };
    let output = absolute(&args.output)?;
    let names_frames = output.contains('#');
    if last > first && !names_frames {
        miette::bail!(
            "cannot write {} frames to `{}`: put a run of `#` in the output name for the frame number, as in `out/frame_####.exr`",
            last - first + 1,
            args.output.display()
        );
    }
    let radiant = match &args.radiant {
        Some(path) => absolute(path)?,
        None => std::env::current_exe()
            .map_err(|e| {
                miette::miette!("cannot find this program's path ({e}); give --radiant PATH")
            })
            .and_then(|p| absolute(&p))?,
    };
    let script = script_path(args);
    let log_dir = script
        .parent()
        .map(absolute)
        .transpose()?
        .unwrap_or_default();
    let stem = args
        .scene
        .file_stem()
        .map(|s| s.to_string_lossy().into_owned())
        .unwrap_or_default();
    Ok(Job {
        name: format!("radiant-{stem}"),
        radiant,
        scene: absolute(&args.scene)?,
        output,
        frames: (first, last),
        split,
        render_options: render_options(args),
        resources: Resources {
            queue: args.queue.clone(),
            time: args.time.clone(),
            cpus_per_task: args.cpus_per_task,
            mem: args.mem.clone(),
        },
        log_dir,
    })
}

/// Where the array script goes.
fn script_path(args: &SlurmArgs) -> PathBuf {
    args.script.clone().unwrap_or_else(|| {
        let stem = args.scene.file_stem().unwrap_or_default();
        args.output
            .with_file_name(format!("{}.sbatch", stem.to_string_lossy()))
    })
}

/// `radiant farm slurm`.
fn slurm_job(args: &SlurmArgs) -> miette::Result<()> {
    let job = job(args)?;
    let error = |e: slurm::SlurmError| miette::miette!("{e}");
    let script = script_path(args);
    slurm::write_script(&script, &job.render_script().map_err(error)?).map_err(error)?;
    let what = match job.split {
        Split::Chunks(chunk) => format!(
            "frames {}..{}, {chunk} per task",
            job.frames.0, job.frames.1
        ),
        Split::Partitions(count) => format!(
            "frames {}..{} in {count} sample partitions each",
            job.frames.0, job.frames.1
        ),
    };
    eprintln!(
        "wrote `{}`: {} array tasks, {what}",
        script.display(),
        job.tasks()
    );
    let merge = match job.merge_script().map_err(error)? {
        Some(text) => {
            let path = script.with_extension("merge.sbatch");
            slurm::write_script(&path, &text).map_err(error)?;
            eprintln!("wrote `{}`: the merge job", path.display());
            Some(path)
        }
        None => None,
    };
    if !args.submit {
        eprintln!("submit with: sbatch {}", script.display());
        if let Some(merge) = &merge {
            eprintln!(
                "then:        sbatch --dependency=afterok:JOBID {}",
                merge.display()
            );
        }
        return Ok(());
    }
    let id = slurm::submit(&script, None).map_err(error)?;
    println!("{id}");
    eprintln!("submitted job array {id}");
    if let Some(merge) = &merge {
        let merge_id = slurm::submit(merge, Some(&id)).map_err(error)?;
        println!("{merge_id}");
        eprintln!("submitted merge job {merge_id}, to run after {id} succeeded");
    }
    Ok(())
}

/// `radiant farm status`.
fn status(args: &StatusArgs) -> miette::Result<()> {
    let states = frame_states(&args.output, args.frames, args.partitions);
    let of = |wanted: fn(&FrameState) -> bool| -> Vec<i64> {
        states
            .iter()
            .filter(|(_, s)| wanted(s))
            .map(|(f, _)| *f)
            .collect()
    };
    let done = of(|s| *s == FrameState::Done);
    let missing = of(|s| *s == FrameState::Missing);
    let partial = of(|s| matches!(s, FrameState::Partial(_)));
    println!(
        "{} frames: {} done, {} missing, {} partial",
        states.len(),
        done.len(),
        missing.len(),
        partial.len()
    );
    println!("done: {}", ranges(&done));
    println!("missing: {}", ranges(&missing));
    println!("partial: {}", ranges(&partial));
    for (frame, state) in &states {
        if let FrameState::Partial(why) = state {
            println!("  frame {frame}: {why}");
        }
    }
    Ok(())
}
