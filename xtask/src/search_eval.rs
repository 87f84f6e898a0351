//! `cargo xtask search-eval`: the search planner against the paper's pipeline (Hybrid + DP) on
//! the first tasks of the evaluation set, at several step budgets, beside each task's
//! reachability bound (`docs/results/search.{json,md}`, `docs/figures/search-budget.svg`):
//! shares of the bound length-weighted per bucket of the bound, and the time every plan took.

use std::path::{Path, PathBuf};
use std::time::Instant;

use anyhow::Context;
use emg_control::{CheckRollout, Task};
use emg_eval::{BoundShare, Summary, bound_shares, four};
use emg_planner::{
    PlanRequest, Planner, PlannerConfig, PlannerKind, SHORTFALL_SHARE, SearchConfig,
};
use emg_verify::ReferenceModel;
use indicatif::ProgressIterator;
use plotters::prelude::*;
use serde::{Deserialize, Serialize};

use crate::task_set_options::TaskSetOptions;
use crate::{figure, progress, workspace};

/// File name of the mean length against budget figure in a robot's figure directory.
pub const BUDGET_FIGURE: &str = "search-budget.svg";

/// Where `--budgets` stands among the options of `search-eval`: `--threads` is listed beside
/// it (after it, by name), before `--search-config`.
const BUDGETS_SLOT: usize = 1;

/// Options of `search-eval`.
#[derive(clap::Args)]
#[command(
    mut_arg("threads", |arg| arg.display_order(BUDGETS_SLOT)),
    mut_arg("out_dir", |arg| arg.help("Output directory of search.{json,md}")),
)]
pub struct Args {
    /// Tasks: the first this many of the task set (the report's Search rows need the whole
    /// evaluation set).
    #[arg(long, default_value_t = 10_000)]
    tasks: usize,
    /// Step budgets of the search, comma-separated.
    #[arg(long, value_delimiter = ',', default_values_t = [1_000u64, 5_000, 10_000, 20_000, 50_000])]
    budgets: Vec<u64>,
    /// JSON file of search settings (`emg_planner::SearchConfig`; unset fields keep their
    /// defaults, `budget_steps` is replaced by each of `--budgets`).
    #[arg(long, value_name = "JSON")]
    search_config: Option<PathBuf>,
    /// Worker threads, task set, robot file and output directory.
    #[command(flatten)]
    common: TaskSetOptions,
    /// Output figure.
    #[arg(long, default_value_os_t = workspace::figure(BUDGET_FIGURE))]
    figure: PathBuf,
    /// Plan nothing: write search.md and the figure again from the search.json there.
    #[arg(long)]
    render_only: bool,
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
    /// `Σ length / Σ bound` per bucket of the bound, then over all tasks, with the tasks below
    /// half their bound.
    pub bound_shares: Vec<BoundShare>,
    /// Steps actually taken by the returned plans, mean.
    pub plan_steps: f64,
    /// Wall time × threads per task on this machine (ms): the CPU time a task takes.
    pub cpu_ms_per_task: f64,
    /// Time each plan took on its thread (ms; search and bound together), over the tasks.
    pub plan_ms: Summary,
    /// Median and 99th percentile of the plan times (ms).
    pub plan_ms_median_p99: [f64; 2],
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
    /// Reachability bounds of the tasks: the scan's, raised to the longest plan of any row.
    pub reachability_bound_m: Summary,
    /// Tasks where some plan went beyond the scan's own bound.
    pub scan_missed: usize,
    /// The bound of every task (m), in task order.
    pub bounds_m: Vec<f64>,
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
    if args.render_only {
        return render(args);
    }
    let workspace::PlannerSetup {
        planner,
        checker,
        tasks,
    } = args.common.planner_setup(args.tasks, "search-eval")?;
    let pool = workspace::thread_pool(args.common.threads)?;
    let search: SearchConfig =
        workspace::read_config(args.search_config.as_deref(), "search config")?;
    let budgets = Budgets {
        planner: &planner,
        checker: &checker,
        tasks: &tasks,
        pool: &pool,
        search: &search,
    };
    let mut rows: Vec<Row> = Vec::new();
    // The scan's bound of every task: the search scans it (from the pipeline's seed, at every
    // budget alike) and hands it back with its plan.
    let mut scanned: Option<Vec<f64>> = None;
    let settings = std::iter::once(None).chain(args.budgets.iter().copied().map(Some));
    for budget in settings.progress_with(progress::bar(1 + args.budgets.len() as u64, "budgets")) {
        let pipeline_mean = rows.first().map(|pipeline| pipeline.path_length_m.mean);
        let (row, scans) = budgets.plan_all(budget, pipeline_mean)?;
        if scans.len() == tasks.len() {
            scanned.get_or_insert(scans);
        }
        rows.push(row);
    }
    let scanned = match scanned {
        Some(scanned) => scanned,
        None => pool.install(|| {
            use rayon::prelude::*;
            tasks
                .par_iter()
                .map(|task| planner.reach(task, &[]).scanned_m)
                .collect()
        }),
    };
    // Every plan witnesses its length: the bound never reads below a plan.
    let bounds: Vec<f64> = scanned
        .iter()
        .enumerate()
        .map(|(i, &scan)| rows.iter().map(|r| r.lengths_m[i]).fold(scan, f64::max))
        .collect();
    let scan_missed = bounds.iter().zip(&scanned).filter(|(b, s)| b > s).count();
    for row in &mut rows {
        row.share_of_bound = mean_ratio(&row.lengths_m, &bounds);
        row.bound_shares = bound_shares(&row.lengths_m, &bounds, &bounds);
    }
    let record = Record {
        robot: planner.robot().name().to_string(),
        tasks: workspace::relative(&args.common.task_file),
        task_count: tasks.len(),
        machine: workspace::machine(),
        threads: pool.current_num_threads(),
        search,
        reachability_bound_m: Summary::of(&bounds).context("no tasks")?,
        scan_missed,
        bounds_m: bounds,
        rows,
    };
    workspace::write_results(&args.common.out_dir, "search", &record, &markdown(&record))?;
    draw(&record, &args.figure)?;
    println!("wrote {}", args.figure.display());
    Ok(())
}

