//! Slurm job scripts. A sequence becomes a job array whose tasks each
//! render a chunk of frames with `--skip-existing` (so resubmitting the same
//! script renders only the frames still missing); a partitioned frame
//! becomes an array of one task per (frame, sample partition) and a merge
//! job that runs after the whole array succeeded (`--dependency=afterok`).
//! [`submit`] hands a script to `sbatch`.

use super::partition::Partition;
use crate::world::systems::sequence_path;
use std::fmt::Write as _;
use std::io::Write as _;
use std::path::{Path, PathBuf};
use std::process::Command;

/// What each task asks Slurm for (`#SBATCH` options); `None` leaves the
/// cluster's default.
#[derive(Debug, Clone, Default, PartialEq, Eq)]
pub struct Resources {
    /// The Slurm partition (queue) to run in.
    pub queue: Option<String>,
    /// Wall-time limit per task, in Slurm's format (`01:00:00`).
    pub time: Option<String>,
    /// CPU cores per task (the render's `--threads`).
    pub cpus_per_task: Option<u32>,
    /// Memory per node, in Slurm's format (`16G`).
    pub mem: Option<String>,
}

/// How the array divides the work.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Split {
    /// Each task renders this many consecutive frames.
    Chunks(u32),
    /// Each task renders one of this many sample partitions of one frame;
    /// a merge job adds them up.
    Partitions(u32),
}

/// A render spread over a job array.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Job {
    /// The job's name in `squeue`.
    pub name: String,
    /// The `radiant` binary the nodes run (on a shared file system).
    pub radiant: String,
    /// The scene file (absolute, so that any node finds it).
    pub scene: String,
    /// The output, with a run of `#` for the frame number (absolute).
    pub output: String,
    /// The first and last frame.
    pub frames: (i64, i64),
    /// How tasks divide the frames.
    pub split: Split,
    /// Further options of every `radiant render` (`--spp 64`, …).
    pub render_options: Vec<String>,
    /// What each task asks for.
    pub resources: Resources,
    /// Where Slurm writes each task's output (`slurm-JOB_TASK.out`).
    pub log_dir: String,
}

/// Why a job cannot be written or submitted.
#[derive(Debug, thiserror::Error)]
pub enum SlurmError {
    /// A text cannot go into a shell script.
    #[error("`{0}` cannot be written into a shell script (it holds a NUL byte)")]
    Unquotable(String),
    /// The script could not be written.
    #[error("cannot write `{path}`: {message}")]
    Write {
        /// The script.
        path: String,
        /// What went wrong.
        message: String,
    },
    /// `sbatch` is not installed.
    #[error(
        "cannot submit `{script}`: `sbatch` was not found on PATH. Install Slurm's client commands (Debian and Ubuntu: `apt-get install slurm-client`; `slurm-wlm` for a whole one-node cluster), or submit the script on a machine that has them: sbatch {script}"
    )]
    NoSbatch {
        /// The script that was written.
        script: String,
    },
    /// `sbatch` ran and refused the job, or could not run.
    #[error("sbatch {script} failed: {message}")]
    Sbatch {
        /// The script.
        script: String,
        /// What sbatch said.
        message: String,
    },
}

/// `text` quoted for a POSIX shell.
fn quote(text: &str) -> Result<String, SlurmError> {
    shlex::try_quote(text)
        .map(|q| q.into_owned())
        .map_err(|_| SlurmError::Unquotable(text.to_string()))
}

/// The file partition `partition` of `frame` is rendered to, beside the
/// frame's own output: `frame_0042.part-3-of-16.exr` for
/// `frame_####.exr`.
pub fn part_path(output: &Path, frame: i64, partition: Partition) -> PathBuf {
    let (prefix, suffix) = part_name(output, partition.count());
    let name = format!("{prefix}{}{suffix}", partition.index());
    sequence_path(Path::new(&name), frame)
}

/// The name of the partitions of `count` as the text before and after the
/// partition's number (the frame's `#` still in it).
fn part_name(output: &Path, count: u32) -> (String, String) {
    let stem = output.with_extension("");
    (
        format!("{}.part-", stem.display()),
        format!("-of-{count}.exr"),
    )
}

impl Job {
    /// The number of array tasks.
    pub fn tasks(&self) -> u64 {
        let frames = (self.frames.1 - self.frames.0 + 1) as u64;
        match self.split {
            Split::Chunks(chunk) => frames.div_ceil(u64::from(chunk.max(1))),
            Split::Partitions(count) => frames * u64::from(count),
        }
    }

    /// The `#SBATCH` header of a script named `name`, and `set -eu`.
    fn header(&self, name: &str, array: Option<u64>) -> Result<String, SlurmError> {
        let mut s = String::from("#!/bin/bash\n");
        let _ = writeln!(s, "#SBATCH --job-name={}", quote(name)?);
        let log = match array {
            Some(tasks) => {
                let _ = writeln!(s, "#SBATCH --array=0-{}", tasks - 1);
                "slurm-%A_%a.out"
            }
            None => "slurm-%j.out",
        };
        let log = Path::new(&self.log_dir).join(log);
        let _ = writeln!(s, "#SBATCH --output={}", quote(&log.to_string_lossy())?);
        let r = &self.resources;
        let options = [
            ("partition", r.queue.clone()),
            ("time", r.time.clone()),
            ("cpus-per-task", r.cpus_per_task.map(|n| n.to_string())),
            ("mem", r.mem.clone()),
        ];
        for (option, value) in options {
            if let Some(value) = value {
                let _ = writeln!(s, "#SBATCH --{option}={}", quote(&value)?);
            }
        }
        s.push_str("set -eu\n");
        Ok(s)
    }

