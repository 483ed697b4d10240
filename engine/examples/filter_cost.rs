//! Benchmark of what the pixel filter costs: the Cornell box at 64 spp
//! with `box`, `gaussian` (radius 2) and `lanczos` (radius 3), each with
//! `filter_sampling: splat` and `importance`, reported as samples per
//! second and as the ratio to `box` measured in the same run. Each
//! configuration renders three times, interleaved with the others; the
//! fastest render counts, which keeps noise from other processes out.
//!
//! ```text
//! cargo run --release --example filter_cost [-- --threads N]
//! ```

use anyhow::{Context, Result};
use radiant::backend::cpu::{Progress, render};
use radiant::extract::{Overrides, extract};
use radiant::scene::FilterSampling;
use std::path::Path;

/// Renders per configuration; the fastest counts.
const REPEATS: usize = 3;

fn main() -> Result<()> {
    let threads = std::env::args()
        .skip_while(|a| a != "--threads")
        .nth(1)
        .map(|t| t.parse::<usize>())
        .transpose()
        .context("--threads takes a number")?;
    if let Some(n) = threads {
        rayon::ThreadPoolBuilder::new()
            .num_threads(n)
            .build_global()
            .context("thread pool")?;
    }
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("../scenes/cornell-box.yaml");
    let text = std::fs::read_to_string(&path).context("reading the Cornell box")?;
    let filters = [
        ("box", "{type: box}"),
        ("gaussian", "{type: gaussian, stddev: 0.5}"),
        ("lanczos", "{type: lanczos, lobes: 3}"),
    ];
    let line = "  filter: {type: gaussian, stddev: 0.5}";
    anyhow::ensure!(text.contains(line), "the Cornell box's filter line moved");
    let registry = radiant::builtin_registry();
    let mut configs = Vec::new();
    for sampling in [FilterSampling::Splat, FilterSampling::Importance] {
        for (name, filter) in filters {
            let scene_text = text.replace(line, &format!("  filter: {filter}"));
            let scene = radiant::scene::from_str(
                &scene_text,
                &path,
                path.parent().unwrap_or(Path::new(".")),
            )?;
            let mut r = extract(&scene, &registry, &Overrides::default())?;
            r.settings.filter_sampling = sampling;
            configs.push((name, sampling, r, f64::INFINITY));
        }
    }
    for _ in 0..REPEATS {
        for (_, _, scene, best) in &mut configs {
            let rendered = render(scene, &Progress::none());
            *best = best.min(rendered.time.as_secs_f64());
        }
    }
    let samples = {
        let s = &configs[0].2.settings;
        (s.width * s.height * s.spp) as f64
    };
    println!("filter     sampling    Msamples/s  time vs box (same sampling)");
    for (name, sampling, _, best) in &configs {
        let reference = configs
            .iter()
            .find(|(n, s, _, _)| *n == "box" && s == sampling)
            .map_or(*best, |c| c.3);
        println!(
            "{name:<10} {:<11} {:>10.2}  {:>6.2}",
            format!("{sampling:?}").to_lowercase(),
            samples / best / 1e6,
            best / reference
        );
    }
    Ok(())
}