/// Writes `search.md` and the figure again from the `search.json` in the output directory.
fn render(args: &Args) -> anyhow::Result<()> {
    let path = args.common.out_dir.join("search.json");
    let record: Record = serde_json::from_str(
        &std::fs::read_to_string(&path).with_context(|| format!("reading {}", path.display()))?,
    )?;
    workspace::write_results(&args.common.out_dir, "search", &record, &markdown(&record))?;
    draw(&record, &args.figure)?;
    println!("wrote {}", args.figure.display());
    Ok(())
}

/// The tasks, and what each budget plans and checks them with.
struct Budgets<'a> {
    planner: &'a Planner,
    checker: &'a ReferenceModel,
    tasks: &'a [Task],
    pool: &'a rayon::ThreadPool,
    /// The search's settings but its budget.
    search: &'a SearchConfig,
}

impl Budgets<'_> {
    /// Every task planned by the pipeline (`budget` none) or by the search at `budget` steps,
    /// and checked: the row (its shares of the bound left for the caller, its mean length
    /// against `pipeline_mean`, its own when none) and the scan's bound of each task the
    /// plans hand back.
    fn plan_all(
        &self,
        budget: Option<u64>,
        pipeline_mean: Option<f64>,
    ) -> anyhow::Result<(Row, Vec<f64>)> {
        let mut config = PlannerConfig {
            search: self.search.clone(),
            ..PlannerConfig::default()
        };
        let request = match budget {
            None => PlanRequest::pipeline(),
            Some(steps) => {
                config.search.budget_steps = steps;
                PlanRequest {
                    planner: PlannerKind::Search,
                    ..PlanRequest::pipeline()
                }
            }
        };
        let planner = self.planner.with_config(config)?;
        let started = Instant::now();
        let plans: Vec<_> = self.pool.install(|| {
            use rayon::prelude::*;
            self.tasks
                .par_iter()
                .map(|task| {
                    let started = Instant::now();
                    let plan = planner.plan(task, &request);
                    (plan, started.elapsed().as_secs_f64() * 1e3)
                })
                .collect()
        });
        let threads = self.pool.current_num_threads();
        let cpu_ms = started.elapsed().as_secs_f64() * 1e3 * threads as f64;
        let count = self.tasks.len();
        let mut lengths = Vec::with_capacity(count);
        let mut plan_ms = Vec::with_capacity(count);
        let mut scans = Vec::with_capacity(count);
        let mut steps = 0usize;
        let mut failures = 0;
        for (task, (plan, ms)) in self.tasks.iter().zip(plans) {
            let plan = plan.with_context(|| format!("planning {task:?}"))?;
            if self
                .checker
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
            plan_ms.push(ms);
            scans.extend(plan.reach.map(|reach| reach.scanned_m));
        }
        let summary = Summary::of(&lengths).context("no tasks")?;
        let pipeline_mean = pipeline_mean.unwrap_or(summary.mean);
        let row = Row {
            planner: if budget.is_some() {
                "search"
            } else {
                "pipeline"
            }
            .to_string(),
            budget_steps: budget,
            ratio_to_pipeline: summary.mean / pipeline_mean,
            path_length_m: summary,
            share_of_bound: 0.0,
            bound_shares: Vec::new(),
            plan_steps: steps as f64 / count as f64,
            cpu_ms_per_task: cpu_ms / count as f64,
            plan_ms: Summary::of(&plan_ms).context("no tasks")?,
            plan_ms_median_p99: [percentile(&plan_ms, 0.5), percentile(&plan_ms, 0.99)],
            checker_failures: failures,
            lengths_m: lengths,
        };
        Ok((row, scans))
    }
}

