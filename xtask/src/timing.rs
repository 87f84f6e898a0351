//! `cargo xtask timing`: every task of a task set planned as `emg plan` plans it (search planner,
//! hybrid controller, the bound's note), its joint trajectory timed rest to rest within the
//! robot's joint limits and written as `emg plan` writes it, read back and verified as `emg
//! check` verifies it; the duration statistics with and without jerk limits, and the time of
//! the whole `emg plan` per task (`docs/results/timing.{json,md}`,
//! `docs/figures/timing-durations.svg`).

use std::path::{Path, PathBuf};
use std::time::Instant;

use anyhow::Context;
use emg_control::Task;
use emg_eval::{Summary, four};
use emg_io::TrajectoryContents;
use emg_planner::{
    DEFAULT_RATE_HZ, MotionTiming, PlanFiles, PlanRecord, PlanRequest, Planner, PlannerKind,
};
use emg_verify::ReferenceModel;
use plotters::prelude::*;
use rayon::prelude::*;
use serde::{Deserialize, Serialize};

use crate::results::{SummaryPlace, shipped_results};
use crate::task_set_options::{ROBOT_WITH_JOINT_LIMITS, THREADS_TIMED, TaskSetOptions};
use crate::{figure, progress, workspace};

/// Options of `timing`.
#[derive(clap::Args)]
#[command(
    mut_arg("threads", |arg| arg.help(THREADS_TIMED)),
    mut_arg("robot", |arg| arg.help(ROBOT_WITH_JOINT_LIMITS)),
    mut_arg("out_dir", |arg| arg.help("Output directory of timing.{json,md}")),
)]
pub struct Args {
    /// Tasks: the first this many of the task set (default: all).
    #[arg(long)]
    tasks: Option<usize>,
    /// Samples per second of the joint trajectories.
    #[arg(long, default_value_t = DEFAULT_RATE_HZ)]
    rate_hz: f64,
    /// Worker threads, task set, robot file and output directory.
    #[command(flatten)]
    common: TaskSetOptions,
    /// Output figure.
    #[arg(long, default_value_os_t = workspace::figure("timing-durations.svg"))]
    figure: PathBuf,
}

/// One task's timed motion, as written and verified.
struct Outcome {
    /// Rest to rest (s).
    duration_s: f64,
    /// TOPP-RA within the velocity, acceleration and tool-speed limits, no jerk limit (s).
    time_optimal_s: f64,
    tool_speed_share: f64,
    path_travel_m: f64,
    points: usize,
    file_bytes: usize,
    refined: bool,
    /// Where the smooth path ends before the last planned point, and why.
    cut: Option<String>,
    slowdowns: usize,
    /// Wall time of the timing alone (ms).
    timing_ms: f64,
    /// Wall time of all that `emg plan` computes for the task (ms): the plan (search and
    /// bound), the bound's note and the timed files.
    whole_ms: f64,
    /// What `emg check` says when the file does not hold up.
    failure: Option<String>,
}

/// The whole record written to `timing.json`.
#[derive(Serialize, Deserialize)]
struct Record {
    robot: String,
    joint_limits: String,
    tasks: String,
    task_count: usize,
    rate_hz: f64,
    tool_speed_m_per_s: f64,
    machine: String,
    threads: usize,
    /// Rest to rest, jerk-limited: what the files hold (s).
    duration_s: Summary,
    /// The time-optimal motion without jerk limits along the same paths (s).
    time_optimal_s: Summary,
    /// duration / time-optimal − 1, per task.
    jerk_limited_overhead: Summary,
    /// Share of each motion with the tool at ≥ 99 % of the requested speed.
    tool_speed_share: Summary,
    /// TCP travel along each path (m).
    path_travel_m: Summary,
    points_per_trajectory: Summary,
    file_megabytes: Summary,
    /// Tasks whose smooth path needed extra knots to hold the task constraints.
    tasks_refined: usize,
    /// Tasks whose smooth path ends before the last planned point, and the first few.
    tasks_cut: usize,
    cut_examples: Vec<String>,
    /// Rounds of local slow-down per task.
    slowdowns: Summary,
    /// Wall time of the timing per trajectory (ms): median and 95th percentile.
    timing_ms_median: f64,
    timing_ms_p95: f64,
    /// Wall time of the whole `emg plan` per task (ms): the plan (search and bound), the
    /// bound's note and the timed files; with its median and 99th percentile.
    whole_plan_ms: Summary,
    whole_plan_ms_median: f64,
    whole_plan_ms_p99: f64,
    /// Files `emg check` rejects (must be 0), and the first few messages.
    checker_failures: usize,
    failure_examples: Vec<String>,
}

