//! `cargo xtask path-eval`: the path population (`emg_control::path_tasks`: rectangles, full
//! circles, arcs and S-curves from the evaluation tasks' starts) planned by the classical
//! controller from each task's generating configuration and by the search (`emg plan`'s
//! default), beside each path's reachability bound; every rollout re-checked by the independent
//! checker, every search plan timed rest to rest and its files verified as `emg check` verifies
//! them; the rectangles also planned one line at a time, as a line-only planner makes a user
//! plan them (`docs/results/paths.{json,md}`).

use std::path::Path;
use std::time::Instant;

use anyhow::Context;
use emg_control::{CheckRollout, PathShape, Task, Termination, path_tasks};
use emg_eval::{LinesOutcome, Summary, lines_one_at_a_time};
use emg_io::TrajectoryContents;
use emg_planner::{
    ControllerKind, DEFAULT_RATE_HZ, MotionTiming, PlanFiles, PlanRecord, PlanRequest, Planner,
    PlannerKind, SeedSource,
};
use emg_verify::ReferenceModel;
use rayon::prelude::*;
use serde::{Deserialize, Serialize};

use crate::results::shipped_results;
use crate::task_set_options::{ROBOT_WITH_JOINT_LIMITS, THREADS_TIMED, TaskSetOptions};
use crate::{progress, workspace};

/// Options of `path-eval`.
#[derive(clap::Args)]
#[command(
    mut_arg("threads", |arg| arg.help(THREADS_TIMED)),
    mut_arg("task_file", |arg| arg.help("Task set whose starts the paths leave from")),
    mut_arg("robot", |arg| arg.help(ROBOT_WITH_JOINT_LIMITS)),
    mut_arg("out_dir", |arg| arg.help("Output directory of paths.{json,md}")),
)]
pub struct Args {
    /// Paths: one from each of the first this many tasks of the task set.
    #[arg(long, default_value_t = 1000)]
    paths: usize,
    /// Seed of the path population's sizes and sides.
    #[arg(long, default_value_t = 20_261_126)]
    seed: u64,
    /// Worker threads, task set, robot file and output directory.
    #[command(flatten)]
    common: TaskSetOptions,
}

/// One path's outcome.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct PathRow {
    /// The stroke's shape.
    pub shape: PathShape,
    /// The path's length (m).
    pub length_m: f64,
    /// Arc length the classical controller reaches from `q0_seed` (m).
    pub classical_m: f64,
    /// Arc length the paper's pipeline (hybrid controller from the DP seed) reaches (m).
    pub pipeline_m: f64,
    /// Arc length the search reaches with the classical controller as its requested one (m).
    pub search_classical_m: f64,
    /// Arc length the search reaches (m).
    pub search_m: f64,
    /// The reachability bound along the path (m).
    pub bound_m: f64,
    /// Whether the search's plan reaches the end of the path.
    pub search_completed: bool,
    /// The rectangles planned one line at a time.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub lines: Option<LinesOutcome>,
    /// Rest-to-rest duration of the search's plan (s).
    pub duration_s: f64,
    /// Time of the search plan on its thread, bound scan included (ms).
    pub plan_ms: f64,
}

/// One shape's row of the table (or all shapes together).
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct ShapeRow {
    /// The shape's name, or `all`.
    pub shape: String,
    /// Paths of the shape.
    pub paths: usize,
    /// Mean path length (m).
    pub mean_length_m: f64,
    /// Σ reached / Σ path length: the classical controller, the pipeline, the search, the
    /// search with the classical controller, the bound.
    pub classical_share: f64,
    /// See `classical_share`.
    pub pipeline_share: f64,
    /// See `classical_share`.
    pub search_share: f64,
    /// See `classical_share`.
    pub search_classical_share: f64,
    /// See `classical_share`.
    pub bound_share: f64,
    /// Σ search / Σ bound.
    pub search_of_bound: f64,
    /// Paths planned to their end: the classical controller, the search; paths whose bound
    /// reaches the end.
    pub classical_completed: usize,
    /// See `classical_completed`.
    pub search_completed: usize,
    /// See `classical_completed`.
    pub bound_completed: usize,
}

