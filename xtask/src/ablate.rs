//! `cargo xtask ablate <variant>`: ablations written to `docs/results/` (Tables 4 and 5).

use std::path::PathBuf;

use anyhow::{Context, bail};
use emg_control::{RolloutConfig, Task};
use emg_diffusion::{DenoiserWeights, DpSeedConfig, DpSeeder, SeedOrigin, SeedWorkspace};
use emg_eval::{Summary, rollout_all};
use emg_io::read_tasks;
use emg_kinematics::ProjectionConfig;
use emg_planner::{ControllerKind, Executor};
use emg_seeding::{HeuristicConfig, HeuristicObjective, LabelSet, heuristic_seed};
use rayon::prelude::*;
use serde::Serialize;

use crate::{progress, workspace};

/// The ablations.
#[derive(clap::Subcommand)]
pub enum Variant {
    /// Classifier-free guidance scale w ∈ {0, 1, 1.5, 2, 3} (Table 4).
    CfgScale(DpArgs),
    /// DDIM steps ∈ {10, 20, 50, 100} (Table 5).
    DdimSteps(DpArgs),
    /// Classical gains (k_μ, k_jl, k_θ): the 4 × 3 × 3 grid and each objective alone (Table 3).
    ClassicalWeights(crate::ablate_control::ControlArgs),
    /// Hybrid switch thresholds and boundary measures (Table 6).
    Switching(crate::ablate_control::ControlArgs),
}

/// Options shared by the DP-seed ablations.
#[derive(clap::Args)]
pub struct DpArgs {
    /// Diffusion weights.
    #[arg(long, default_value_os_t = workspace::data("models/diffusion-v1.weights"))]
    weights: PathBuf,
    /// Evaluation tasks (never seen in training).
    #[arg(long, default_value_os_t = workspace::data("tasks/eval-v1.tasks"))]
    tasks: PathBuf,
    /// Labels of the evaluation tasks: their starts give the reference lengths ℓ_ref (as in the
    /// protocol), when the file exists.
    #[arg(long, default_value_os_t = workspace::data("labels/eval-v1.labels"))]
    reference: PathBuf,
    /// Use only the first N tasks.
    #[arg(long)]
    limit: Option<usize>,
    /// Worker threads (0 = one per core); lengths do not depend on it, seed times do (timing
    /// is per task on one core, so keep 1 for the reported times).
    #[arg(long, default_value_t = 1)]
    threads: usize,
    /// Directory of the result files.
    #[arg(long, default_value_os_t = workspace::results_dir())]
    out_dir: PathBuf,
    /// Controller that rolls out from the seeds.
    #[arg(long, value_name = "classical|rl|hybrid", value_parser = <ControllerKind as std::str::FromStr>::from_str, default_value = "hybrid")]
    controller: ControllerKind,
    /// Policy weights of the learned controllers.
    #[arg(long, default_value_os_t = crate::protocol::default_policy())]
    policy: PathBuf,
    /// Robot file.
    #[arg(long, value_parser = workspace::robot_file, default_value_os_t = workspace::default_robot())]
    robot: PathBuf,
}

/// Runs an ablation.
pub fn run(variant: &Variant) -> anyhow::Result<()> {
    match variant {
        Variant::ClassicalWeights(args) => crate::ablate_control::classical_weights(args),
        Variant::Switching(args) => crate::ablate_control::switching(args),
        Variant::CfgScale(args) => dp_sweep(
            args,
            "cfg-scale",
            "w",
            &[0.0, 1.0, 1.5, 2.0, 3.0],
            |config, w| {
                config.sample.guidance_scale = w;
            },
        ),
        Variant::DdimSteps(args) => dp_sweep(
            args,
            "ddim-steps",
            "DDIM steps",
            &[10.0, 20.0, 50.0, 100.0],
            |config, steps| {
                config.sample.steps = steps as usize;
            },
        ),
    }
}

/// Seed time statistics (ms).
#[derive(Serialize)]
struct TimeStats {
    median_ms: f64,
    p95_ms: f64,
    mean_ms: f64,
}

