//! `cargo xtask search-eval`: the search planner against the paper's pipeline (Hybrid + DP) on
//! the first tasks of the evaluation set, at several step budgets, beside each task's
//! reachability bound (`docs/results/search.{json,md}`, `docs/figures/search-budget.svg`).

use std::path::{Path, PathBuf};
use std::time::Instant;

use anyhow::Context;
use emg_control::CheckRollout;
use emg_eval::{Summary, four};
use emg_planner::{PlanRequest, PlannerConfig, PlannerKind, SearchConfig};
use indicatif::ProgressIterator;
use plotters::prelude::*;
use serde::{Deserialize, Serialize};

use crate::{progress, workspace};

/// File name of the mean length against budget figure in a robot's figure directory.
pub const BUDGET_FIGURE: &str = "search-budget.svg";

/// Options of `search-eval`.
#[derive(clap::Args)]
pub struct Args {
    /// Tasks: the first this many of the task set (the report's Search rows need the whole
    /// evaluation set).
    #[arg(long, default_value_t = 10_000)]
    tasks: usize,
    /// Step budgets of the search, comma-separated.
    #[arg(long, value_delimiter = ',', default_values_t = [1_000u64, 5_000, 10_000, 20_000, 50_000])]
    budgets: Vec<u64>,
    /// Worker threads (0 = one per core); the results do not depend on it.
    #[arg(long, default_value_t = 0)]
    threads: usize,
    /// JSON file of search settings (`emg_planner::SearchConfig`; unset fields keep their
    /// defaults, `budget_steps` is replaced by each of `--budgets`).
    #[arg(long, value_name = "JSON")]
    search_config: Option<PathBuf>,
    /// Task set.
    #[arg(long, default_value_os_t = workspace::data("tasks/eval-v1.tasks"))]
    task_file: PathBuf,
    /// Robot file.
    #[arg(long, value_parser = workspace::robot_file, default_value_os_t = workspace::default_robot())]
    robot: PathBuf,
    /// Output directory of search.{json,md}.
    #[arg(long, default_value_os_t = workspace::results_dir())]
    out_dir: PathBuf,
    /// Output figure.
    #[arg(long, default_value_os_t = workspace::figure(BUDGET_FIGURE))]
    figure: PathBuf,
}

/// One planner setting over the tasks.
#[derive(Serialize, Deserialize)]
pub struct Row {
    /// `pipeline` or `search`.
    pub planner: String,
    /// The search's step budget (none for the pipeline).
    pub budget_steps: Option<u64>,
    /// Path length statistics over the tasks.
    pub path_length_m: Summary,
    /// Mean length / the pipeline's mean length.
    pub ratio_to_pipeline: f64,
    /// Mean over tasks of length / reachability bound (tasks with a bound above 0).
    pub share_of_bound: f64,
    /// Steps actually taken by the returned plans, mean.
    pub plan_steps: f64,
    /// Wall time × threads per task on this machine (ms): the CPU time a task takes.
    pub cpu_ms_per_task: f64,
    /// Plans the independent checker rejected.
    pub checker_failures: usize,
    /// Path length of every task (m), in task order (the report's Search rows per bucket).
    pub lengths_m: Vec<f64>,
}

/// The whole record written to `search.json`.
#[derive(Serialize, Deserialize)]
pub struct Record {
    /// Robot name.
    pub robot: String,
    /// Task file, relative to the workspace.
    pub tasks: String,
    /// Tasks planned: the first this many of the file.
    pub task_count: usize,
    /// Machine the times were measured on.
    pub machine: String,
    /// Worker threads.
    pub threads: usize,
    /// Search settings (`budget_steps` per row).
    pub search: SearchConfig,
    /// Reachability bounds of the tasks.
    pub reachability_bound_m: Summary,
    /// The pipeline, then the search at each budget.
    pub rows: Vec<Row>,
}

impl Record {
    /// The search row at the default budget of `emg plan`, if it was run.
    pub fn default_budget_row(&self) -> Option<&Row> {
        let budget = PlannerConfig::default().search.budget_steps;
        self.rows.iter().find(|r| r.budget_steps == Some(budget))
    }
}

