//! `cargo xtask eval --compare-velocity-limits`: DP seeds × every controller on the evaluation
//! set with the joint-velocity limits off (the paper's runs) and at the full, half and a quarter of
//! them (time scaling), and how path length and duration change
//! (`docs/results/velocity-limits.{json,md}`).

use std::path::Path;

use anyhow::Context;
use emg_control::{ConstraintConfig, Trajectory, VelocityLimitFraction};
use emg_eval::{Setup, Summary, four};
use emg_io::read_tasks;
use emg_planner::{ControllerKind, SeedSource};
use serde::{Deserialize, Serialize};

use crate::workspace;

/// `eval --velocity-limits`: whether rollouts honour the robot file's joint-velocity limits.
#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum VelocityLimits {
    /// Steps that would be too fast are slowed down in time (the default).
    On,
    /// Joint speeds are not bounded (the paper's setting).
    Off,
}

impl VelocityLimits {
    /// The constraint setting of this choice.
    pub fn apply(self, constraints: &mut ConstraintConfig) {
        constraints.velocity_limit_fraction = match self {
            Self::On => Some(VelocityLimitFraction::FULL),
            Self::Off => None,
        };
    }
}

/// Fractions of the velocity limits compared with the unlimited runs: the full limits, and a cell
/// run at half and a quarter of them.
const FRACTIONS: [f64; 3] = [1.0, 0.5, 0.25];

/// One controller's runs with the limits off and at each of [`FRACTIONS`].
#[derive(Serialize)]
struct Comparison {
    controller: ControllerKind,
    off: Timing,
    /// Tasks whose unlimited run exceeds some joint's velocity limit.
    tasks_over_the_limits_when_off: usize,
    limited: Vec<Limited>,
}

/// The runs at one fraction of the velocity limits, against the unlimited runs.
#[derive(Serialize)]
struct Limited {
    fraction: f64,
    timing: Timing,
    /// Tasks whose path length differs from the unlimited run's.
    tasks_with_other_path_length: usize,
    /// Tasks with at least one slowed step.
    tasks_slowed: usize,
    /// Slowed steps over all steps.
    slowed_step_fraction: f64,
    /// Duration limited / duration unlimited, per task with at least one step.
    duration_ratio: Summary,
}

/// Path length and duration of one set of runs.
#[derive(Serialize)]
struct Timing {
    path_length_m: Summary,
    duration_s: Summary,
    /// Largest joint speed as a fraction of that joint's full limit, per task with at least one
    /// step.
    peak_speed_ratio: Summary,
}

fn duration(trajectory: &Trajectory) -> f64 {
    trajectory.steps.last().map_or(0.0, |s| s.time_s)
}

/// Largest `|Δq_i| / Δt / v_max,i` over the steps of `trajectory` (0 for a seed alone).
fn peak_speed_ratio(trajectory: &Trajectory, limits: &[f64]) -> f64 {
    trajectory
        .steps
        .windows(2)
        .flat_map(|pair| {
            let elapsed = pair[1].time_s - pair[0].time_s;
            limits
                .iter()
                .enumerate()
                .map(move |(i, v)| (pair[1].q[i] - pair[0].q[i]).abs() / elapsed / v)
        })
        .fold(0.0, f64::max)
}

fn timing(trajectories: &[Trajectory], limits: &[f64]) -> anyhow::Result<Timing> {
    let moving: Vec<&Trajectory> = trajectories.iter().filter(|t| t.steps.len() > 1).collect();
    let summary = |values: Vec<f64>| Summary::of(&values).context("no task moved at all");
    Ok(Timing {
        path_length_m: summary(trajectories.iter().map(|t| t.path_length_m).collect())?,
        duration_s: summary(trajectories.iter().map(duration).collect())?,
        peak_speed_ratio: summary(moving.iter().map(|t| peak_speed_ratio(t, limits)).collect())?,
    })
}

