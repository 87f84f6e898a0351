//! `cargo xtask precision-eval`: the search (`emg plan`'s default request) at the tolerances a
//! cell uses, 20 mm (the paper's benchmark), 0.5 mm and 0.1 mm, with the paper's step and the
//! corrected step (`emg_control::Tracking`), on the first tasks of the evaluation set (lines)
//! and on the path population of `path-eval` (paths): Σ plan / Σ bound per bucket of the bound
//! at each tolerance, the motions the line tolerance ends, the paths completed, every plan
//! re-checked by the independent checker and every corrected plan timed rest to rest with its
//! files verified as `emg check` verifies them (`docs/results/precision.{json,md}`).

use std::path::Path;
use std::time::Instant;

use anyhow::Context;
use emg_control::{CheckRollout, PathShape, Task, Termination, Tracking, path_tasks};
use emg_eval::{BoundShare, bound_shares};
use emg_io::TrajectoryContents;
use emg_planner::{
    ControllerKind, DEFAULT_RATE_HZ, FAR_END_SHARE, MotionTiming, PlanFiles, PlanRecord,
    PlanRequest, Planner, PlannerConfig, SHORTFALL_SHARE,
};
use rayon::prelude::*;
use serde::{Deserialize, Serialize};

use crate::results::{SummaryPlace, shipped_results};
use crate::task_set_options::{ROBOT_WITH_JOINT_LIMITS, THREADS_TIMED, TaskSetOptions};
use crate::{progress, workspace};

/// The markers around the table of [`readme_table`] in `docs/results/summary.md` (written there
/// by `cargo xtask report`, [`crate::workspace::RESULTS_SUMMARY`]).
const README_START: &str = "<!-- precision:start -->";
/// See [`README_START`].
const README_END: &str = "<!-- precision:end -->";

/// Where the precision table ([`readme_table`]) is shown: the results summary.
pub const SUMMARY: SummaryPlace = SummaryPlace::in_results_summary(
    README_START,
    README_END,
    "## Precision: 20 mm, 0.5 mm and 0.1 mm\n\nThe search with the paper's step and the \
         corrected one at each tolerance, on lines and paths (`cargo xtask precision-eval`; \
         `docs/results/precision.md` per arm):\n\n",
);

/// The tolerances compared (mm): the paper's benchmark, then two a cell uses.
pub const TOLERANCES_MM: [f64; 3] = [20.0, 0.5, 0.1];

/// The tolerance (mm) at which the search also runs without its learned parts.
const UNLEARNED_TOLERANCE_MM: f64 = 0.5;

/// Options of `precision-eval`.
#[derive(clap::Args)]
#[command(
    mut_arg("threads", |arg| arg.help(THREADS_TIMED)),
    mut_arg("robot", |arg| arg.help(ROBOT_WITH_JOINT_LIMITS)),
    mut_arg("out_dir", |arg| arg.help("Output directory of precision.{json,md}")),
)]
pub struct Args {
    /// Lines: the first this many tasks of the task set.
    #[arg(long, default_value_t = 400)]
    tasks: usize,
    /// Paths: one from each of the first this many tasks (the path population of `path-eval`).
    #[arg(long, default_value_t = 200)]
    paths: usize,
    /// Seed of the path population's sizes and sides (`path-eval`'s).
    #[arg(long, default_value_t = 20_261_126)]
    seed: u64,
    /// Worker threads, task set, robot file and output directory.
    #[command(flatten)]
    common: TaskSetOptions,
}

/// What a row plans with.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct Setting {
    /// The line tolerance (mm).
    pub tolerance_mm: f64,
    /// The step.
    pub tracking: Tracking,
    /// Whether the search uses its learned parts (the hybrid's policy, the diffusion seeder's
    /// samples); without them it runs its classical controller and no samples.
    pub learned: bool,
}

