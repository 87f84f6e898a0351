//! `cargo xtask cartesian-eval`: the baseline today's tools offer, a MoveIt-style Cartesian
//! path (`emg_planner::cartesian_path`), on the evaluation tasks of `search-eval`, from the
//! paper's pipeline's seed, beside the same tasks' reachability bounds, the pipeline and the
//! default search (read from `search.json`), per bucket of the bound.

use std::time::Instant;

use anyhow::Context;
use emg_eval::{BoundShare, bound_shares};
use emg_planner::{CartesianConfig, cartesian_path, prepare_seed};
use serde::{Deserialize, Serialize};

use crate::search_eval;
use crate::task_set_options::TaskSetOptions;
use crate::{progress, workspace};

/// Where `--threads` stands among the options of `cartesian-eval`: after the other three of
/// [`TaskSetOptions`].
const LAST_SLOT: usize = 4;

/// Options of `cargo xtask cartesian-eval`.
#[derive(clap::Args)]
#[command(
    mut_arg("task_file", |arg| arg.help("Task set: the one `search-eval` planned (its bounds are read from search.json)")),
    mut_arg("out_dir", |arg| arg.help("Directory holding search.json and receiving cartesian.{json,md}")),
    mut_arg("threads", |arg| arg
        .help("Worker threads (0 = one per core); the lengths do not depend on it")
        .display_order(LAST_SLOT)),
)]
pub struct Args {
    /// Worker threads, task set, robot file and output directory.
    #[command(flatten)]
    common: TaskSetOptions,
}

/// The Cartesian paths of the evaluation tasks.
#[derive(Serialize, Deserialize)]
pub struct Record {
    /// Robot name.
    pub robot: String,
    /// Task file, relative to the workspace.
    pub tasks: String,
    /// Tasks planned.
    pub task_count: usize,
    /// Machine the times were measured on.
    pub machine: String,
    /// The Cartesian path's settings.
    pub cartesian: CartesianConfig,
    /// Mean path length (m).
    pub mean_length_m: f64,
    /// Mean path length of the paper's pipeline and of the default search on the same tasks
    /// (m), from search.json.
    pub pipeline_mean_length_m: f64,
    /// The same for the search at `emg plan`'s default budget.
    pub search_mean_length_m: f64,
    /// `Σ length / Σ bound` per bucket of the bound, then over all tasks.
    pub bound_shares: Vec<BoundShare>,
    /// How many paths ended for each reason (`unreachable`, `violation`, `jump`,
    /// `max_length`).
    pub ended: Vec<(String, usize)>,
    /// Mean time of one path on its thread, seed included (ms).
    pub mean_ms: f64,
    /// Each task's path length (m), in task order.
    pub lengths_m: Vec<f64>,
}

