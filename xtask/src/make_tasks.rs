//! `cargo xtask make-tasks`: the evaluation set and the training pool.
//!
//! Candidates are drawn in index order from one seeded population (SPEC §2); the first
//! `eval_count` accepted tasks form the evaluation set and the next `train_count` the training
//! pool, so the two are disjoint by construction and each file is reproducible bit for bit.

use std::path::PathBuf;

use anyhow::Context;
use emg_control::{ClassicalGains, RolloutConfig, SamplerConfig, TaskSampler};
use emg_io::{TASK_FORMAT_VERSION, write_task_set};
use serde::Serialize;

use crate::{progress, workspace};

/// Options of `make-tasks`.
#[derive(clap::Args)]
pub struct Args {
    /// Tasks in the evaluation set.
    #[arg(long, default_value_t = 10_000)]
    eval_count: usize,
    /// Tasks in the training pool.
    #[arg(long, default_value_t = 50_000)]
    train_count: usize,
    /// Seed of the population.
    #[arg(long, default_value_t = SamplerConfig::default().seed)]
    seed: u64,
    /// Output directory.
    #[arg(long, default_value_os_t = workspace::data("tasks"))]
    out_dir: PathBuf,
    /// Robot file.
    #[arg(long, value_parser = workspace::robot_file, default_value_os_t = workspace::default_robot())]
    robot: PathBuf,
    /// Keep only tasks whose work surface clears the arm (all but the pen) at q0_seed by M
    /// metres: the population a real cell can pose (SPEC §9). Without it, the paper's
    /// population.
    #[arg(long, value_name = "M", value_parser = workspace::non_negative)]
    surface_clearance: Option<f64>,
}

/// What a task-set directory holds, written beside the sets as `tasks-v<version>.manifest.json`.
#[derive(Serialize)]
struct Manifest {
    format_version: u32,
    robot: String,
    sampler: SamplerConfig,
    rollout: RolloutConfig,
    gains: ClassicalGains,
    eval_file: String,
    eval_count: usize,
    train_file: String,
    train_count: usize,
    candidates_drawn: u64,
    split: &'static str,
}

/// Candidates drawn per requested task before the sampler gives up (the shipped robots'
/// populations accept about 1 in 1.1).
const MAX_CANDIDATES_PER_TASK: u64 = 1000;

/// Runs the sampler and writes both sets and their manifest.
pub fn run(args: &Args) -> anyhow::Result<()> {
    let robot = workspace::load_robot(&args.robot)?;
    let sampler_config = SamplerConfig {
        seed: args.seed,
        surface_clearance_m: args.surface_clearance,
        ..SamplerConfig::default()
    };
    let (rollout, gains) = (RolloutConfig::default(), ClassicalGains::default());
    let mut sampler = TaskSampler::new(&robot, &rollout, &gains, &sampler_config);
    std::fs::create_dir_all(&args.out_dir)
        .with_context(|| format!("creating {}", args.out_dir.display()))?;
    let version = TASK_FORMAT_VERSION;
    let mut files = Vec::new();
    for (name, count) in [("eval", args.eval_count), ("train", args.train_count)] {
        let bar = progress::bar(count as u64, name);
        let max_candidates = (count as u64).saturating_mul(MAX_CANDIDATES_PER_TASK);
        let tasks = sampler.take(count, max_candidates, &|accepted| {
            bar.set_position(accepted as u64)
        });
        bar.finish();
        anyhow::ensure!(
            tasks.len() == count,
            "{name} set: only {} of {count} tasks among {max_candidates} candidates; the \
             population of {} accepts fewer than 1 candidate in {MAX_CANDIDATES_PER_TASK}",
            tasks.len(),
            args.robot.display()
        );
        let file = args.out_dir.join(format!("{name}-v{version}.tasks"));
        write_task_set(&file, &tasks)?;
        println!("wrote {} tasks to {}", tasks.len(), file.display());
        files.push(file);
    }
    let candidates_drawn = sampler.candidates_drawn();
    let manifest = Manifest {
        format_version: version,
        robot: workspace::relative(&args.robot),
        sampler: sampler_config,
        rollout,
        gains,
        eval_file: workspace::relative(&files[0]),
        eval_count: args.eval_count,
        train_file: workspace::relative(&files[1]),
        train_count: args.train_count,
        candidates_drawn,
        split: "first eval_count accepted candidates, then the next train_count",
    };
    let manifest_path = args.out_dir.join(format!("tasks-v{version}.manifest.json"));
    emg_io::write_atomically(
        &manifest_path,
        serde_json::to_string_pretty(&manifest)? + "\n",
    )?;
    println!("wrote {}", manifest_path.display());
    Ok(())
}