impl Setting {
    /// The settings compared on `kind`: each tolerance with both steps, and on lines the
    /// corrected step without the learned parts at [`UNLEARNED_TOLERANCE_MM`].
    fn all(kind: Kind) -> Vec<Self> {
        let mut settings: Vec<Self> = TOLERANCES_MM
            .iter()
            .flat_map(|&tolerance_mm| {
                [Tracking::FirstOrder, Tracking::Corrected].map(|tracking| Self {
                    tolerance_mm,
                    tracking,
                    learned: true,
                })
            })
            .collect();
        if kind == Kind::Lines {
            settings.push(Self {
                tolerance_mm: UNLEARNED_TOLERANCE_MM,
                tracking: Tracking::Corrected,
                learned: false,
            });
        }
        settings
    }

    /// The paper's protocol (no work surface) at this setting.
    pub(crate) fn config(&self) -> PlannerConfig {
        let mut config = PlannerConfig::default();
        config.rollout.constraints.line_tolerance_m = self.tolerance_mm * 1e-3;
        config.rollout.tracking = self.tracking;
        if !self.learned {
            config.search.dp_samples = 0;
        }
        config
    }

    /// `emg plan`'s default request, or its classical controller without the learned parts.
    pub(crate) fn request(&self) -> PlanRequest {
        PlanRequest {
            controller: if self.learned {
                PlanRequest::default().controller
            } else {
                ControllerKind::Classical
            },
            ..PlanRequest::default()
        }
    }

    fn step_name(&self) -> &'static str {
        match (self.tracking, self.learned) {
            (Tracking::FirstOrder, _) => "paper",
            (Tracking::Corrected, true) => "corrected",
            (Tracking::Corrected, false) => "corrected, no learned parts",
        }
    }
}

/// Lines or paths.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Kind {
    /// The evaluation set's line tasks.
    Lines,
    /// The path population.
    Paths,
}

/// One setting over one kind of task.
#[derive(Serialize, Deserialize)]
pub struct Row {
    /// Lines or paths.
    pub kind: Kind,
    /// What it planned with.
    pub setting: Setting,
    /// `Σ plan / Σ bound` per bucket of the bound at this tolerance, then over all tasks.
    pub bound_shares: Vec<BoundShare>,
    /// Motions that the line tolerance ended.
    pub ended_by_line_tolerance: usize,
    /// Of those, the motions that ended more than one grid step of the scan (its resolution)
    /// short of the bound: where the step's own tracking ended them, not the end of the arm's
    /// reach along the line or path.
    pub ended_by_line_tolerance_short: usize,
    /// Tasks whose plan ends below the shortfall share of its bound with no chain of valid
    /// configurations joining `p0` to near the bound's end (the bound's continuity test,
    /// `emg_planner::BoundNote::likely_loose`: the bound is likely loose there), in task order;
    /// tested on the rows whose plans are written as `emg plan` writes them (the corrected step
    /// with learned parts), empty on the others.
    pub bound_likely_loose: Vec<usize>,
    /// Paths planned to their end (lines: 0).
    pub completed: usize,
    /// Plans, timed motions or files the independent checker rejected.
    pub checker_failures: usize,
    /// Mean time per plan on its thread (ms).
    pub plan_ms_mean: f64,
    /// Every task's planned length (m), in task order.
    pub lengths_m: Vec<f64>,
}

/// A path the corrected step completes at 20 mm and not at the tightest tolerance.
#[derive(Serialize, Deserialize)]
pub struct Unfinished {
    /// Index in the path population.
    pub index: usize,
    /// Its shape.
    pub shape: PathShape,
    /// Its length (m).
    pub length_m: f64,
    /// What the corrected step reaches at the tightest tolerance (m).
    pub reached_m: f64,
    /// The bound at the tightest tolerance (m).
    pub bound_m: f64,
}