    /// `radiant render SCENE` with the job's options, quoted.
    fn render_command(&self) -> Result<String, SlurmError> {
        let mut words = vec![quote(&self.radiant)?, "render".into(), quote(&self.scene)?];
        for option in &self.render_options {
            words.push(quote(option)?);
        }
        if self.resources.cpus_per_task.is_some() {
            words.push("--threads \"$SLURM_CPUS_PER_TASK\"".into());
        }
        Ok(words.join(" "))
    }

    /// The array script: each task renders its chunk of frames, or its
    /// partition of a frame, leaving files that exist.
    pub fn render_script(&self) -> Result<String, SlurmError> {
        let (first, last) = self.frames;
        let mut s = self.header(&self.name, Some(self.tasks()))?;
        let task = "$SLURM_ARRAY_TASK_ID";
        match self.split {
            Split::Chunks(chunk) => {
                let _ = writeln!(s, "# Frames {first}..{last}, {chunk} per task.");
                let _ = writeln!(s, "first=$(({first} + {task} * {chunk}))");
                let _ = writeln!(
                    s,
                    "last=$((first + {} < {last} ? first + {} : {last}))",
                    chunk - 1,
                    chunk - 1
                );
                let _ = writeln!(
                    s,
                    "exec {} -o {} --frames \"$first..$last\" --skip-existing",
                    self.render_command()?,
                    quote(&self.output)?
                );
            }
            Split::Partitions(count) => {
                let _ = writeln!(
                    s,
                    "# Frames {first}..{last}, each in {count} sample partitions (one per task)."
                );
                let _ = writeln!(s, "frame=$(({first} + {task} / {count}))");
                let _ = writeln!(s, "part=$(({task} % {count} + 1))");
                let (prefix, suffix) = part_name(Path::new(&self.output), count);
                let _ = writeln!(
                    s,
                    "exec {} -o {}\"$part\"{} --frames \"$frame\" --partition \"$part/{count}\" --skip-existing",
                    self.render_command()?,
                    quote(&prefix)?,
                    quote(&suffix)?
                );
            }
        }
        Ok(s)
    }

    /// The merge script of a partitioned job (run after the array
    /// succeeded): one `radiant merge` per frame. `None` for chunks.
    pub fn merge_script(&self) -> Result<Option<String>, SlurmError> {
        let Split::Partitions(count) = self.split else {
            return Ok(None);
        };
        let mut s = self.header(&format!("{}-merge", self.name), None)?;
        for frame in self.frames.0..=self.frames.1 {
            let mut words = vec![quote(&self.radiant)?, "merge".into()];
            for index in 1..=count {
                let partition = Partition::new(index, count).expect("1 ≤ index ≤ count");
                let part = part_path(Path::new(&self.output), frame, partition);
                words.push(quote(&part.to_string_lossy())?);
            }
            words.push("-o".into());
            let output = sequence_path(Path::new(&self.output), frame);
            words.push(quote(&output.to_string_lossy())?);
            s.push_str(&words.join(" "));
            s.push('\n');
        }
        Ok(Some(s))
    }
}

/// Writes the script `text` to `path` atomically (a temporary file beside
/// it, renamed into place).
pub fn write_script(path: &Path, text: &str) -> Result<(), SlurmError> {
    let error = |e: std::io::Error| SlurmError::Write {
        path: path.display().to_string(),
        message: e.to_string(),
    };
    let mut tmp = crate::film::output::temp_file_beside(path, ".tmp").map_err(error)?;
    tmp.write_all(text.as_bytes()).map_err(error)?;
    tmp.as_file().sync_all().map_err(error)?;
    tmp.persist(path).map_err(|e| error(e.error))?;
    Ok(())
}