/// Runs the comparison and writes the record, its table and its figure.
pub fn run(args: &Args) -> anyhow::Result<()> {
    let workspace::PlannerSetup {
        planner,
        checker,
        tasks,
    } = workspace::planner_setup(&args.robot, &args.task_file, args.tasks, "search-eval")?;
    let pool = workspace::thread_pool(args.threads)?;
    let threads = pool.current_num_threads();
    let search: SearchConfig =
        workspace::read_config(args.search_config.as_deref(), "search config")?;

    println!("reachability bound of {} tasks", tasks.len());
    let bar = progress::bar(tasks.len() as u64, "reach");
    let bounds: Vec<f64> = pool.install(|| {
        use rayon::prelude::*;
        tasks
            .par_iter()
            .map(|task| {
                let reach = planner.reach(task, &[]);
                bar.inc(1);
                reach.reachable_m
            })
            .collect()
    });
    bar.finish();

    let mut rows = Vec::new();
    let mut pipeline_mean: Option<f64> = None;
    let settings = std::iter::once(None).chain(args.budgets.iter().copied().map(Some));
    for budget in settings.progress_with(progress::bar(1 + args.budgets.len() as u64, "budgets")) {
        let mut config = PlannerConfig {
            search: search.clone(),
            ..PlannerConfig::default()
        };
        let request = match budget {
            None => PlanRequest::default(),
            Some(steps) => {
                config.search.budget_steps = steps;
                PlanRequest {
                    planner: PlannerKind::Search,
                    ..PlanRequest::default()
                }
            }
        };
        let planner = planner.with_config(config)?;
        let started = Instant::now();
        let plans = pool.install(|| planner.plan_many(&tasks, &request));
        let cpu_ms = started.elapsed().as_secs_f64() * 1e3 * threads as f64;
        let mut lengths = Vec::with_capacity(tasks.len());
        let mut steps = 0usize;
        let mut failures = 0;
        for (task, plan) in tasks.iter().zip(plans) {
            let plan = plan.with_context(|| format!("planning {task:?}"))?;
            if checker
                .check(
                    task,
                    &plan.trajectory,
                    &planner.config().rollout.constraints,
                )
                .is_err()
            {
                failures += 1;
            }
            steps += plan.trajectory.steps.len() - 1;
            lengths.push(plan.trajectory.path_length_m);
        }
        let summary = Summary::of(&lengths).context("no tasks")?;
        let pipeline_mean = *pipeline_mean.get_or_insert(summary.mean);
        rows.push(Row {
            planner: if budget.is_some() {
                "search"
            } else {
                "pipeline"
            }
            .to_string(),
            budget_steps: budget,
            ratio_to_pipeline: summary.mean / pipeline_mean,
            path_length_m: summary,
            share_of_bound: mean_ratio(&lengths, &bounds),
            plan_steps: steps as f64 / tasks.len() as f64,
            cpu_ms_per_task: cpu_ms / tasks.len() as f64,
            checker_failures: failures,
            lengths_m: lengths,
        });
    }

    let record = Record {
        robot: planner.robot().name().to_string(),
        tasks: workspace::relative(&args.task_file),
        task_count: tasks.len(),
        machine: workspace::machine(),
        threads,
        search,
        reachability_bound_m: Summary::of(&bounds).context("no tasks")?,
        rows,
    };
    workspace::write_results(&args.out_dir, "search", &record, &markdown(&record))?;
    draw(&record, &args.figure)?;
    println!("wrote {}", args.figure.display());
    Ok(())
}

/// Mean of `values[i] / of[i]` over the tasks where `of[i]` is positive.
fn mean_ratio(values: &[f64], of: &[f64]) -> f64 {
    let ratios: Vec<f64> = values
        .iter()
        .zip(of)
        .filter(|(_, o)| **o > 1e-9)
        .map(|(v, o)| v / o)
        .collect();
    ratios.iter().sum::<f64>() / ratios.len().max(1) as f64
}