/// The whole record written to `precision.json`.
#[derive(Serialize, Deserialize)]
pub struct Record {
    /// Robot name.
    pub robot: String,
    /// The command that wrote the record.
    pub command: String,
    /// Task set.
    pub tasks: String,
    /// Lines planned (the first of the set) and paths (one from each of the first tasks).
    pub line_count: usize,
    /// See `line_count`.
    pub path_count: usize,
    /// Seed of the path population.
    pub seed: u64,
    /// Machine and worker threads.
    pub machine: String,
    /// See `machine`.
    pub threads: usize,
    /// Every row.
    pub rows: Vec<Row>,
    /// The bound of every line at each tolerance of [`TOLERANCES_MM`] (m): the scan's,
    /// raised to the longest plan of any row at that tolerance.
    pub line_bounds_m: Vec<Vec<f64>>,
    /// The same for the paths (capped at each path's length).
    pub path_bounds_m: Vec<Vec<f64>>,
    /// Paths the corrected step completes at 20 mm and not at 0.1 mm.
    pub unfinished_at_tightest: Vec<Unfinished>,
    /// The grid step of the reachability scan (m), its resolution.
    pub grid_m: f64,
    /// The first few checker failures.
    pub failure_examples: Vec<String>,
}

/// One task planned at one setting.
struct Outcome {
    length_m: f64,
    bound_m: f64,
    ended_by_line_tolerance: bool,
    bound_likely_loose: bool,
    completed: bool,
    plan_ms: f64,
    failures: Vec<String>,
}

/// Plans every line and path at every setting; writes the record and its table.
pub fn run(args: &Args) -> anyhow::Result<()> {
    let workspace::PlannerSetup {
        planner,
        checker,
        tasks,
    } = args
        .common
        .planner_setup(args.tasks.max(args.paths), "precision-eval")?;
    let lines: Vec<Task> = tasks[..args.tasks].to_vec();
    let paths = path_tasks(planner.robot(), &tasks[..args.paths], args.seed)?;
    let path_only: Vec<Task> = paths.iter().map(|(_, task)| task.clone()).collect();
    let pool = workspace::thread_pool(args.common.threads)?;
    let robot_name = args.common.robot.display().to_string();

    let grid_m = planner.config().reach.grid_m;
    let mut rows = Vec::new();
    let mut bounds = [Vec::new(), Vec::new()];
    let mut failures = Vec::new();
    for (kind, set) in [(Kind::Lines, &lines), (Kind::Paths, &path_only)] {
        let settings = Setting::all(kind);
        let bar = progress::bar(
            (settings.len() * set.len()) as u64,
            match kind {
                Kind::Lines => "lines",
                Kind::Paths => "paths",
            },
        );
        let mut outcomes = Vec::new();
        for setting in &settings {
            let planner = planner.with_config(setting.config())?;
            let (timing, _) =
                workspace::motion_timing(&planner, &args.common.robot, DEFAULT_RATE_HZ)?;
            let planned: Vec<Outcome> = pool.install(|| {
                set.par_iter()
                    .map(|task| {
                        let outcome =
                            plan_one(&planner, &checker, &timing, &robot_name, setting, task);
                        bar.inc(1);
                        outcome
                    })
                    .collect::<anyhow::Result<_>>()
            })?;
            outcomes.push(planned);
        }
        bar.finish();
        let kind_bounds = tolerance_bounds(kind, set, &settings, &outcomes);
        for (setting, planned) in settings.iter().zip(outcomes) {
            failures.extend(planned.iter().flat_map(|o| o.failures.iter().cloned()));
            rows.push(Row::of(kind, *setting, &planned, &kind_bounds, grid_m));
        }
        bounds[kind as usize] = kind_bounds;
    }
    let [line_bounds_m, path_bounds_m] = bounds;
    let unfinished_at_tightest = unfinished(&rows, &paths, &path_bounds_m);
    let record = Record {
        robot: planner.robot().name().to_string(),
        command: workspace::command_for("precision-eval", &args.common.robot),
        tasks: workspace::relative(&args.common.task_file),
        line_count: args.tasks,
        path_count: args.paths,
        seed: args.seed,
        machine: workspace::machine(),
        threads: pool.current_num_threads(),
        rows,
        line_bounds_m,
        path_bounds_m,
        unfinished_at_tightest,
        grid_m,
        failure_examples: failures.iter().take(5).cloned().collect(),
    };
    workspace::write_results(
        &args.common.out_dir,
        "precision",
        &record,
        &markdown(&record),
    )?;
    anyhow::ensure!(
        failures.is_empty(),
        "{} checks fail, e.g. {}",
        failures.len(),
        failures[0]
    );
    Ok(())
}