/// The rectangles one line at a time beside the search on the whole path.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct LinesRow {
    /// Rectangles compared.
    pub paths: usize,
    /// Σ reached / Σ path length, the search on the path (no reconfiguration, by construction).
    pub path_share: f64,
    /// Σ drawn / Σ path length one line at a time, the arm reconfiguring where a line's plan
    /// starts elsewhere.
    pub lines_drawn_share: f64,
    /// Σ drawn before the first reconfiguration / Σ path length.
    pub lines_continuous_share: f64,
    /// Mean reconfigurations per rectangle.
    pub mean_reconfigurations: f64,
    /// Rectangles completed: the path planner; one line at a time (reconfigurations allowed);
    /// one line at a time without a reconfiguration.
    pub path_completed: usize,
    /// See `path_completed`.
    pub lines_completed: usize,
    /// See `path_completed`.
    pub lines_completed_continuous: usize,
}

/// The whole record written to `paths.json`.
#[derive(Serialize, Deserialize)]
pub struct Record {
    /// Robot name.
    pub robot: String,
    /// The command that wrote the record.
    pub command: String,
    /// Task set the paths start from.
    pub tasks: String,
    /// Seed of the population.
    pub seed: u64,
    /// Machine the times were measured on, and the worker threads.
    pub machine: String,
    /// See `machine`.
    pub threads: usize,
    /// Per shape, then all together.
    pub shapes: Vec<ShapeRow>,
    /// The comparison with one line at a time.
    pub lines: LinesRow,
    /// Search plan time on its thread (ms).
    pub plan_ms: Summary,
    /// Rest-to-rest duration of the search plans (s).
    pub duration_s: Summary,
    /// Rollouts or files the independent checker rejects (must be 0), and the first few.
    pub checker_failures: usize,
    /// See `checker_failures`.
    pub failure_examples: Vec<String>,
    /// Every path, in population order.
    pub rows: Vec<PathRow>,
}

/// Plans, checks and times every path; writes the record and its table.
pub fn run(args: &Args) -> anyhow::Result<()> {
    let workspace::PlannerSetup {
        planner,
        checker,
        tasks: anchors,
    } = args.common.planner_setup(args.paths, "path-eval")?;
    let paths = path_tasks(planner.robot(), &anchors, args.seed)?;
    let pool = workspace::thread_pool(args.common.threads)?;
    let (timing, _) = workspace::motion_timing(&planner, &args.common.robot, DEFAULT_RATE_HZ)?;
    let robot_name = args.common.robot.display().to_string();
    let comparison = Comparison {
        planner: &planner,
        checker: &checker,
        timing: &timing,
        robot_name: &robot_name,
    };
    let bar = progress::bar(paths.len() as u64, "paths");
    let outcomes: Vec<(PathRow, Vec<String>)> = pool.install(|| {
        paths
            .par_iter()
            .enumerate()
            .map(|(index, (shape, task))| {
                let outcome = comparison.plan_path(index, *shape, task);
                bar.inc(1);
                outcome
            })
            .collect::<anyhow::Result<Vec<_>>>()
    })?;
    bar.finish();
    let (rows, failures): (Vec<PathRow>, Vec<Vec<String>>) = outcomes.into_iter().unzip();
    let failures: Vec<String> = failures.into_iter().flatten().collect();
    let record = Record {
        robot: planner.robot().name().to_string(),
        command: workspace::command_for("path-eval", &args.common.robot),
        tasks: workspace::relative(&args.common.task_file),
        seed: args.seed,
        machine: workspace::machine(),
        threads: pool.current_num_threads(),
        shapes: shape_rows(&rows, &paths),
        lines: lines_row(&rows),
        plan_ms: Summary::of(&rows.iter().map(|r| r.plan_ms).collect::<Vec<_>>())
            .context("no paths")?,
        duration_s: Summary::of(&rows.iter().map(|r| r.duration_s).collect::<Vec<_>>())
            .context("no paths")?,
        checker_failures: failures.len(),
        failure_examples: failures.iter().take(5).cloned().collect(),
        rows,
    };
    workspace::write_results(&args.common.out_dir, "paths", &record, &markdown(&record))?;
    anyhow::ensure!(
        record.checker_failures == 0,
        "{} checks fail, e.g. {}",
        record.checker_failures,
        failures[0]
    );
    Ok(())
}

/// What every path is planned, checked and timed with.
struct Comparison<'a> {
    planner: &'a Planner,
    checker: &'a ReferenceModel,
    timing: &'a MotionTiming,
    /// The robot file as the plan records name it.
    robot_name: &'a str,
}