/// The points the far-end stage of `config` plans back from, as words: "3 and 10 grid steps
/// past the plan's end, halfway to the bound, half a grid step before it, and 95 %, 80 % and
/// 50 % of the scan".
pub(crate) fn far_end_points(config: &SearchConfig) -> String {
    let percents: Vec<String> = config
        .far_end_shares
        .iter()
        .map(|share| format!("{:.0} %", 100.0 * share))
        .collect();
    let listed = match percents.split_last() {
        Some((last, rest)) if !rest.is_empty() => format!("{} and {last}", rest.join(", ")),
        _ => percents.join(""),
    };
    format!(
        "3 and 10 grid steps past the plan's end, halfway to the bound, half a grid step before \
         it, and {listed} of the scan"
    )
}

/// What the search (`config`) does where its plan ends short of its bound, as a clause of
/// search.md's description: its widened pass and its beam stage, each when it has one.
fn shortfall_clause(config: &SearchConfig) -> String {
    let mut clause = String::new();
    if config.widened_budget_steps > 0 {
        clause += &format!(
            "; where its plan then ends below {SHORTFALL_SHARE} × the bound, it goes on with {} \
             more steps, {} times as many chains, diffusion samples and IK restarts",
            config.widened_budget_steps, config.widened_breadth
        );
    }
    if !config.far_end_shares.is_empty() {
        let when = if clause.is_empty() { "then" } else { "still" };
        clause += &format!(
            "; where its plan {when} ends below {SHORTFALL_SHARE} × the bound, it plans the line \
             backwards to `p0` from {} (the whole planner on the reversed line, its own far \
             end left out) and takes each motion that gets past `p0`, read forwards and followed \
             from `p0`, asking again beyond each new end until no motion back passes `p0`",
            far_end_points(config)
        );
    }
    if config.beam_width > 0 {
        let when = if clause.is_empty() { "then" } else { "still" };
        clause += &format!(
            "; where its plan {when} ends below {} × the bound, a beam search over action \
             sequences of {} members goes on for up to {} more steps",
            config.beam_below_share, config.beam_width, config.beam_budget_steps
        );
    }
    clause
}