/// The bound of each task of `set` at each compared tolerance: the scan's, raised to every plan
/// at that tolerance (`outcomes` per setting of `settings`); a path's no longer than the path.
fn tolerance_bounds(
    kind: Kind,
    set: &[Task],
    settings: &[Setting],
    outcomes: &[Vec<Outcome>],
) -> Vec<Vec<f64>> {
    TOLERANCES_MM
        .iter()
        .map(|&tolerance_mm| {
            (0..set.len())
                .map(|i| {
                    let at = settings
                        .iter()
                        .zip(outcomes)
                        .filter(|(setting, _)| setting.tolerance_mm == tolerance_mm);
                    let bound = at
                        .map(|(_, planned)| planned[i].bound_m.max(planned[i].length_m))
                        .fold(0.0, f64::max);
                    match kind {
                        Kind::Lines => bound,
                        Kind::Paths => bound.min(set[i].length_m().unwrap_or(bound)),
                    }
                })
                .collect()
        })
        .collect()
}

impl Row {
    /// The row of `setting` over the tasks `planned`, beside their bounds per tolerance
    /// (`bounds`, [`tolerance_bounds`]); a line motion the tolerance ended more than `grid_m`
    /// short of its bound counts as short.
    fn of(
        kind: Kind,
        setting: Setting,
        planned: &[Outcome],
        bounds: &[Vec<f64>],
        grid_m: f64,
    ) -> Self {
        let tolerance = TOLERANCES_MM
            .iter()
            .position(|&t| t == setting.tolerance_mm)
            .expect("a compared tolerance");
        let lengths: Vec<f64> = planned.iter().map(|o| o.length_m).collect();
        Self {
            kind,
            setting,
            bound_shares: bound_shares(&lengths, &bounds[tolerance], &bounds[tolerance]),
            ended_by_line_tolerance: planned.iter().filter(|o| o.ended_by_line_tolerance).count(),
            ended_by_line_tolerance_short: planned
                .iter()
                .zip(&bounds[tolerance])
                .filter(|(o, bound)| o.ended_by_line_tolerance && *bound - o.length_m > grid_m)
                .count(),
            bound_likely_loose: (0..planned.len())
                .filter(|&i| planned[i].bound_likely_loose)
                .collect(),
            completed: planned.iter().filter(|o| o.completed).count(),
            checker_failures: planned.iter().map(|o| o.failures.len()).sum(),
            plan_ms_mean: planned.iter().map(|o| o.plan_ms).sum::<f64>()
                / planned.len().max(1) as f64,
            lengths_m: lengths,
        }
    }
}

/// Plans `task` at `setting`, checks the plan and, under the corrected step, its timed files.
fn plan_one(
    planner: &Planner,
    checker: &emg_verify::ReferenceModel,
    timing: &MotionTiming,
    robot_name: &str,
    setting: &Setting,
    task: &Task,
) -> anyhow::Result<Outcome> {
    let request = setting.request();
    let constraints = &planner.config().rollout.constraints;
    let started = Instant::now();
    let plan = planner.plan(task, &request)?;
    let plan_ms = started.elapsed().as_secs_f64() * 1e3;
    let reach = planner.reach_of(task, &plan);
    let mut failures = Vec::new();
    let what = format!(
        "{} mm, {} step, task {}",
        setting.tolerance_mm,
        setting.step_name(),
        serde_json::to_string(task).unwrap_or_default()
    );
    if let Err(problem) = checker.check(task, &plan.trajectory, constraints) {
        failures.push(format!("{what}: {problem}"));
    }
    let mut bound_likely_loose = false;
    if setting.tracking == Tracking::Corrected && setting.learned {
        let bound = planner.bound_note(task, &plan);
        bound_likely_loose = bound.likely_loose;
        let record = PlanRecord {
            robot: robot_name,
            request: &request,
            bound: Some(&bound),
            timing,
        };
        let files = PlanFiles::new(planner, task, &plan, &record)
            .with_context(|| format!("{what}: timing"))?;
        let verified = TrajectoryContents::parse(&files.joint_trajectory)
            .map_err(|e| e.to_string())
            .and_then(|contents| {
                contents
                    .verify(
                        checker,
                        planner.robot().joint_names(),
                        task,
                        constraints,
                        true,
                        None,
                    )
                    .map(|_| ())
                    .map_err(|e| e.to_string())
            });
        if let Err(problem) = verified {
            failures.push(format!("{what}, joint trajectory file: {problem}"));
        }
    }
    Ok(Outcome {
        length_m: plan.trajectory.path_length_m,
        bound_m: reach.reachable_m,
        ended_by_line_tolerance: plan.trajectory.termination.label() == "line_tolerance",
        bound_likely_loose,
        completed: plan.trajectory.termination == Termination::Completed,
        plan_ms,
        failures,
    })
}