/// Submits `script` with `sbatch` (after the jobs in `after` succeeded, if
/// any) and returns the job id.
pub fn submit(script: &Path, after: Option<&str>) -> Result<String, SlurmError> {
    let name = script.display().to_string();
    let mut command = Command::new("sbatch");
    command.arg("--parsable");
    if let Some(job) = after {
        command.arg(format!("--dependency=afterok:{job}"));
    }
    let output = command.arg(script).output().map_err(|e| match e.kind() {
        std::io::ErrorKind::NotFound => SlurmError::NoSbatch {
            script: name.clone(),
        },
        _ => SlurmError::Sbatch {
            script: name.clone(),
            message: e.to_string(),
        },
    })?;
    let stdout = String::from_utf8_lossy(&output.stdout);
    // `--parsable` prints `id` or `id;cluster`.
    let id = stdout
        .trim()
        .split(';')
        .next()
        .unwrap_or_default()
        .to_string();
    if !output.status.success() || id.is_empty() {
        return Err(SlurmError::Sbatch {
            script: name,
            message: format!(
                "{} {}",
                output.status,
                String::from_utf8_lossy(&output.stderr).trim()
            ),
        });
    }
    Ok(id)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn job(split: Split) -> Job {
        Job {
            name: "radiant-shot".into(),
            radiant: "/opt/radiant/bin/radiant".into(),
            scene: "/home/me/my scenes/shot.yaml".into(),
            output: "/home/me/out/frame_####.exr".into(),
            frames: (1, 12),
            split,
            render_options: vec!["--spp".into(), "64".into()],
            resources: Resources {
                queue: Some("gpu".into()),
                time: Some("01:00:00".into()),
                cpus_per_task: Some(8),
                mem: None,
            },
            log_dir: "/home/me/out".into(),
        }
    }

    #[test]
    fn chunks_become_array_tasks() {
        let script = job(Split::Chunks(5)).render_script().expect("quotable");
        assert_eq!(
            script,
            "#!/bin/bash\n\
             #SBATCH --job-name=radiant-shot\n\
             #SBATCH --array=0-2\n\
             #SBATCH --output='/home/me/out/slurm-%A_%a.out'\n\
             #SBATCH --partition=gpu\n\
             #SBATCH --time=01:00:00\n\
             #SBATCH --cpus-per-task=8\n\
             set -eu\n\
             # Frames 1..12, 5 per task.\n\
             first=$((1 + $SLURM_ARRAY_TASK_ID * 5))\n\
             last=$((first + 4 < 12 ? first + 4 : 12))\n\
             exec /opt/radiant/bin/radiant render '/home/me/my scenes/shot.yaml' --spp 64 \
             --threads \"$SLURM_CPUS_PER_TASK\" -o '/home/me/out/frame_####.exr' \
             --frames \"$first..$last\" --skip-existing\n"
        );
        assert_eq!(job(Split::Chunks(12)).tasks(), 1);
        assert_eq!(job(Split::Chunks(1)).tasks(), 12);
        assert_eq!(
            job(Split::Chunks(100)).merge_script().expect("quotable"),
            None
        );
    }

    #[test]
    fn the_chunks_cover_the_frames_once() {
        // What bash computes for each task, in Rust.
        for (first, last, chunk) in [(1, 12, 5), (-3, 4, 2), (7, 7, 3), (1, 250, 5)] {
            let mut j = job(Split::Chunks(chunk));
            j.frames = (first, last);
            let mut next = first;
            for task in 0..j.tasks() as i64 {
                let a = first + task * chunk as i64;
                let b = (a + chunk as i64 - 1).min(last);
                assert_eq!(a, next);
                next = b + 1;
            }
            assert_eq!(next, last + 1);
        }
    }

    #[test]
    fn partitions_become_tasks_and_a_merge() {
        let mut j = job(Split::Partitions(4));
        j.frames = (7, 8);
        j.resources = Resources::default();
        let script = j.render_script().expect("quotable");
        assert!(script.contains("#SBATCH --array=0-7\n"), "{script}");
        assert!(!script.contains("--partition="), "{script}");
        assert!(
            script.contains(
                "frame=$((7 + $SLURM_ARRAY_TASK_ID / 4))\npart=$(($SLURM_ARRAY_TASK_ID % 4 + 1))\n"
            ),
            "{script}"
        );
        assert!(
            script.contains(" -o '/home/me/out/frame_####.part-'\"$part\"-of-4.exr --frames \"$frame\" --partition \"$part/4\" --skip-existing\n"),
            "{script}"
        );
        let merge = j.merge_script().expect("quotable").expect("partitioned");
        assert!(merge.contains("#SBATCH --job-name=radiant-shot-merge\n#SBATCH --output='/home/me/out/slurm-%j.out'\n"), "{merge}");
        assert!(merge.contains(
            "/opt/radiant/bin/radiant merge /home/me/out/frame_0008.part-1-of-4.exr /home/me/out/frame_0008.part-2-of-4.exr \
             /home/me/out/frame_0008.part-3-of-4.exr /home/me/out/frame_0008.part-4-of-4.exr -o /home/me/out/frame_0008.exr\n"
        ), "{merge}");
        assert_eq!(merge.matches(" merge ").count(), 2);
        assert_eq!(
            part_path(
                Path::new("out/f_##.exr"),
                3,
                Partition::new(2, 16).expect("valid")
            ),
            Path::new("out/f_03.part-2-of-16.exr")
        );
    }

    #[test]
    fn odd_names_are_quoted() {
        let mut j = job(Split::Chunks(1));
        j.scene = "/tmp/it's $HOME`x`.yaml".into();
        let script = j.render_script().expect("quotable");
        let line = script.lines().last().expect("a command");
        let words = shlex::split(line).expect("valid shell words");
        assert_eq!(words[3], "/tmp/it's $HOME`x`.yaml");
        j.scene = "a\0b".into();
        assert!(matches!(j.render_script(), Err(SlurmError::Unquotable(_))));
    }
}