/// The `fraction` quantile of `values` (nearest rank).
fn percentile(values: &[f64], fraction: f64) -> f64 {
    let mut sorted = values.to_vec();
    sorted.sort_by(f64::total_cmp);
    let rank = (fraction * sorted.len() as f64).ceil() as usize;
    sorted[rank.clamp(1, sorted.len()) - 1]
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
         seed, one rollout). The search first scans the task's reachability bound, rolls the \
         pipeline's plan out, follows up to {} of the scan's chains of configurations from `p0` \
         (its witnesses split where neighbours jump more than {} rad, later pieces joined back \
         to `p0`) with a tracking action, then ranks candidate starts (q0_seed, q_mu, q_jl, {} \
         diffusion samples, cone IK from {} restarts) by rollouts of its own classical \
         controller (Eq. 3 with k_θ {} gated from {}° before the cone's edge, and the tool axis \
         led {}° ahead of its drift with k_lead {}) and re-rolls the best {} with the hybrid \
         controller; then it repairs the longest rollouts of the best {} starts where they \
         failed (each null-space basis direction held for {} steps from 1 to 32 steps before \
         the end, then the hybrid or the search's classical controller). It stops when its \
         budget of control steps is spent or a plan comes within {} m of the first grid point \
         the scan missed{}. Every plan is re-checked by the independent checker. The bound of a \
         task is the scan's, raised to the longest plan of any row (a plan beyond the scan's \
         bound on {} tasks); it ignores continuity, so it may be loose. \
         Bound (m, mean / std / min / max): {}. Times are on {} ({} threads) and depend on the \
         machine; the lengths do not.\n\n\
         | planner | budget (steps) | path length (m, mean / std / min / max) | mean / pipeline \
         mean | length / bound (task mean) | steps per plan | CPU ms per task | checker failures |\n\
         |---|---|---|---|---|---|---|---|\n",
        record.robot,
        record.task_count,
        record.tasks,
        record.search.chains,
        record.search.chain_jump_rad,
        record.search.dp_samples,
        record.search.ik_restarts,
        record.search.classical_gains.k_theta,
        record.search.classical_gains.cone_gate_width_deg,
        record.search.classical_gains.lead_deg,
        record.search.classical_gains.k_lead,
        record.search.finalists,
        record.search.repaired_starts,
        record.search.detour_steps,
        record.search.stop_within_m,
        shortfall_clause(&record.search),
        record.scan_missed,
        four(&record.reachability_bound_m, 3),
        record.machine,
        record.threads,
    );
    for row in &record.rows {
        md += &format!(
            "| {} | {} | {} | {:.3} | {:.3} | {:.1} | {:.1} | {} |\n",
            row.planner,
            budget_name(row),
            four(&row.path_length_m, 4),
            row.ratio_to_pipeline,
            row.share_of_bound,
            row.plan_steps,
            row.cpu_ms_per_task,
            row.checker_failures,
        );
    }
    md += "\n## Share of the bound by bucket of the bound\n\nΣ length / Σ bound over the \
           tasks whose bound lies in the bucket (the task mean of length / bound in brackets), and \
           the tasks that end below half their bound.\n\n| planner | budget (steps) |";
    let Some(first) = record.rows.first() else {
        return md;
    };
    for bucket in &first.bound_shares {
        md += &format!(" {} ({} tasks) |", bucket.bucket, bucket.tasks);
    }
    md += " tasks below 0.5 × bound |\n|---|---|";
    md += &"---|".repeat(first.bound_shares.len() + 1);
    md += "\n";
    for row in &record.rows {
        md += &format!("| {} | {} |", row.planner, budget_name(row));
        for bucket in &row.bound_shares {
            md += &format!(" {:.3} ({:.3}) |", bucket.share, bucket.task_mean_share);
        }
        let below = row
            .bound_shares
            .last()
            .map_or(0, |all| all.below_half.len());
        md += &format!(" {below} |\n");
    }
    md += "\n## Time per plan\n\nThe time each plan took on its thread (the search with its \
           bound scan; ms).\n\n| planner | budget (steps) | mean | median | 99th percentile | \
           slowest |\n|---|---|---|---|---|---|\n";
    for row in &record.rows {
        md += &format!(
            "| {} | {} | {:.1} | {:.1} | {:.1} | {:.1} |\n",
            row.planner,
            budget_name(row),
            row.plan_ms.mean,
            row.plan_ms_median_p99[0],
            row.plan_ms_median_p99[1],
            row.plan_ms.max,
        );
    }
    md
}

