//! Controller ablations (`cargo xtask ablate classical-weights | switching`): Tables 3 and 6, with
//! the ratio to the same per-task reference lengths as the protocol.

use std::path::PathBuf;
use std::time::Instant;

use anyhow::Context;
use emg_control::{ClassicalGains, Task, Trajectory};
use emg_eval::{CellStats, Setup, Summary, cell_stats, four};
use emg_hybrid::{BoundaryMeasure, SwitchConfig, count_switches};
use emg_io::read_tasks;
use emg_kinematics::JointVector;
use emg_planner::{ControllerKind, ExecutorConfig, SeedSource};
use emg_seeding::LabelSet;
use serde::{Deserialize, Serialize};

use crate::protocol;
use crate::workspace;

/// Options of the controller ablations.
#[derive(clap::Args)]
pub struct ControlArgs {
    /// Evaluation tasks.
    #[arg(long, default_value_os_t = workspace::data("tasks/eval-v1.tasks"))]
    tasks: PathBuf,
    /// Labels of the evaluation tasks (reference lengths).
    #[arg(long, default_value_os_t = workspace::data("labels/eval-v1.labels"))]
    labels: PathBuf,
    /// Use only the first N tasks.
    #[arg(long)]
    limit: Option<usize>,
    /// Worker threads (0 = one per core); results do not depend on it.
    #[arg(long, default_value_t = 0)]
    threads: usize,
    /// Policy weights.
    #[arg(long, default_value_os_t = protocol::default_policy())]
    policy: PathBuf,
    /// Diffusion weights.
    #[arg(long, default_value_os_t = protocol::default_diffusion())]
    diffusion: PathBuf,
    /// Directory of the result files.
    #[arg(long, default_value_os_t = workspace::results_dir())]
    out_dir: PathBuf,
    /// Robot file.
    #[arg(long, value_parser = workspace::robot_file, default_value_os_t = workspace::default_robot())]
    robot: PathBuf,
}

/// The gain grid of Table 3: every (k_μ, k_jl, k_θ) combination plus each objective alone.
#[derive(Clone, Debug, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct GainGrid {
    /// `k_μ` values.
    pub k_mu: Vec<f64>,
    /// `k_jl` values.
    pub k_jl: Vec<f64>,
    /// `k_θ` values.
    pub k_theta: Vec<f64>,
    /// Gain of the single-objective settings.
    pub single_gain: f64,
}

impl Default for GainGrid {
    fn default() -> Self {
        Self {
            k_mu: vec![0.2, 0.4, 0.6, 0.8],
            k_jl: vec![0.1, 0.2, 0.4],
            k_theta: vec![0.2, 0.4, 0.8],
            single_gain: 1.0,
        }
    }
}

impl GainGrid {
    /// The settings in table order: the three single objectives, then the grid.
    pub fn settings(&self) -> Vec<ClassicalGains> {
        let base = ClassicalGains::default();
        let single = |k_mu, k_jl, k_theta| ClassicalGains {
            k_mu,
            k_jl,
            k_theta,
            ..base.clone()
        };
        let g = self.single_gain;
        let mut settings = vec![
            single(g, 0.0, 0.0),
            single(0.0, g, 0.0),
            single(0.0, 0.0, g),
        ];
        for &k_mu in &self.k_mu {
            for &k_jl in &self.k_jl {
                for &k_theta in &self.k_theta {
                    settings.push(single(k_mu, k_jl, k_theta));
                }
            }
        }
        settings
    }
}

/// The switch settings of Table 6 (each under both boundary measures).
#[derive(Clone, Debug, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct SwitchGrid {
    /// Single thresholds `τ_enter = τ_exit`.
    pub single: Vec<f64>,
    /// Hysteresis pairs `(τ_enter, τ_exit)`.
    pub hysteresis: Vec<(f64, f64)>,
    /// Boundary measures compared.
    pub measures: Vec<BoundaryMeasure>,
}

impl Default for SwitchGrid {
    fn default() -> Self {
        Self {
            single: vec![0.85, 0.90, 0.95, 0.97, 0.98, 0.99],
            hysteresis: vec![(0.98, 0.94), (0.99, 0.93), (0.97, 0.93), (0.95, 0.90)],
            measures: vec![
                BoundaryMeasure::JointLimits,
                BoundaryMeasure::AllConstraints {
                    clearance_scale_m: 0.05,
                },
            ],
        }
    }
}