fn markdown(record: &Record) -> String {
    let mut md = format!(
        "# Search planner vs the paper's pipeline\n\nWritten by `cargo xtask search-eval`. Do not \
         edit by hand. Robot `{}`, the first {} tasks of `{}`. The pipeline is Hybrid + DP (one \
         seed, one rollout); the search rolls that plan out first, then ranks candidate starts \
         (q0_seed, q_mu, q_jl, {} diffusion samples, cone IK from {} restarts) by classical \
         rollouts, re-rolls the best {} with the hybrid controller, then repairs the longest \
         rollouts of the best {} starts where they failed (each null-space basis direction held \
         for {} steps from 1 to 32 steps before the end, then the hybrid or the classical \
         controller), until its budget of control steps is spent. Every plan is re-checked by the independent checker. Reachability bound \
         (m, mean / std / min / max): {}. Times are CPU time per task on {} ({} threads) and \
         depend on the machine; the lengths do not.\n\n\
         | planner | budget (steps) | path length (m, mean / std / min / max) | mean / pipeline \
         mean | length / bound (task mean) | steps per plan | CPU ms per task | checker failures |\n\
         |---|---|---|---|---|---|---|---|\n",
        record.robot,
        record.task_count,
        record.tasks,
        record.search.dp_samples,
        record.search.ik_restarts,
        record.search.finalists,
        record.search.repaired_starts,
        record.search.detour_steps,
        four(&record.reachability_bound_m, 3),
        record.machine,
        record.threads,
    );
    for row in &record.rows {
        md += &format!(
            "| {} | {} | {} | {:.3} | {:.3} | {:.1} | {:.1} | {} |\n",
            row.planner,
            row.budget_steps.map_or("—".into(), |b| b.to_string()),
            four(&row.path_length_m, 4),
            row.ratio_to_pipeline,
            row.share_of_bound,
            row.plan_steps,
            row.cpu_ms_per_task,
            row.checker_failures,
        );
    }
    md
}

/// Mean path length against the search budget, with the pipeline and the mean bound as lines.
fn draw(record: &Record, path: &Path) -> anyhow::Result<()> {
    if let Some(dir) = path.parent() {
        std::fs::create_dir_all(dir)?;
    }
    let searched: Vec<(f64, f64)> = record
        .rows
        .iter()
        .filter_map(|r| r.budget_steps.map(|b| (b as f64, r.path_length_m.mean)))
        .collect();
    let pipeline = record
        .rows
        .iter()
        .find(|r| r.budget_steps.is_none())
        .map_or(0.0, |r| r.path_length_m.mean);
    let bound = record.reachability_bound_m.mean;
    let (x_min, x_max) = searched
        .iter()
        .fold((f64::INFINITY, 0.0f64), |(lo, hi), (x, _)| {
            (lo.min(*x), hi.max(*x))
        });
    let y_max = bound.max(pipeline) * 1.1;
    let root = SVGBackend::new(path, (720, 420)).into_drawing_area();
    root.fill(&WHITE)?;
    let mut chart = ChartBuilder::on(&root)
        .caption(
            format!(
                "{}: mean path length against the search budget",
                record.robot
            ),
            ("sans-serif", 18),
        )
        .margin(12)
        .x_label_area_size(40)
        .y_label_area_size(56)
        .build_cartesian_2d((x_min * 0.8..x_max * 1.25).log_scale(), 0.0..y_max)?;
    chart
        .configure_mesh()
        .light_line_style(WHITE)
        .x_label_formatter(&|x| format!("{x:.0}"))
        .x_desc("budget (control steps per task, log scale)")
        .y_desc("mean path length (m)")
        .draw()?;
    let span = [x_min * 0.8, x_max * 1.25];
    chart
        .draw_series(LineSeries::new(
            span.map(|x| (x, bound)),
            BLACK.stroke_width(1),
        ))?
        .label(format!("reachability bound {bound:.3} m"))
        .legend(|(x, y)| PathElement::new([(x, y), (x + 16, y)], BLACK));
    chart
        .draw_series(LineSeries::new(
            span.map(|x| (x, pipeline)),
            RED.stroke_width(2),
        ))?
        .label(format!("Hybrid + DP pipeline {pipeline:.3} m"))
        .legend(|(x, y)| PathElement::new([(x, y), (x + 16, y)], RED));
    chart
        .draw_series(LineSeries::new(searched.clone(), BLUE.stroke_width(2)))?
        .label("search")
        .legend(|(x, y)| PathElement::new([(x, y), (x + 16, y)], BLUE));
    chart.draw_series(searched.iter().map(|p| Circle::new(*p, 4, BLUE.filled())))?;
    chart
        .configure_series_labels()
        .background_style(WHITE.mix(0.8))
        .border_style(BLACK)
        .position(SeriesLabelPosition::LowerRight)
        .draw()?;
    root.present()?;
    Ok(())
}