/// One ablation row.
#[derive(Serialize)]
struct Row {
    value: f64,
    dp: DpSeedConfig,
    seed_time: TimeStats,
    tries_mean: f64,
    fallbacks: usize,
    path_length_m: Summary,
    ratio_to_reference_pct: Option<Summary>,
}

#[derive(Serialize)]
struct Baseline {
    seed: &'static str,
    path_length_m: Summary,
    ratio_to_reference_pct: Option<Summary>,
}

#[derive(Serialize)]
struct Report<'a> {
    ablation: &'a str,
    parameter: &'a str,
    tasks: String,
    task_count: usize,
    weights: String,
    weights_dataset: String,
    reference: Option<String>,
    controller: &'static str,
    rollout: RolloutConfig,
    baselines: Vec<Baseline>,
    rows: Vec<Row>,
}

/// Sweeps the DP seeder's `parameter` over `values` (`apply` sets it on a configuration) on
/// the ablation's tasks, beside the three baseline seeds, and writes `ablate-{name}`.
fn dp_sweep(
    args: &DpArgs,
    name: &str,
    parameter: &str,
    values: &[f64],
    apply: impl Fn(&mut DpSeedConfig, f64),
) -> anyhow::Result<()> {
    let setup = crate::protocol::load_setup(&args.robot, &args.policy, &args.weights)?;
    let tasks = ablation_tasks(args, &setup.robot)?;
    let weights = DenoiserWeights::read(&args.weights).with_context(|| {
        format!(
            "reading {} (train it with `cargo xtask train-diffusion`)",
            args.weights.display()
        )
    })?;
    let pool = workspace::thread_pool(args.threads)?;
    let reference = match args.reference.exists() {
        true => {
            let labels = LabelSet::read(&args.reference)
                .with_context(|| format!("reading {}", args.reference.display()))?;
            let indices: Vec<usize> = (0..tasks.len()).collect();
            Some(pool.install(|| setup.references(&tasks, &indices, &labels))?)
        }
        false => None,
    };
    let sweep = Sweep {
        prototype: Executor::new(args.controller, Some(&setup.policy), &setup.executor)?,
        setup: &setup,
        tasks: &tasks,
        pool: &pool,
        reference,
    };
    let baselines = sweep.baselines()?;
    let rows = values
        .iter()
        .map(|&value| {
            let mut dp = DpSeedConfig::default();
            apply(&mut dp, value);
            sweep.row(value, dp, &weights)
        })
        .collect::<anyhow::Result<Vec<Row>>>()?;
    let report = Report {
        ablation: name,
        parameter,
        tasks: workspace::relative(&args.tasks),
        task_count: tasks.len(),
        weights: workspace::relative(&args.weights),
        weights_dataset: weights.header().dataset.clone(),
        reference: sweep
            .reference
            .as_ref()
            .map(|_| workspace::relative(&args.reference)),
        controller: args.controller.name(),
        rollout: setup.rollout.clone(),
        baselines,
        rows,
    };
    std::fs::create_dir_all(&args.out_dir)?;
    let stem = args.out_dir.join(format!("ablate-{name}"));
    emg_io::write_atomically(
        stem.with_extension("json"),
        serde_json::to_string_pretty(&report)? + "\n",
    )?;
    emg_io::write_atomically(stem.with_extension("md"), markdown(&report))?;
    println!("{}", markdown(&report));
    Ok(())
}

/// The ablation's tasks (the first `--limit`), each with its `q0_seed`.
fn ablation_tasks(args: &DpArgs, robot: &emg_kinematics::Robot) -> anyhow::Result<Vec<Task>> {
    let mut tasks = read_tasks(&args.tasks, robot)
        .with_context(|| format!("reading {}", args.tasks.display()))?;
    if let Some(limit) = args.limit {
        tasks.truncate(limit);
    }
    if tasks.is_empty() || tasks.iter().any(|t| t.q0_seed.is_none()) {
        bail!(
            "{}: the ablation needs at least one task, each with its q0_seed",
            args.tasks.display()
        );
    }
    Ok(tasks)
}