/// Plans, times, writes, reads back and checks every task; writes the record and its figure.
pub fn run(args: &Args) -> anyhow::Result<()> {
    let count = match args.tasks {
        Some(count) => count,
        None => emg_io::read_tasks(
            &args.common.task_file,
            &workspace::load_robot(&args.common.robot)?,
        )?
        .len(),
    };
    let workspace::PlannerSetup {
        planner,
        checker,
        tasks,
    } = args.common.planner_setup(count, "timing")?;
    let pool = workspace::thread_pool(args.common.threads)?;
    let config = planner.config().clone();
    let (timing, limits_file) =
        workspace::motion_timing(&planner, &args.common.robot, args.rate_hz)?;
    let robot_name = args.common.robot.display().to_string();
    let timer = Timer {
        planner: &planner,
        checker: &checker,
        timing: &timing,
        // `emg plan`'s defaults: the search planner, the hybrid controller, DP seeds.
        request: PlanRequest {
            planner: PlannerKind::Search,
            ..PlanRequest::pipeline()
        },
        robot_name: &robot_name,
    };
    let bar = progress::bar(tasks.len() as u64, "timing");
    let outcomes: Vec<Outcome> = pool.install(|| {
        tasks
            .par_iter()
            .enumerate()
            .map(|(index, task)| {
                let outcome = timer.time_task(index, task);
                bar.inc(1);
                outcome
            })
            .collect::<anyhow::Result<Vec<_>>>()
    })?;
    bar.finish();
    let record = Record {
        robot: planner.robot().name().to_string(),
        joint_limits: workspace::relative(&limits_file),
        tasks: workspace::relative(&args.common.task_file),
        task_count: tasks.len(),
        rate_hz: args.rate_hz,
        tool_speed_m_per_s: config.rollout.speed_m_per_s,
        machine: workspace::machine(),
        threads: pool.current_num_threads(),
        ..Record::of(&outcomes)?
    };
    workspace::write_results(&args.common.out_dir, "timing", &record, &markdown(&record))?;
    draw(&outcomes, &record, &args.figure)?;
    println!("wrote {}", args.figure.display());
    anyhow::ensure!(
        record.checker_failures == 0,
        "{} of {} timed trajectories fail the check, e.g. {}",
        record.checker_failures,
        record.task_count,
        record.failure_examples[0]
    );
    Ok(())
}

/// What every task is planned, timed and checked with, as `emg plan` and `emg check` do.
struct Timer<'a> {
    planner: &'a Planner,
    checker: &'a ReferenceModel,
    timing: &'a MotionTiming,
    request: PlanRequest,
    /// The robot file as the plan records name it.
    robot_name: &'a str,
}

impl Timer<'_> {
    /// Plans task `index` as `emg plan` does, times its motion, and reads back and checks the
    /// joint trajectory it writes.
    fn time_task(&self, index: usize, task: &Task) -> anyhow::Result<Outcome> {
        let constraints = &self.planner.config().rollout.constraints;
        let whole = Instant::now();
        let plan = self.planner.plan(task, &self.request)?;
        let bound = self.planner.bound_note(task, &plan);
        let record = PlanRecord {
            robot: self.robot_name,
            request: &self.request,
            bound: Some(&bound),
            timing: self.timing,
        };
        let files = PlanFiles::new(self.planner, task, &plan, &record)?;
        let whole_ms = whole.elapsed().as_secs_f64() * 1e3;
        let started = Instant::now();
        let motion = self
            .timing
            .time(self.planner.robot(), task, constraints, &plan.trajectory)?;
        let timing_ms = started.elapsed().as_secs_f64() * 1e3;
        let contents = TrajectoryContents::parse(&files.joint_trajectory)?;
        let failure = workspace::verify_file(&contents, self.planner, self.checker, task)
            .err()
            .map(|failure| format!("task {index}: {failure}"));
        let report = &motion.report;
        Ok(Outcome {
            duration_s: report.duration_s,
            time_optimal_s: report.time_optimal_s,
            tool_speed_share: report.tool_speed_share,
            path_travel_m: report.path_travel_m,
            points: motion.samples.len(),
            file_bytes: files.joint_trajectory.len(),
            refined: report.refined_knots > 0,
            cut: report.cut.as_ref().map(|(point, violation)| {
                format!("task {index}: ends at planned point {point}: {violation}")
            }),
            slowdowns: report.slowdowns,
            timing_ms,
            whole_ms,
            failure,
        })
    }
}