/// The result file of a controller ablation: its grid, the task count and one row per setting.
#[derive(Serialize, Deserialize)]
pub struct ControlAblation<G, S> {
    /// The settings swept.
    pub grid: G,
    /// Tasks per setting.
    pub task_count: usize,
    /// One row per setting, in table order.
    pub rows: Vec<Row<S>>,
}

/// One ablation row: a setting and its statistics.
#[derive(Serialize, Deserialize)]
pub struct Row<S> {
    /// The setting.
    pub setting: S,
    /// Path length and ratio to ℓ_ref.
    pub stats: CellStats,
    /// Mean hand-overs per episode (hybrid only).
    pub switches_per_episode: Option<f64>,
}

/// One switch setting of Table 6.
#[derive(Serialize, Deserialize)]
pub struct SwitchSetting {
    /// Boundary measure.
    pub measure: BoundaryMeasure,
    /// Entry threshold `τ_enter`.
    pub tau_enter: f64,
    /// Exit threshold `τ_exit`.
    pub tau_exit: f64,
}

/// `docs/results/ablate-classical-weights.json` (Table 3).
pub type WeightsAblation = ControlAblation<GainGrid, ClassicalGains>;

/// `docs/results/ablate-switching.json` (Table 6).
pub type SwitchingAblation = ControlAblation<SwitchGrid, SwitchSetting>;

/// The tasks of a controller ablation, each with its seed and its reference length.
struct Sweep {
    setup: Setup,
    tasks: Vec<Task>,
    seeds: Vec<JointVector>,
    /// The protocol's reference length ℓ_ref of each task.
    references: Vec<f64>,
}

impl Sweep {
    /// Loads the setup, the tasks, their seeds from `source` and their reference lengths.
    fn prepare(args: &ControlArgs, source: &SeedSource) -> anyhow::Result<Self> {
        let setup = protocol::load_setup(&args.robot, &args.policy, &args.diffusion)?;
        let mut tasks = read_tasks(&args.tasks, &setup.robot)?;
        if let Some(limit) = args.limit {
            tasks.truncate(limit);
        }
        let labels = LabelSet::read(&args.labels)
            .with_context(|| format!("reading {}", args.labels.display()))?;
        let indices: Vec<usize> = (0..tasks.len()).collect();
        let references = setup.references(&tasks, &indices, &labels)?;
        let (seeds, _) = setup.seeds(&tasks, source)?;
        Ok(Self {
            setup,
            tasks,
            seeds,
            references,
        })
    }

    /// Every task rolled out by `controller` under `executor` (`what` names the setting while
    /// it runs), with the statistics of the path lengths and of their ratios to ℓ_ref.
    fn roll_out(
        &self,
        controller: ControllerKind,
        executor: &ExecutorConfig,
        what: &str,
    ) -> anyhow::Result<(Vec<Trajectory>, CellStats)> {
        let trajectories =
            self.setup
                .rollouts(&self.tasks, &self.seeds, controller, executor, what)?;
        let lengths: Vec<f64> = trajectories.iter().map(|t| t.path_length_m).collect();
        let all: Vec<usize> = (0..self.tasks.len()).collect();
        let stats = cell_stats(&lengths, &self.references, &all).context("no tasks")?;
        Ok((trajectories, stats))
    }
}

/// Runs the controller ablation `name` on the worker threads of `args`: `table` sweeps the tasks
/// with seeds from `source` into the record and its page, written as `ablate-<name>.{json,md}`
/// with the wall time of the whole run.
fn ablate<R: Serialize>(
    args: &ControlArgs,
    name: &str,
    source: SeedSource,
    table: impl FnOnce(&Sweep) -> anyhow::Result<(R, String)> + Send,
) -> anyhow::Result<()> {
    let pool = workspace::thread_pool(args.threads)?;
    pool.install(|| {
        let started = Instant::now();
        let sweep = Sweep::prepare(args, &source)?;
        let (record, mut md) = table(&sweep)?;
        md += &format!(
            "\nRun: {:.1} s wall on {} threads ({}); every trajectory passed the independent checker.\n",
            started.elapsed().as_secs_f64(),
            rayon::current_num_threads(),
            workspace::machine()
        );
        workspace::write_results(&args.out_dir, &format!("ablate-{name}"), &record, &md)
    })
}