/// One DP-seed sweep: the tasks, the controller they are rolled out with and the reference
/// lengths they are measured against.
struct Sweep<'a> {
    setup: &'a emg_eval::Setup,
    tasks: &'a [Task],
    pool: &'a rayon::ThreadPool,
    prototype: Executor,
    /// Per-task reference lengths, where the reference labels exist.
    reference: Option<Vec<f64>>,
}

impl Sweep<'_> {
    /// The path lengths `tasks` (seeded) roll out to, each trajectory checked; `what` names
    /// the progress bar.
    fn lengths(&self, tasks: &[Task], what: &str) -> anyhow::Result<Vec<f64>> {
        let bar = progress::bar(tasks.len() as u64, what);
        let trajectories = self.pool.install(|| {
            rollout_all(
                &self.setup.robot,
                tasks,
                |t| t.q0_seed.expect("seeded"),
                || self.prototype.clone(),
                &self.setup.rollout,
                &|| bar.inc(1),
            )
        });
        bar.finish();
        self.pool
            .install(|| self.setup.check(tasks, &trajectories))?;
        Ok(trajectories.iter().map(|t| t.path_length_m).collect())
    }

    /// The tasks' own seeds and the two heuristic seeds, measured.
    fn baselines(&self) -> anyhow::Result<Vec<Baseline>> {
        let mut baselines = Vec::new();
        for (seed, objective) in [
            ("q0_seed", None),
            ("q_mu", Some(HeuristicObjective::Manipulability)),
            ("q_jl", Some(HeuristicObjective::JointCentring)),
        ] {
            let seeded = match objective {
                None => self.tasks.to_vec(),
                Some(objective) => self.heuristic_seeded(objective, seed),
            };
            let lengths = self.lengths(&seeded, seed)?;
            baselines.push(Baseline {
                seed,
                path_length_m: summary(&lengths),
                ratio_to_reference_pct: self.reference.as_ref().map(|r| ratio(&lengths, r)),
            });
        }
        Ok(baselines)
    }

    /// The tasks seeded by the heuristic `objective` (each keeping its own seed where the
    /// heuristic finds none); `what` names the progress bar.
    fn heuristic_seeded(&self, objective: HeuristicObjective, what: &str) -> Vec<Task> {
        let robot = &self.setup.robot;
        let bar = progress::bar(self.tasks.len() as u64, what);
        let seeded = self.pool.install(|| {
            self.tasks
                .par_iter()
                .map(|task| {
                    bar.inc(1);
                    let q = heuristic_seed(
                        robot,
                        task,
                        objective,
                        &HeuristicConfig::default(),
                        &ProjectionConfig::default(),
                    )
                    .map_or(task.q0_seed, |h| Some(h.q));
                    Task {
                        q0_seed: q,
                        ..task.clone()
                    }
                })
                .collect()
        });
        bar.finish();
        seeded
    }

    /// The row of the parameter's `value`: the tasks seeded by the DP seeder configured as
    /// `dp` (with `weights`), its seed times, tries and fallbacks, and the lengths rolled out.
    fn row(&self, value: f64, dp: DpSeedConfig, weights: &DenoiserWeights) -> anyhow::Result<Row> {
        let robot = &self.setup.robot;
        let seeder = DpSeeder::new(robot, weights, dp.clone())?;
        let bar = progress::bar(self.tasks.len() as u64, "dp seeds");
        let constraints = &self.setup.rollout.constraints;
        let seeds = self.pool.install(|| {
            self.tasks
                .par_iter()
                .map_init(SeedWorkspace::default, |workspace, task| {
                    bar.inc(1);
                    seeder.seed(robot, task, constraints, workspace)
                })
                .collect::<Result<Vec<_>, _>>()
        })?;
        bar.finish();
        let seeded: Vec<Task> = self
            .tasks
            .iter()
            .zip(&seeds)
            .map(|(task, seed)| Task {
                q0_seed: Some(seed.q),
                ..task.clone()
            })
            .collect();
        let lengths = self.lengths(&seeded, "dp rollouts")?;
        let mut times: Vec<f64> = seeds
            .iter()
            .map(|s| s.elapsed.as_secs_f64() * 1e3)
            .collect();
        times.sort_by(f64::total_cmp);
        let quantile = |q: f64| times[((times.len() - 1) as f64 * q).round() as usize];
        Ok(Row {
            value,
            dp,
            seed_time: TimeStats {
                median_ms: quantile(0.5),
                p95_ms: quantile(0.95),
                mean_ms: times.iter().sum::<f64>() / times.len() as f64,
            },
            tries_mean: seeds.iter().map(|s| s.tries as f64).sum::<f64>() / seeds.len() as f64,
            fallbacks: seeds
                .iter()
                .filter(|s| s.origin == SeedOrigin::Fallback)
                .count(),
            path_length_m: summary(&lengths),
            ratio_to_reference_pct: self.reference.as_ref().map(|r| ratio(&lengths, r)),
        })
    }
}