impl Record {
    /// The statistics of `outcomes`; the fields that name the run are left empty.
    fn of(outcomes: &[Outcome]) -> anyhow::Result<Self> {
        let summary = |value: fn(&Outcome) -> f64| {
            Summary::of(&outcomes.iter().map(value).collect::<Vec<_>>()).context("no tasks")
        };
        let overhead: Vec<f64> = outcomes
            .iter()
            .filter(|o| o.time_optimal_s > 0.0)
            .map(|o| o.duration_s / o.time_optimal_s - 1.0)
            .collect();
        let sorted = |value: fn(&Outcome) -> f64| {
            let mut values: Vec<f64> = outcomes.iter().map(value).collect();
            values.sort_by(f64::total_cmp);
            values
        };
        let quantile =
            |sorted: &[f64], q: f64| sorted[((sorted.len() - 1) as f64 * q).round() as usize];
        let (timing_ms, whole_ms) = (sorted(|o| o.timing_ms), sorted(|o| o.whole_ms));
        let failures: Vec<String> = outcomes.iter().filter_map(|o| o.failure.clone()).collect();
        let cuts: Vec<String> = outcomes.iter().filter_map(|o| o.cut.clone()).collect();
        Ok(Self {
            robot: String::new(),
            joint_limits: String::new(),
            tasks: String::new(),
            task_count: 0,
            rate_hz: 0.0,
            tool_speed_m_per_s: 0.0,
            machine: String::new(),
            threads: 0,
            duration_s: summary(|o| o.duration_s)?,
            time_optimal_s: summary(|o| o.time_optimal_s)?,
            jerk_limited_overhead: Summary::of(&overhead).context("no moving task")?,
            tool_speed_share: summary(|o| o.tool_speed_share)?,
            path_travel_m: summary(|o| o.path_travel_m)?,
            points_per_trajectory: summary(|o| o.points as f64)?,
            file_megabytes: summary(|o| o.file_bytes as f64 / 1e6)?,
            tasks_refined: outcomes.iter().filter(|o| o.refined).count(),
            tasks_cut: cuts.len(),
            cut_examples: cuts.iter().take(5).cloned().collect(),
            slowdowns: summary(|o| o.slowdowns as f64)?,
            timing_ms_median: quantile(&timing_ms, 0.5),
            timing_ms_p95: quantile(&timing_ms, 0.95),
            whole_plan_ms: summary(|o| o.whole_ms)?,
            whole_plan_ms_median: quantile(&whole_ms, 0.5),
            whole_plan_ms_p99: quantile(&whole_ms, 0.99),
            checker_failures: failures.len(),
            failure_examples: failures.iter().take(5).cloned().collect(),
        })
    }
}

/// Markers of the table of `emg plan`'s time per task in `docs/results/summary.md`
/// ([`plan_times_table`], written there by `cargo xtask report`,
/// [`crate::workspace::RESULTS_SUMMARY`]).
const README_START: &str = "<!-- plan-times:start -->";
/// The end marker of that table.
const README_END: &str = "<!-- plan-times:end -->";

/// Where the table of plan times ([`plan_times_table`]) is shown: the results summary.
pub const SUMMARY: SummaryPlace = SummaryPlace::in_results_summary(
    README_START,
    README_END,
    "## Time of the whole `emg plan`\n\nPer unseen task: the plan (search and bound), the \
         bound's note and the timed files, as `emg plan` computes them (`cargo xtask timing`; \
         `docs/results/timing.md` per arm):\n\n",
);

/// For every shipped arm with a `timing.json` under `results` (the FR3's top-level, the others'
/// in their sub-directories): the time of the whole `emg plan` per task (mean, median, 99th
/// percentile, slowest), the timing's share of it (median) and the machine and threads it was
/// measured with.
pub fn plan_times_table(results: &Path) -> anyhow::Result<String> {
    let mut md = String::from(
        "| arm | tasks | mean ms | median ms | 99th percentile ms | slowest ms | timing alone, \
         median ms | measured on |\n|---|---|---|---|---|---|---|---|\n",
    );
    for (shipped, record) in shipped_results::<Record>(results, "timing.json")? {
        md += &format!(
            "| {} | {} | {:.1} | {:.1} | {:.1} | {:.1} | {:.2} | {}, {} threads busy |\n",
            shipped.name,
            record.task_count,
            record.whole_plan_ms.mean,
            record.whole_plan_ms_median,
            record.whole_plan_ms_p99,
            record.whole_plan_ms.max,
            record.timing_ms_median,
            record.machine,
            record.threads,
        );
    }
    Ok(md)
}