impl Comparison<'_> {
    /// Path `index` planned by the classical controller, the pipeline and the search (with the
    /// classical controller too), checked, the search's files written, read back and checked,
    /// and one line at a time; its row and what the checker rejects.
    fn plan_path(
        &self,
        index: usize,
        shape: PathShape,
        task: &Task,
    ) -> anyhow::Result<(PathRow, Vec<String>)> {
        let constraints = &self.planner.config().rollout.constraints;
        let classical = PlanRequest {
            planner: PlannerKind::Controller,
            seed: Some(SeedSource::Generating),
            controller: ControllerKind::Classical,
        };
        let pipeline = PlanRequest::pipeline();
        let search = PlanRequest::default();
        let search_classical = PlanRequest {
            controller: ControllerKind::Classical,
            ..PlanRequest::default()
        };
        let mut failures = Vec::new();
        let mut check = |what: &str, result: Result<(), String>| {
            if let Err(problem) = result {
                failures.push(format!("{} path, {what}: {problem}", shape.name()));
            }
        };
        let base = self.planner.plan(task, &classical)?;
        check(
            "classical rollout",
            self.checker
                .check(task, &base.trajectory, constraints)
                .map_err(|e| e.to_string()),
        );
        let learned = self.planner.plan(task, &pipeline)?;
        let classical_search = self.planner.plan(task, &search_classical)?;
        for (what, plan) in [
            ("pipeline", &learned),
            ("classical search", &classical_search),
        ] {
            check(
                what,
                self.checker
                    .check(task, &plan.trajectory, constraints)
                    .map_err(|e| e.to_string()),
            );
        }
        let started = Instant::now();
        let plan = self.planner.plan(task, &search)?;
        let plan_ms = started.elapsed().as_secs_f64() * 1e3;
        let bound = self.planner.bound_note(task, &plan);
        let record = PlanRecord {
            robot: self.robot_name,
            request: &search,
            bound: Some(&bound),
            timing: self.timing,
        };
        let files = PlanFiles::new(self.planner, task, &plan, &record).with_context(|| {
            format!(
                "path {index} ({}): {}",
                shape.name(),
                serde_json::to_string(task.path.as_ref().expect("a path task")).unwrap_or_default()
            )
        })?;
        for (what, verified) in self.verify_files(task, &files) {
            check(what, verified);
        }
        let lines = lines_one_at_a_time(self.planner, task, &search).transpose()?;
        let length_m = task.length_m().unwrap_or(0.0);
        Ok((
            PathRow {
                shape,
                length_m,
                classical_m: base.trajectory.path_length_m,
                pipeline_m: learned.trajectory.path_length_m,
                search_classical_m: classical_search.trajectory.path_length_m,
                search_m: plan.trajectory.path_length_m,
                bound_m: bound.reachable_m,
                search_completed: plan.trajectory.termination == Termination::Completed,
                lines,
                duration_s: files.timing.duration_s,
                plan_ms,
            },
            failures,
        ))
    }

    /// The search's trajectory files of `task` read back and verified as `emg check` verifies
    /// them: each file's name and what the checker says.
    fn verify_files(
        &self,
        task: &Task,
        files: &PlanFiles,
    ) -> [(&'static str, Result<(), String>); 2] {
        let verify = |text: &str| {
            TrajectoryContents::parse(text)
                .map_err(|e| e.to_string())
                .and_then(|contents| {
                    workspace::verify_file(&contents, self.planner, self.checker, task)
                        .map_err(|e| e.to_string())
                })
        };
        [
            ("search's trajectory file", verify(&files.json)),
            (
                "search's joint trajectory file",
                verify(&files.joint_trajectory),
            ),
        ]
    }
}

/// Whether a reached length counts as the end of a path of `length_m` (the step lands on it
/// to within the arrival tolerance the checker allows).
fn completes(reached_m: f64, length_m: f64) -> bool {
    reached_m >= length_m - 2.0 * emg_control::ARRIVAL_M
}