/// Per-task ratio `L / ℓ_ref` in percent, over the tasks with a positive reference.
fn ratio(lengths: &[f64], reference: &[f64]) -> Summary {
    let ratios: Vec<f64> = lengths
        .iter()
        .zip(reference)
        .filter(|(_, r)| **r > 0.0)
        .map(|(l, r)| 100.0 * l / r)
        .collect();
    summary(&ratios)
}

/// The summary of a non-empty sample (the task list is checked non-empty up front).
fn summary(values: &[f64]) -> Summary {
    Summary::of(values).expect("at least one task")
}

fn summary_cell(s: &Summary, digits: usize) -> String {
    format!(
        "{:.d$} / {:.d$} / {:.d$} / {:.d$}",
        s.mean,
        s.std,
        s.min,
        s.max,
        d = digits
    )
}

fn markdown(report: &Report) -> String {
    let ratio_header = if report.reference.is_some() {
        " Ratio to reference (%) mean / std / min / max |"
    } else {
        ""
    };
    let ratio_rule = if report.reference.is_some() {
        "---|"
    } else {
        ""
    };
    let ratio_cell = |r: &Option<Summary>| {
        r.as_ref()
            .map_or(String::new(), |s| format!(" {} |", summary_cell(s, 1)))
    };
    let mut text = format!(
        "# Ablation: {}\n\nWritten by `cargo xtask ablate {}`. The {} controller from the DP seed over {} \
         evaluation tasks (every trajectory passed the independent checker) ({}, unseen in training); weights {} trained on {}. Seed time per task on one core \
         (median / p95 / mean; the machine was shared with other jobs); tries = candidates projected; fallbacks = tasks that fell back to q0_seed.\n\n\
         | {} | seed time (ms) median / p95 / mean | tries | fallbacks | Path length (m) mean / std / min / max |{}\n\
         |---|---|---|---|---|{}\n",
        report.parameter,
        report.ablation,
        report.controller,
        report.task_count,
        report.tasks,
        report.weights,
        report.weights_dataset,
        report.parameter,
        ratio_header,
        ratio_rule
    );
    for row in &report.rows {
        text += &format!(
            "| {} | {:.3} / {:.3} / {:.3} | {:.2} | {} | {} |{}\n",
            row.value,
            row.seed_time.median_ms,
            row.seed_time.p95_ms,
            row.seed_time.mean_ms,
            row.tries_mean,
            row.fallbacks,
            summary_cell(&row.path_length_m, 3),
            ratio_cell(&row.ratio_to_reference_pct)
        );
    }
    for baseline in &report.baselines {
        text += &format!(
            "| {} (baseline seed) | — | — | — | {} |{}\n",
            baseline.seed,
            summary_cell(&baseline.path_length_m, 3),
            ratio_cell(&baseline.ratio_to_reference_pct)
        );
    }
    text += "\nRatios are per task against the protocol's reference length ℓ_ref (the longest hybrid rollout over the task's labelled starts, as in Tables 1–2).\n";
    text
}