/// The paths the corrected step completes at 20 mm and not at the tightest tolerance.
fn unfinished(
    rows: &[Row],
    paths: &[(PathShape, Task)],
    path_bounds_m: &[Vec<f64>],
) -> Vec<Unfinished> {
    let corrected = |tolerance_mm: f64| {
        rows.iter().find(|row| {
            row.kind == Kind::Paths
                && row.setting.tracking == Tracking::Corrected
                && row.setting.tolerance_mm == tolerance_mm
        })
    };
    let tightest = TOLERANCES_MM.len() - 1;
    let (Some(loose), Some(tight)) = (
        corrected(TOLERANCES_MM[0]),
        corrected(TOLERANCES_MM[tightest]),
    ) else {
        return Vec::new();
    };
    let ends = |reached: f64, length: f64| reached >= length - 2.0 * emg_control::ARRIVAL_M;
    paths
        .iter()
        .enumerate()
        .filter_map(|(index, (shape, task))| {
            let length_m = task.length_m()?;
            (ends(loose.lengths_m[index], length_m) && !ends(tight.lengths_m[index], length_m))
                .then(|| Unfinished {
                    index,
                    shape: *shape,
                    length_m,
                    reached_m: tight.lengths_m[index],
                    bound_m: path_bounds_m[tightest][index],
                })
        })
        .collect()
}

fn markdown(record: &Record) -> String {
    let mut md = format!(
        "# Precision: the search at 20 mm, 0.5 mm and 0.1 mm ({})\n\n\
         Generated by `{}` on {} ({} threads). Lines: the first {} tasks of `{}`; paths: the \
         path population of `path-eval` (one rectangle, circle, arc or S-curve from each of the \
         first {} tasks' starts, seed {}). Every plan is `emg plan`'s default search \
         (hybrid controller, diffusion samples among its starts, default budget) in the paper's \
         protocol (no work surface), with the line tolerance of its row and a 30° cone. The \
         *paper* step is Eq. 2's explicit step, whose motion ends where its TCP lands outside \
         the tolerance; the *corrected* step (`emg plan`'s) moves a step that lands more than \
         half the tolerance off the line or path back onto it (`emg_control::Tracking`). \
         *No learned parts*: the search with its classical controller and no diffusion \
         samples. The bound is the reachability scan at the row's tolerance, raised to the \
         longest plan of any row at that tolerance. Every plan passed the independent checker, \
         and every plan of the corrected step with learned parts was also timed rest to rest \
         and its joint trajectory file verified as `emg check` verifies it: {} failures.\n\n",
        record.robot,
        record.command,
        record.machine,
        record.threads,
        record.line_count,
        record.tasks,
        record.path_count,
        record.seed,
        record
            .rows
            .iter()
            .map(|r| r.checker_failures)
            .sum::<usize>(),
    );
    for kind in [Kind::Lines, Kind::Paths] {
        md.push_str(&kind_section(record, kind));
    }
    md.push_str(&unfinished_section(record));
    md
}