/// One row per shape, then all shapes together.
fn shape_rows(rows: &[PathRow], paths: &[(PathShape, Task)]) -> Vec<ShapeRow> {
    let classical_done: Vec<bool> = rows
        .iter()
        .map(|row| completes(row.classical_m, row.length_m))
        .collect();
    let row_of = |name: &str, members: Vec<usize>| {
        let sum =
            |value: fn(&PathRow) -> f64| members.iter().map(|&i| value(&rows[i])).sum::<f64>();
        let length = sum(|r| r.length_m);
        let bound = sum(|r| r.bound_m.min(r.length_m));
        ShapeRow {
            shape: name.to_string(),
            paths: members.len(),
            mean_length_m: length / members.len().max(1) as f64,
            classical_share: sum(|r| r.classical_m) / length,
            pipeline_share: sum(|r| r.pipeline_m) / length,
            search_share: sum(|r| r.search_m) / length,
            search_classical_share: sum(|r| r.search_classical_m) / length,
            bound_share: bound / length,
            search_of_bound: sum(|r| r.search_m) / bound,
            classical_completed: members.iter().filter(|&&i| classical_done[i]).count(),
            search_completed: members
                .iter()
                .filter(|&&i| rows[i].search_completed)
                .count(),
            bound_completed: members
                .iter()
                .filter(|&&i| completes(rows[i].bound_m, rows[i].length_m))
                .count(),
        }
    };
    let mut table: Vec<ShapeRow> = PathShape::ALL
        .iter()
        .map(|shape| {
            let members = (0..rows.len()).filter(|&i| paths[i].0 == *shape).collect();
            row_of(shape.name(), members)
        })
        .collect();
    table.push(row_of("all", (0..rows.len()).collect()));
    table
}

/// The comparison on the paths planned one line at a time (the rectangles).
fn lines_row(rows: &[PathRow]) -> LinesRow {
    let compared: Vec<(&PathRow, &LinesOutcome)> = rows
        .iter()
        .filter_map(|row| row.lines.as_ref().map(|lines| (row, lines)))
        .collect();
    let length: f64 = compared.iter().map(|(row, _)| row.length_m).sum();
    let share = |value: &dyn Fn(&(&PathRow, &LinesOutcome)) -> f64| {
        compared.iter().map(value).sum::<f64>() / length
    };
    LinesRow {
        paths: compared.len(),
        path_share: share(&|(row, _)| row.search_m),
        lines_drawn_share: share(&|(_, lines)| lines.drawn_m),
        lines_continuous_share: share(&|(_, lines)| lines.continuous_m),
        mean_reconfigurations: compared
            .iter()
            .map(|(_, lines)| lines.reconfigurations as f64)
            .sum::<f64>()
            / compared.len().max(1) as f64,
        path_completed: compared
            .iter()
            .filter(|(row, _)| row.search_completed)
            .count(),
        lines_completed: compared
            .iter()
            .filter(|(row, lines)| completes(lines.drawn_m, row.length_m))
            .count(),
        lines_completed_continuous: compared
            .iter()
            .filter(|(row, lines)| completes(lines.continuous_m, row.length_m))
            .count(),
    }
}