/// Table 3: the classical controller from q0_seed under every gain setting.
pub fn classical_weights(args: &ControlArgs) -> anyhow::Result<()> {
    ablate(args, "classical-weights", SeedSource::Generating, |sweep| {
        let grid = GainGrid::default();
        let mut rows = Vec::new();
        for gains in grid.settings() {
            let executor = ExecutorConfig {
                gains: gains.clone(),
                ..sweep.setup.executor.clone()
            };
            let what = format!("{}/{}/{}", gains.k_mu, gains.k_jl, gains.k_theta);
            let (_, stats) = sweep.roll_out(ControllerKind::Classical, &executor, &what)?;
            rows.push(Row {
                setting: gains,
                stats,
                switches_per_episode: None,
            });
        }
        let md = weights_markdown(&rows);
        Ok((
            WeightsAblation {
                grid,
                task_count: sweep.tasks.len(),
                rows,
            },
            md,
        ))
    })
}

/// The page of Table 3: one row per gain setting, the best ratio marked.
fn weights_markdown(rows: &[Row<ClassicalGains>]) -> String {
    let mut md = String::from(
        "# Ablation: classical secondary-objective weights (Table 3)\n\nWritten by `cargo xtask ablate classical-weights`. \
         Do not edit by hand. Classical controller from q0_seed; ratio to the protocol's reference length ℓ_ref. \
         The first three rows use one objective alone.\n\n\
         | k_μ | k_jl | k_θ | path length (m) mean / std / min / max | ratio to ℓ_ref (%) mean / std / min / max |\n|---|---|---|---|---|\n",
    );
    let best = rows
        .iter()
        .enumerate()
        .max_by(|a, b| {
            a.1.stats
                .ratio_percent
                .mean
                .total_cmp(&b.1.stats.ratio_percent.mean)
        })
        .map(|(i, _)| i);
    for (i, row) in rows.iter().enumerate() {
        let gain = |v: f64| {
            if v == 0.0 {
                "—".to_string()
            } else {
                format!("{v}")
            }
        };
        let mark = if Some(i) == best { " **(best)**" } else { "" };
        md += &format!(
            "| {} | {} | {} | {} | {}{mark} |\n",
            gain(row.setting.k_mu),
            gain(row.setting.k_jl),
            gain(row.setting.k_theta),
            four(&row.stats.length_m, 3),
            four(&row.stats.ratio_percent, 1)
        );
    }
    md
}

/// Table 6: the hybrid controller from DP seeds under every switch setting and boundary measure.
pub fn switching(args: &ControlArgs) -> anyhow::Result<()> {
    ablate(args, "switching", SeedSource::Dp, |sweep| {
        let grid = SwitchGrid::default();
        let thresholds: Vec<(f64, f64)> = grid
            .single
            .iter()
            .map(|&t| (t, t))
            .chain(grid.hysteresis.iter().copied())
            .collect();
        let mut rows = Vec::new();
        let mut md = String::from(
            "# Ablation: switching thresholds and boundary measure (Table 6)\n\nWritten by `cargo xtask ablate switching`. \
             Do not edit by hand. Hybrid controller from DP seeds; ratio to the protocol's reference length ℓ_ref. \
             `joint_limits` is the paper's rule (ρ only, the reference configuration); `all_constraints` also covers the \
             tool cone (θ/θ_max) and self-collision (1 − clearance/0.05 m).\n\n\
             | measure | (τ_enter, τ_exit) | switches / episode | path length (m) mean / std / min / max | ratio to ℓ_ref (%) mean / std / min / max |\n|---|---|---|---|---|---|\n",
        );
        for measure in &grid.measures {
            for &(tau_enter, tau_exit) in &thresholds {
                let executor = ExecutorConfig {
                    switch: SwitchConfig {
                        tau_enter,
                        tau_exit,
                    },
                    measure: measure.clone(),
                    ..sweep.setup.executor.clone()
                };
                let what = format!("{} {tau_enter}/{tau_exit}", measure.name());
                let (trajectories, stats) =
                    sweep.roll_out(ControllerKind::Hybrid, &executor, &what)?;
                let switches: Vec<f64> = trajectories
                    .iter()
                    .map(|t| count_switches(t) as f64)
                    .collect();
                let switches_per_episode = Summary::of(&switches).map(|s| s.mean);
                md += &format!(
                    "| {} | ({tau_enter:.2}, {tau_exit:.2}) | {:.2} | {} | {} |\n",
                    measure.name(),
                    switches_per_episode.unwrap_or(0.0),
                    four(&stats.length_m, 3),
                    four(&stats.ratio_percent, 1)
                );
                rows.push(Row {
                    setting: SwitchSetting {
                        measure: measure.clone(),
                        tau_enter,
                        tau_exit,
                    },
                    stats,
                    switches_per_episode,
                });
            }
        }
        Ok((
            SwitchingAblation {
                grid,
                task_count: sweep.tasks.len(),
                rows,
            },
            md,
        ))
    })
}