/// The section of the lines or of the paths: per row its shares of the bound per bucket, the
/// motions the tolerance ended, the plan time and the checker's failures, then the loose
/// bounds; empty where no row planned `kind`.
fn kind_section(record: &Record, kind: Kind) -> String {
    let rows: Vec<&Row> = record.rows.iter().filter(|r| r.kind == kind).collect();
    let Some(first) = rows.first() else {
        return String::new();
    };
    let buckets: Vec<String> = first
        .bound_shares
        .iter()
        .map(|b| b.bucket.clone())
        .collect();
    let mut md = String::from(match kind {
        Kind::Lines => "## Lines\n\n",
        Kind::Paths => "## Paths\n\n",
    });
    md.push_str(
        "Σ plan / Σ bound per bucket of the bound at the row's tolerance (tasks in the \
         bucket in brackets), the motions the line tolerance ended and, of them, those it \
         ended more than one grid step of the scan (1 cm) short of the bound (the others \
         end where the scan found no valid configuration one grid step further: the end of \
         the arm's reach along the line or path)",
    );
    md.push_str(match kind {
        Kind::Lines => ", and the mean plan time on its thread.\n\n",
        Kind::Paths => ", the paths planned to their end, and the mean plan time.\n\n",
    });
    md.push_str("| tolerance | step |");
    for bucket in &buckets {
        md.push_str(&format!(" {bucket} |"));
    }
    md.push_str(" ended by the tolerance | of them short of the bound |");
    if kind == Kind::Paths {
        md.push_str(" completed |");
    }
    md.push_str(" ms per plan | checker failures |\n|---|---|");
    md.push_str(&"---|".repeat(buckets.len() + 4 + usize::from(kind == Kind::Paths)));
    md.push('\n');
    for row in rows {
        let total = row.lengths_m.len().max(1);
        md.push_str(&format!(
            "| {} mm | {} |",
            row.setting.tolerance_mm,
            row.setting.step_name()
        ));
        for share in &row.bound_shares {
            md.push_str(&format!(" {:.3} ({}) |", share.share, share.tasks));
        }
        for ended in [
            row.ended_by_line_tolerance,
            row.ended_by_line_tolerance_short,
        ] {
            md.push_str(&format!(
                " {ended} ({:.1} %) |",
                100.0 * ended as f64 / total as f64
            ));
        }
        if kind == Kind::Paths {
            md.push_str(&format!(" {} of {} |", row.completed, row.lengths_m.len()));
        }
        md.push_str(&format!(
            " {:.1} | {} |\n",
            row.plan_ms_mean, row.checker_failures
        ));
    }
    md.push('\n');
    md.push_str(&loose_bounds(record, kind));
    md
}

/// The section of the paths the corrected step completes at 20 mm and not at the tightest
/// tolerance, each with what its bound says.
fn unfinished_section(record: &Record) -> String {
    let mut md = String::from("## Paths completed at 20 mm and not at 0.1 mm (corrected step)\n\n");
    if record.unfinished_at_tightest.is_empty() {
        md.push_str(
            "None: every path the corrected step completes at 20 mm it completes at 0.1 mm.\n",
        );
    } else {
        md.push_str(
            "The bound at 0.1 mm says whether the path can be finished at all: where it lies \
             within one grid step of the scan (1 cm) of what was reached, no valid configuration \
             was found further along.\n\n\
             | path | shape | length (m) | reached at 0.1 mm (m) | bound at 0.1 mm (m) | the \
             bound says |\n\
             |---|---|---|---|---|---|\n",
        );
        for path in &record.unfinished_at_tightest {
            md.push_str(&format!(
                "| {} | {} | {:.4} | {:.4} | {:.4} | {} |\n",
                path.index,
                path.shape.name(),
                path.length_m,
                path.reached_m,
                path.bound_m,
                if path.bound_m - path.reached_m > record.grid_m {
                    "reachable further"
                } else {
                    "cannot"
                }
            ));
        }
    }
    md
}