fn markdown(record: &Record) -> String {
    let mut md = format!(
        "# Paths: rectangles, circles, arcs and S-curves ({})\n\n\
         Generated by `{}` on {} ({} threads): one path from the start of \
         each of the first {} tasks of `{}` (`emg_control::path_tasks`, seed {}), along the \
         task's direction on its surface, the paper's protocol (no work surface). The \
         classical controller rolls out from the task's generating configuration; the search is \
         `emg plan`'s default (hybrid controller, DP samples among its starts); the pipeline is \
         the paper's (hybrid controller from the DP seed), both learned on lines and given the \
         path's local tangent as the line direction; *search, classical* is the search with the \
         classical controller as its requested one. Shares are Σ arc length reached / Σ path \
         length (the bound capped at the path's end); *completed* counts the paths planned to \
         their end.\n\n\
         | shape | paths | mean length (m) | classical | pipeline | search | search, classical | \
         bound | search / bound | completed: classical | search | bound |\n\
         |---|---|---|---|---|---|---|---|---|---|---|---|\n",
        record.robot,
        record.command,
        record.machine,
        record.threads,
        record.rows.len(),
        record.tasks,
        record.seed
    );
    for row in &record.shapes {
        md.push_str(&format!(
            "| {} | {} | {:.3} | {:.3} | {:.3} | {:.3} | {:.3} | {:.3} | {:.3} | {} | {} | {} |\n",
            row.shape,
            row.paths,
            row.mean_length_m,
            row.classical_share,
            row.pipeline_share,
            row.search_share,
            row.search_classical_share,
            row.bound_share,
            row.search_of_bound,
            row.classical_completed,
            row.search_completed,
            row.bound_completed
        ));
    }
    let lines = &record.lines;
    md.push_str(&format!(
        "\n## One line at a time\n\n\
         A line-only planner makes a user cut a rectangle into its four sides and plan each \
         from scratch as a line task (`emg_eval::lines_one_at_a_time`, the same search), its \
         plan cut at the side's end: the arm stops at every corner and starts the next side \
         wherever that side's plan starts, leaving the stroke to reconfigure when that is \
         another configuration (a joint more than {} rad away). On the {} rectangles:\n\n\
         | planner | Σ drawn / Σ length | completed | reconfigurations per rectangle |\n\
         |---|---|---|---|\n\
         | the search on the path | {:.3} | {} | 0 |\n\
         | one line at a time | {:.3} | {} | {:.2} |\n\
         | one line at a time, until the first reconfiguration | {:.3} | {} | — |\n",
        emg_eval::SAME_CONFIGURATION_RAD,
        lines.paths,
        lines.path_share,
        lines.path_completed,
        lines.lines_drawn_share,
        lines.lines_completed,
        lines.mean_reconfigurations,
        lines.lines_continuous_share,
        lines.lines_completed_continuous,
    ));
    md.push_str(&format!(
        "\n## Checks and time\n\n\
         Every rollout re-checked by the independent checker and every search plan's trajectory \
         and joint-trajectory files (timed rest to rest within `{}`'s joint limits, at rest at \
         each rectangle corner) verified as `emg check` verifies them: **{} failures**.\n\n\
         | | mean | std | min | max |\n|---|---|---|---|---|\n\
         | search plan, bound included (ms) | {:.1} | {:.1} | {:.1} | {:.1} |\n\
         | rest-to-rest duration (s) | {:.2} | {:.2} | {:.2} | {:.2} |\n",
        record.robot,
        record.checker_failures,
        record.plan_ms.mean,
        record.plan_ms.std,
        record.plan_ms.min,
        record.plan_ms.max,
        record.duration_s.mean,
        record.duration_s.std,
        record.duration_s.min,
        record.duration_s.max,
    ));
    md
}

/// The report's section on paths: per shipped arm with a `paths.json` under `results`, the
/// shares over all paths and per shape, and one line at a time on the rectangles.
pub fn report_section(results: &Path) -> anyhow::Result<String> {
    let mut rows = String::new();
    let mut lines = String::new();
    for (shipped, record) in shipped_results::<Record>(results, "paths.json")? {
        for row in &record.shapes {
            rows += &format!(
                "| {} | {} | {} | {:.3} | {:.3} | {:.3} | {:.3} | {} / {} / {} |\n",
                shipped.name,
                row.shape,
                row.paths,
                row.classical_share,
                row.pipeline_share,
                row.search_share,
                row.bound_share,
                row.classical_completed,
                row.search_completed,
                row.bound_completed
            );
        }
        let compared = &record.lines;
        lines += &format!(
            "| {} | {} | {:.3} ({}) | {:.3} ({}) | {:.2} | {:.3} ({}) |\n",
            shipped.name,
            compared.paths,
            compared.path_share,
            compared.path_completed,
            compared.lines_drawn_share,
            compared.lines_completed,
            compared.mean_reconfigurations,
            compared.lines_continuous_share,
            compared.lines_completed_continuous
        );
    }
    if rows.is_empty() {
        return Ok(String::new());
    }
    Ok(format!(
        "## Paths: rectangles, circles, arcs and S-curves\n\n\
         Σ arc length reached / Σ path length over the path population (`cargo xtask \
         path-eval`; `docs/results/paths.md`), and the paths planned to their end (classical / \
         search / bound):\n\n\
         | arm | shape | paths | classical | pipeline | search | bound | completed |\n\
         |---|---|---|---|---|---|---|---|\n{rows}\n\
         The rectangles one line at a time (each side planned from scratch by the same search, \
         the arm reconfiguring where the next side's plan starts elsewhere) against the search \
         on the whole path, Σ drawn / Σ length (completed):\n\n\
         | arm | rectangles | search on the path | one line at a time | reconfigurations per \
         rectangle | one line at a time, without reconfiguring |\n\
         |---|---|---|---|---|---|\n{lines}\n"
    ))
}