/// Runs the comparison on the first `limit` tasks (all without a limit) and writes its files.
pub fn run(
    setup: &mut Setup,
    tasks_path: &Path,
    limit: Option<usize>,
    out_dir: &Path,
) -> anyhow::Result<()> {
    let mut tasks = read_tasks(tasks_path, &setup.robot)?;
    if let Some(limit) = limit {
        tasks.truncate(limit);
    }
    let limits: Vec<f64> = setup.robot.limits().velocity.iter().copied().collect();
    let (seeds, _) = setup.seeds(&tasks, &SeedSource::Dp)?;
    let executor = setup.executor.clone();
    let dt = setup.rollout.dt_s;
    let mut comparisons = Vec::new();
    for controller in ControllerKind::ALL {
        let mut run = |fraction: Option<f64>| -> anyhow::Result<Vec<Trajectory>> {
            setup.rollout.constraints.velocity_limit_fraction =
                fraction.map(VelocityLimitFraction::new).transpose()?;
            let what = match fraction {
                None => format!("DP+{} (no limits)", controller.name()),
                Some(f) => format!("DP+{} ({f} × limits)", controller.name()),
            };
            Ok(setup.rollouts(&tasks, &seeds, controller, &executor, &what)?)
        };
        let off = run(None)?;
        let mut limited = Vec::new();
        for fraction in FRACTIONS {
            let on = run(Some(fraction))?;
            let ratios: Vec<f64> = off
                .iter()
                .zip(&on)
                .filter(|(a, _)| duration(a) > 0.0)
                .map(|(a, b)| duration(b) / duration(a))
                .collect();
            let slowed = |t: &Trajectory| {
                t.steps
                    .windows(2)
                    .filter(|p| p[1].time_s - p[0].time_s > dt * (1.0 + 1e-9))
                    .count()
            };
            let steps: usize = on.iter().map(|t| t.steps.len() - 1).sum();
            let slowed_steps: usize = on.iter().map(slowed).sum();
            limited.push(Limited {
                fraction,
                timing: timing(&on, &limits)?,
                tasks_with_other_path_length: off
                    .iter()
                    .zip(&on)
                    .filter(|(a, b)| a.path_length_m != b.path_length_m)
                    .count(),
                tasks_slowed: on.iter().filter(|t| slowed(t) > 0).count(),
                slowed_step_fraction: slowed_steps as f64 / steps.max(1) as f64,
                duration_ratio: Summary::of(&ratios).context("no task moved at all")?,
            });
        }
        comparisons.push(Comparison {
            controller,
            tasks_over_the_limits_when_off: off
                .iter()
                .filter(|t| peak_speed_ratio(t, &limits) > 1.0 + 1e-9)
                .count(),
            off: timing(&off, &limits)?,
            limited,
        });
    }
    VelocityLimits::On.apply(&mut setup.rollout.constraints);

    let record = serde_json::json!({
        "robot": setup.robot.name(),
        "tasks": workspace::relative(tasks_path),
        "task_count": tasks.len(),
        "seed": "dp",
        "velocity_limits_rad_per_s": limits,
        "controllers": comparisons,
    });
    let md = markdown(setup, &comparisons, tasks.len(), tasks_path);
    workspace::write_results(out_dir, "velocity-limits", &record, &md)
}

fn markdown(setup: &Setup, rows: &[Comparison], count: usize, tasks_path: &Path) -> String {
    let mut md = format!(
        "# Joint-velocity limits: off vs on\n\nWritten by `cargo xtask eval --compare-velocity-limits`. \
         Do not edit by hand. Robot `{}`, {count} tasks of `{}`, DP seeds, every trajectory re-checked \
         by the independent checker (joint speeds included when the limits are on). With the limits on, \
         a step that would move some joint faster than the allowed fraction of the robot file's velocity \
         limit keeps its shape and lasts longer (time scaling), so the path is the same and only the \
         timing changes. Rows: no limits (the paper's setting), the full limits (the default), and a \
         cell run at half and at a quarter of them.\n\n\
         | controller | velocity limits | path length (m) | tasks with another length | duration (s) | duration / unlimited | tasks slowed | steps slowed | peak joint speed / full limit |\n\
         |---|---|---|---|---|---|---|---|---|\n",
        setup.robot.name(),
        workspace::relative(tasks_path),
    );
    for row in rows {
        let peak = |t: &Timing| {
            format!(
                "mean {:.3}, max {:.3}",
                t.peak_speed_ratio.mean, t.peak_speed_ratio.max
            )
        };
        md += &format!(
            "| {} | none | {:.4} | — | {:.3} | — | — | — | {} ({} tasks above 1) |\n",
            row.controller.title(),
            row.off.path_length_m.mean,
            row.off.duration_s.mean,
            peak(&row.off),
            row.tasks_over_the_limits_when_off,
        );
        for on in &row.limited {
            md += &format!(
                "| {} | {} × | {:.4} | {} | {:.3} | mean {:.4}, max {:.3} | {} | {:.2} % | {} |\n",
                row.controller.title(),
                on.fraction,
                on.timing.path_length_m.mean,
                on.tasks_with_other_path_length,
                on.timing.duration_s.mean,
                on.duration_ratio.mean,
                on.duration_ratio.max,
                on.tasks_slowed,
                100.0 * on.slowed_step_fraction,
                peak(&on.timing),
            );
        }
    }
    md += &format!(
        "\nPath length with the full limits (m, mean / std / min / max): {}.\n",
        rows.iter()
            .map(|r| format!(
                "{} {}",
                r.controller.title(),
                four(&r.limited[0].timing.path_length_m, 3)
            ))
            .collect::<Vec<_>>()
            .join("; ")
    );
    md
}