/// What the bound's continuity test says of the rows that ran it: the tasks whose plan ends
/// short of a bound no chain of valid configurations joins (likely loose), and `Σ plan / Σ
/// bound` over the other tasks.
fn loose_bounds(record: &Record, kind: Kind) -> String {
    let bounds = match kind {
        Kind::Lines => &record.line_bounds_m,
        Kind::Paths => &record.path_bounds_m,
    };
    let mut md = String::new();
    for row in record.rows.iter().filter(|r| {
        r.kind == kind && r.setting.tracking == Tracking::Corrected && r.setting.learned
    }) {
        let Some(tolerance) = TOLERANCES_MM
            .iter()
            .position(|&t| t == row.setting.tolerance_mm)
        else {
            continue;
        };
        let bound = &bounds[tolerance];
        let others: Vec<usize> = (0..row.lengths_m.len())
            .filter(|i| !row.bound_likely_loose.contains(i))
            .collect();
        let sum = |values: &[f64], tasks: &mut dyn Iterator<Item = usize>| {
            tasks.map(|i| values[i]).sum::<f64>()
        };
        if row.bound_likely_loose.is_empty() {
            md.push_str(&format!(
                "At {} mm with the corrected step, the bound's continuity test (`emg plan`'s \
                 note on a plan below {SHORTFALL_SHARE} × its bound) finds a chain of valid \
                 configurations joining `p0` to {:.0} % of the bound on every task that ends \
                 short of it.\n\n",
                row.setting.tolerance_mm,
                100.0 * FAR_END_SHARE,
            ));
            continue;
        }
        let loose_bound = sum(bound, &mut row.bound_likely_loose.iter().copied());
        let loose_plan = sum(&row.lengths_m, &mut row.bound_likely_loose.iter().copied());
        let share = sum(&row.lengths_m, &mut others.iter().copied())
            / sum(bound, &mut others.iter().copied());
        md.push_str(&format!(
            "At {} mm with the corrected step, the bound's continuity test (`emg plan`'s note \
             on a plan below {SHORTFALL_SHARE} × its bound) finds no chain of valid \
             configurations joining `p0` to {:.0} % of the bound on {} of {} tasks (the bound \
             likely loose there): {loose_plan:.2} m planned of their Σ {loose_bound:.2} m bound. \
             Σ plan / Σ bound over the other tasks: {share:.3}.\n\n",
            row.setting.tolerance_mm,
            100.0 * FAR_END_SHARE,
            row.bound_likely_loose.len(),
            row.lengths_m.len(),
        ));
    }
    md
}

/// One row per shipped arm, tolerance and step of every `precision.json` under `results`:
/// Σ plan / Σ bound over all lines and all paths, the share of line motions the tolerance ended,
/// the paths completed, checker failures.
pub fn readme_table(results: &Path) -> anyhow::Result<String> {
    let mut md = String::from(
        "| arm | tolerance | step | lines: Σ plan / Σ bound | lines ended by the tolerance | \
         of them short of the bound | paths: Σ plan / Σ bound | paths completed | checker \
         failures |\n\
         |---|---|---|---|---|---|---|---|---|\n",
    );
    for (shipped, record) in shipped_results::<Record>(results, "precision.json")? {
        let rows_of = |kind: Kind| record.rows.iter().filter(move |r| r.kind == kind);
        for line in rows_of(Kind::Lines).filter(|r| r.setting.learned) {
            let path = rows_of(Kind::Paths).find(|r| r.setting == line.setting);
            let all = |row: &Row| {
                row.bound_shares
                    .iter()
                    .find(|b| b.bucket == "all")
                    .map_or(f64::NAN, |b| b.share)
            };
            md.push_str(&format!(
                "| {} | {} mm | {} | {:.3} | {:.1} % | {:.1} % | {} | {} | {} |\n",
                shipped.name,
                line.setting.tolerance_mm,
                line.setting.step_name(),
                all(line),
                100.0 * line.ended_by_line_tolerance as f64 / line.lengths_m.len().max(1) as f64,
                100.0 * line.ended_by_line_tolerance_short as f64
                    / line.lengths_m.len().max(1) as f64,
                path.map_or("—".to_string(), |p| format!("{:.3}", all(p))),
                path.map_or("—".to_string(), |p| format!(
                    "{} of {}",
                    p.completed,
                    p.lengths_m.len()
                )),
                line.checker_failures + path.map_or(0, |p| p.checker_failures),
            ));
        }
    }
    Ok(md)
}