/// Plans every task's Cartesian path and writes the record and its table.
pub fn run(args: &Args) -> anyhow::Result<()> {
    let search_path = args.common.out_dir.join("search.json");
    let search: search_eval::Record =
        serde_json::from_str(&std::fs::read_to_string(&search_path).with_context(|| {
            format!(
                "reading {} (run `cargo xtask search-eval` first)",
                search_path.display()
            )
        })?)?;
    let workspace::PlannerSetup { planner, tasks, .. } = args
        .common
        .planner_setup(search.task_count, "cartesian-eval")?;
    anyhow::ensure!(
        search.bounds_m.len() == tasks.len(),
        "{} holds {} bounds for {} tasks",
        search_path.display(),
        search.bounds_m.len(),
        tasks.len()
    );
    let pool = workspace::thread_pool(args.common.threads)?;
    let config = CartesianConfig::default();
    let constraints = &planner.config().rollout.constraints;
    let bar = progress::bar(tasks.len() as u64, "Cartesian paths");
    let paths: Vec<_> = pool.install(|| {
        use rayon::prelude::*;
        tasks
            .par_iter()
            .map(|task| {
                let started = Instant::now();
                let seed = prepare_seed(
                    planner.robot(),
                    task,
                    None,
                    constraints,
                    planner.models().seeder.as_ref(),
                );
                let path = seed.map(|seed| {
                    cartesian_path(planner.robot(), task, constraints, &seed.q, &config)
                });
                bar.inc(1);
                (path, started.elapsed().as_secs_f64() * 1e3)
            })
            .collect()
    });
    bar.finish();
    let mut lengths = Vec::with_capacity(tasks.len());
    let mut ended: Vec<(String, usize)> = Vec::new();
    let mut total_ms = 0.0;
    for (index, (path, ms)) in paths.into_iter().enumerate() {
        let path = path.with_context(|| format!("seeding task {index}"))?;
        lengths.push(path.length_m);
        total_ms += ms;
        match ended.iter_mut().find(|(name, _)| name == path.ended.name()) {
            Some((_, count)) => *count += 1,
            None => ended.push((path.ended.name().to_string(), 1)),
        }
    }
    ended.sort();
    // A Cartesian path witnesses its length as any plan does.
    let bounds: Vec<f64> = search
        .bounds_m
        .iter()
        .zip(&lengths)
        .map(|(bound, length)| bound.max(*length))
        .collect();
    let row_mean = |budget: Option<u64>| {
        search
            .rows
            .iter()
            .find(|row| row.budget_steps == budget)
            .map_or(f64::NAN, |row| row.path_length_m.mean)
    };
    let record = Record {
        robot: planner.robot().name().to_string(),
        tasks: workspace::relative(&args.common.task_file),
        task_count: tasks.len(),
        machine: workspace::machine(),
        cartesian: config,
        mean_length_m: lengths.iter().sum::<f64>() / lengths.len().max(1) as f64,
        pipeline_mean_length_m: row_mean(None),
        search_mean_length_m: search
            .default_budget_row()
            .map_or(f64::NAN, |row| row.path_length_m.mean),
        bound_shares: bound_shares(&lengths, &bounds, &bounds),
        ended,
        mean_ms: total_ms / tasks.len().max(1) as f64,
        lengths_m: lengths,
    };
    workspace::write_results(
        &args.common.out_dir,
        "cartesian",
        &record,
        &markdown(&record),
    )
}

/// The record as a page.
fn markdown(record: &Record) -> String {
    let mut md = format!(
        "# A MoveIt-style Cartesian path on the evaluation tasks\n\nWritten by `cargo xtask \
         cartesian-eval`. Do not edit.\n\nThe baseline a motion-planning framework offers for a \
         straight line (`computeCartesianPath`): the tool's whole pose held fixed (its axis on \
         `n`, its roll as the start left it), a waypoint every {:.0} mm along the line, each \
         solved by inverse kinematics from the previous one, ending at the first waypoint \
         inverse kinematics cannot reach, that breaks a constraint, or whose joints jump more \
         than {} rad. It starts from the paper's pipeline's seed. {} tasks of {} ({}), robot \
         {}; bounds from `search.json`.\n\n",
        record.cartesian.eef_step_m * 1e3,
        record.cartesian.jump_threshold_rad,
        record.task_count,
        record.tasks,
        record.machine,
        record.robot
    );
    md += &format!(
        "Mean length: Cartesian path {:.4} m, the paper's pipeline {:.4} m, the search at the \
         default budget {:.4} m.\n\n| bucket of the bound | tasks | Σ length / Σ bound | below ½ \
         bound |\n|---|---|---|---|\n",
        record.mean_length_m, record.pipeline_mean_length_m, record.search_mean_length_m
    );
    for share in &record.bound_shares {
        md += &format!(
            "| {} | {} | {:.3} | {} |\n",
            share.bucket,
            share.tasks,
            share.share,
            share.below_half.len()
        );
    }
    md += "\n| the path ended | tasks |\n|---|---|\n";
    for (name, count) in &record.ended {
        md += &format!("| {name} | {count} |\n");
    }
    md += &format!(
        "\nMean time per path on its thread, seed included: {:.2} ms.\n",
        record.mean_ms
    );
    md
}