fn markdown(record: &Record) -> String {
    let rows = [
        (
            "duration, rest to rest, jerk-limited (s)",
            four(&record.duration_s, 3),
        ),
        (
            "time-optimal duration without jerk limits (s)",
            four(&record.time_optimal_s, 3),
        ),
        (
            "jerk-limited overhead (duration / time-optimal − 1)",
            four(&record.jerk_limited_overhead, 4),
        ),
        (
            "share of the time at the requested tool speed",
            four(&record.tool_speed_share, 3),
        ),
        (
            "TCP travel along the path (m)",
            four(&record.path_travel_m, 3),
        ),
        (
            "points per trajectory",
            four(&record.points_per_trajectory, 0),
        ),
        ("file size (MB)", four(&record.file_megabytes, 2)),
        ("slow-down rounds", four(&record.slowdowns, 2)),
    ];
    let mut md = format!(
        "# Rest-to-rest timing of planned motions\n\nWritten by `cargo xtask timing`. Do not \
         edit by hand. Robot `{}`, joint limits `{}`, {} tasks of `{}`, planned as `emg plan` \
         plans them (search planner, hybrid controller, DP seeds), each joint trajectory timed \
         at {} Hz with the tool at most {} m/s, written as `emg plan` writes it, read back and \
         verified as `emg check` verifies it (velocity, acceleration and jerk limits, rest at \
         both ends, every task constraint at every sample).\n\n\
         **Checker failures: {} of {}.**\n\n\
         | quantity | mean / std / min / max |\n|---|---|\n",
        record.robot,
        record.joint_limits,
        record.task_count,
        record.tasks,
        record.rate_hz,
        record.tool_speed_m_per_s,
        record.checker_failures,
        record.task_count,
    );
    for (name, value) in rows {
        md += &format!("| {name} | {value} |\n");
    }
    md += &format!(
        "\nSmooth paths that needed extra knots to hold the task constraints: {}; paths that end \
         before the last planned point: {}.\n\nTiming alone (smooth path, TOPP-RA, jerk \
         limiting, samples and their limit checks) takes {:.2} ms per trajectory (median; 95th \
         percentile {:.2} ms) of wall time on {} with {} threads busy; the criterion bench \
         `timing` measures it on one idle core. The whole `emg plan` per task (the plan, \
         search and bound; the bound's note; the timed files) takes {:.1} ms on average \
         (median {:.1} ms, 99th percentile {:.1} ms, slowest {:.1} ms) on the same threads.\n",
        record.tasks_refined,
        record.tasks_cut,
        record.timing_ms_median,
        record.timing_ms_p95,
        record.machine,
        record.threads,
        record.whole_plan_ms.mean,
        record.whole_plan_ms_median,
        record.whole_plan_ms_p99,
        record.whole_plan_ms.max,
    );
    for example in record.cut_examples.iter().chain(&record.failure_examples) {
        md += &format!("\n* {example}");
    }
    md
}

/// Each task's duration against its path's TCP travel, with the line of a motion at the
/// requested tool speed throughout: how far the joint limits keep the tool below it.
fn draw(outcomes: &[Outcome], record: &Record, path: &Path) -> anyhow::Result<()> {
    let axis_end = |value: fn(&Outcome) -> f64| {
        outcomes.iter().map(value).fold(0.0, f64::max).max(1e-3) * 1.05
    };
    let (longest, slowest) = (axis_end(|o| o.path_travel_m), axis_end(|o| o.duration_s));
    let speed = record.tool_speed_m_per_s;
    let root = figure::canvas(path, (720, 480))?;
    let mut chart = ChartBuilder::on(&root)
        .caption(
            format!(
                "{}: rest-to-rest duration of {} planned motions",
                record.robot, record.task_count
            ),
            ("sans-serif", 18),
        )
        .margin(12)
        .x_label_area_size(40)
        .y_label_area_size(56)
        .build_cartesian_2d(0.0..longest, 0.0..slowest)?;
    chart
        .configure_mesh()
        .light_line_style(WHITE)
        .x_desc("TCP travel along the path (m)")
        .y_desc("duration, jerk-limited (s)")
        .draw()?;
    chart
        .draw_series(
            outcomes
                .iter()
                .map(|o| Circle::new((o.path_travel_m, o.duration_s), 2, BLUE.mix(0.3).filled())),
        )?
        .label("one task")
        .legend(|(x, y)| Circle::new((x + 8, y), 3, BLUE.filled()));
    let end = longest.min(slowest * speed);
    chart
        .draw_series(LineSeries::new(
            [(0.0, 0.0), (end, end / speed)],
            BLACK.stroke_width(2),
        ))?
        .label(format!("the tool at {speed} m/s throughout"))
        .legend(|(x, y)| PathElement::new([(x, y), (x + 16, y)], BLACK));
    figure::draw_legend(&mut chart, SeriesLabelPosition::UpperLeft)?;
    root.present()?;
    Ok(())
}
