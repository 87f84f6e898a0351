//! `cargo xtask eval`: a controller over the evaluation set, results in `docs/results/`.

use std::collections::BTreeMap;
use std::path::PathBuf;
use std::time::Instant;

use anyhow::{Context, bail};
use emg_control::{
    ClassicalController, ClassicalGains, ReferenceModel, RolloutConfig, Summary, Task,
    joint_limit_histogram, read_tasks, rollout_all, termination_histogram,
};
use serde::Serialize;

use crate::{progress, workspace};

/// Controllers `eval` can run.
#[derive(Clone, Copy, clap::ValueEnum, Serialize)]
#[serde(rename_all = "snake_case")]
enum ControllerChoice {
    /// The classical null-space controller (Eq. 3).
    Classical,
}

/// Options of `eval`.
#[derive(clap::Args)]
pub struct Args {
    /// Controller to evaluate.
    #[arg(long, value_enum)]
    controller: ControllerChoice,
    /// Task set.
    #[arg(long, default_value_os_t = workspace::root().join("data/tasks/eval-v1.tasks"))]
    tasks: PathBuf,
    /// Evaluate only the first N tasks.
    #[arg(long)]
    limit: Option<usize>,
    /// Override the lateral correction gain k_lat (1/s).
    #[arg(long)]
    lateral_gain: Option<f64>,
    /// Worker threads (0 = one per core); results do not depend on it.
    #[arg(long, default_value_t = 0)]
    threads: usize,
    /// Skip the independent re-check of every trajectory.
    #[arg(long)]
    no_check: bool,
    /// Name of the result files (default: the controller's name).
    #[arg(long)]
    name: Option<String>,
    /// Directory of the result files.
    #[arg(long, default_value_os_t = workspace::root().join("docs/results"))]
    out_dir: PathBuf,
    /// Robot file.
    #[arg(long, default_value_os_t = emg_kinematics::default_robot_path())]
    robot: PathBuf,
}

/// The numbers of one evaluation: identical for any thread count.
#[derive(Serialize)]
struct EvalResult {
    controller: ControllerChoice,
    tasks: String,
    task_count: usize,
    seed: &'static str,
    rollout: RolloutConfig,
    gains: ClassicalGains,
    path_length_m: Summary,
    steps: Summary,
    termination: BTreeMap<String, usize>,
    joint_limit_by_joint: BTreeMap<usize, usize>,
    independently_checked: usize,
}