/// The budget of a row for tables: its steps, or a dash for the pipeline.
fn budget_name(row: &Row) -> String {
    row.budget_steps.map_or("—".into(), |b| b.to_string())
}

/// Σ length / Σ bound against the search budget, one line per bucket of the bound and one for
/// all tasks, with the pipeline's share of all tasks as a horizontal line.
fn draw(record: &Record, path: &Path) -> anyhow::Result<()> {
    let searched: Vec<&Row> = record
        .rows
        .iter()
        .filter(|r| r.budget_steps.is_some())
        .collect();
    let budget = |r: &Row| r.budget_steps.unwrap_or(0) as f64;
    let (x_min, x_max) = searched
        .iter()
        .fold((f64::INFINITY, 0.0f64), |(lo, hi), r| {
            (lo.min(budget(r)), hi.max(budget(r)))
        });
    let pipeline = record
        .rows
        .iter()
        .find(|r| r.budget_steps.is_none())
        .and_then(|r| r.bound_shares.last())
        .map_or(0.0, |all| all.share);
    let root = figure::canvas(path, (720, 420))?;
    let mut chart = ChartBuilder::on(&root)
        .caption(
            format!(
                "{}: Σ length / Σ bound against the search budget",
                record.robot
            ),
            ("sans-serif", 18),
        )
        .margin(12)
        .x_label_area_size(40)
        .y_label_area_size(56)
        .build_cartesian_2d((x_min * 0.8..x_max * 1.25).log_scale(), 0.0..1.05)?;
    chart
        .configure_mesh()
        .light_line_style(WHITE)
        .x_label_formatter(&|x| format!("{x:.0}"))
        .x_desc("budget (control steps per task, log scale)")
        .y_desc("Σ length / Σ bound")
        .draw()?;
    let span = [x_min * 0.8, x_max * 1.25];
    chart
        .draw_series(LineSeries::new(
            span.map(|x| (x, pipeline)),
            RED.stroke_width(2),
        ))?
        .label(format!("Hybrid + DP pipeline, all tasks {pipeline:.3}"))
        .legend(|(x, y)| PathElement::new([(x, y), (x + 16, y)], RED));
    let buckets = searched.first().map_or(0, |r| r.bound_shares.len());
    for bucket in 0..buckets {
        let colour = Palette99::pick(bucket).to_rgba();
        let colour = if bucket + 1 == buckets {
            BLACK.to_rgba()
        } else {
            colour
        };
        let points: Vec<(f64, f64)> = searched
            .iter()
            .map(|r| (budget(r), r.bound_shares[bucket].share))
            .collect();
        let first = &searched[0].bound_shares[bucket];
        chart
            .draw_series(LineSeries::new(points.clone(), colour.stroke_width(2)))?
            .label(format!(
                "search, bound {} ({} tasks)",
                first.bucket, first.tasks
            ))
            .legend(move |(x, y)| PathElement::new([(x, y), (x + 16, y)], colour));
        chart.draw_series(points.iter().map(|p| Circle::new(*p, 4, colour.filled())))?;
    }
    figure::draw_legend(&mut chart, SeriesLabelPosition::LowerRight)?;
    root.present()?;
    Ok(())
}