/// Runs the evaluation and writes `<name>.json` and `<name>.md`.
pub fn run(args: &Args) -> anyhow::Result<()> {
    let robot = workspace::load_robot(&args.robot)?;
    let mut tasks = read_tasks(&args.tasks, &robot).with_context(|| {
        format!(
            "reading {} (create it with `cargo xtask make-tasks`)",
            args.tasks.display()
        )
    })?;
    if let Some(limit) = args.limit {
        tasks.truncate(limit);
    }
    if tasks.iter().any(|t| t.q0_seed.is_none()) {
        bail!("every evaluation task needs its q0_seed");
    }
    let mut rollout = RolloutConfig::default();
    if let Some(gain) = args.lateral_gain {
        rollout.lateral_gain_per_s = gain;
    }
    let gains = ClassicalGains::default();
    let pool = workspace::thread_pool(args.threads)?;
    let seed_of = |task: &Task| task.q0_seed.expect("checked above");

    let bar = progress::bar(tasks.len() as u64, "rollouts");
    let started = Instant::now();
    let trajectories = pool.install(|| {
        rollout_all(
            &robot,
            &tasks,
            seed_of,
            || ClassicalController::new(gains.clone()),
            &rollout,
            &|| bar.inc(1),
        )
    });
    let rollout_seconds = started.elapsed().as_secs_f64();
    bar.finish();

    let mut check_seconds = None;
    let mut checked = 0;
    if !args.no_check {
        let checker = ReferenceModel::from_urdf_file(&args.robot, "link0", "pen_tip")
            .map_err(anyhow::Error::msg)?;
        let bar = progress::bar(tasks.len() as u64, "checking");
        let started = Instant::now();
        let failures: Vec<String> = pool.install(|| {
            use rayon::prelude::*;
            tasks
                .par_iter()
                .zip(&trajectories)
                .enumerate()
                .filter_map(|(i, (task, trajectory))| {
                    bar.inc(1);
                    checker
                        .check(task, trajectory, &rollout.constraints)
                        .err()
                        .map(|e| format!("task {i}: {e}"))
                })
                .collect()
        });
        bar.finish();
        if !failures.is_empty() {
            bail!(
                "{} trajectories fail the independent check, first: {}",
                failures.len(),
                failures[0]
            );
        }
        checked = tasks.len();
        check_seconds = Some(started.elapsed().as_secs_f64());
    }

    let lengths: Vec<f64> = trajectories.iter().map(|t| t.path_length_m).collect();
    let steps: Vec<f64> = trajectories
        .iter()
        .map(|t| (t.steps.len() - 1) as f64)
        .collect();
    let result = EvalResult {
        controller: args.controller,
        tasks: workspace::relative(&args.tasks),
        task_count: tasks.len(),
        seed: "q0_seed",
        rollout,
        gains,
        path_length_m: Summary::of(&lengths).context("no tasks to evaluate")?,
        steps: Summary::of(&steps).context("no tasks to evaluate")?,
        termination: termination_histogram(&trajectories),
        joint_limit_by_joint: joint_limit_histogram(&trajectories),
        independently_checked: checked,
    };
    let name = args.name.clone().unwrap_or_else(|| "classical".into());
    std::fs::create_dir_all(&args.out_dir)?;
    let json_path = args.out_dir.join(format!("{name}.json"));
    std::fs::write(&json_path, serde_json::to_string_pretty(&result)? + "\n")?;
    let md_path = args.out_dir.join(format!("{name}.md"));
    std::fs::write(
        &md_path,
        markdown(
            &result,
            rollout_seconds,
            check_seconds,
            pool.current_num_threads(),
        ),
    )?;
    println!(
        "path length mean {:.3} m (std {:.3}, min {:.3}, max {:.3}) over {} tasks; rollouts {:.2} s wall",
        result.path_length_m.mean,
        result.path_length_m.std,
        result.path_length_m.min,
        result.path_length_m.max,
        result.task_count,
        rollout_seconds
    );
    println!("wrote {} and {}", json_path.display(), md_path.display());
    Ok(())
}

fn markdown(
    result: &EvalResult,
    rollout_seconds: f64,
    check_seconds: Option<f64>,
    threads: usize,
) -> String {
    let s = &result.path_length_m;
    let mut md = format!(
        "# Evaluation: {name} controller from q0_seed\n\n\
         Written by `cargo xtask eval --controller {name}` on {tasks} ({count} tasks, k_lat = {k_lat} 1/s). \
         Do not edit by hand.\n\n\
         | path length (m) | mean | std | min | max |\n|---|---|---|---|---|\n\
         | {count} tasks | {:.3} | {:.3} | {:.3} | {:.3} |\n\n\
         Steps per rollout: mean {:.1}, max {:.0}.\n\n## Termination\n\n| reason | tasks | share |\n|---|---|---|\n",
        s.mean,
        s.std,
        s.min,
        s.max,
        result.steps.mean,
        result.steps.max,
        name = "classical",
        tasks = result.tasks,
        count = result.task_count,
        k_lat = result.rollout.lateral_gain_per_s,
    );
    for (reason, n) in &result.termination {
        md += &format!(
            "| {reason} | {n} | {:.1} % |\n",
            100.0 * *n as f64 / result.task_count as f64
        );
    }
    md += "\n## Joint limits reached\n\n| joint | tasks |\n|---|---|\n";
    for (joint, n) in &result.joint_limit_by_joint {
        md += &format!("| {joint} | {n} |\n");
    }
    md += &format!(
        "\n## Run\n\nRollouts: {rollout_seconds:.2} s wall on {threads} threads ({}).\n",
        workspace::machine()
    );
    if let Some(check) = check_seconds {
        md += &format!(
            "Independent check: all {} trajectories pass, {check:.2} s wall.\n",
            result.independently_checked
        );
    }
    md
}
