//! `emg plan`: straight-line motions (or paths) planned task by task, each written as soon as it
//! is planned: the trajectory files, and on request the viewer page and an export.

mod export;
mod models;
mod refusal;
mod tasks;
mod viewer;

use std::path::{Path, PathBuf};
use std::str::FromStr;

use anyhow::Result;
use clap::Args;
use emg_control::Task;
use emg_io::{PlanPaths, html_path};
use emg_kinematics::WorkSurface;
use emg_planner::{
    ControllerKind, Models, MotionTiming, Plan, PlanError, PlanFiles, PlanRecord, PlanRequest,
    Planner, PlannerConfig, PlannerKind, SeedError, SeedSource,
};

use self::export::PlanExportArgs;
use self::tasks::TaskArgs;
use crate::config::{inline_json, read_config};
use crate::interrupt::Interrupt;
use crate::options::{self, ChainArgs, ScalingArgs};
use crate::output;
use crate::report::error_text;
use crate::robot;

/// Options of `emg plan`.
#[derive(Debug, Args)]
pub struct PlanArgs {
    /// Robot: a shipped robot's name (`fr3`, the default, `iiwa14` or `ur5e`) or a robot file
    /// (URDF) of any serial arm of six or seven revolute joints.
    #[arg(long, value_name = "NAME|URDF", value_parser = robot::parse_robot,
          default_value = "fr3")]
    pub robot: PathBuf,
    /// The kinematic chain's ends.
    #[command(flatten)]
    pub chain: ChainArgs,
    /// What to plan: a line, a task file or a path.
    #[command(flatten)]
    pub tasks: TaskArgs,
    /// Seed source: `dp` (the diffusion seeder), `generating` (the task's q0_seed), `home`
    /// (mid-range of the joint limits), `q_mu` / `q_jl` (heuristic ascents from q0_seed) or
    /// `q=v1,...,vN` (radians, one per joint). Default: `dp` when the --weights file exists,
    /// else `generating` when the task has a q0_seed, else `home`.
    #[arg(long, value_name = "SOURCE", value_parser = SeedSource::from_str, allow_hyphen_values = true)]
    pub seed: Option<SeedSource>,
    /// Diffusion-seeder weights for `--seed dp` (default: those shipped for a shipped robot).
    #[arg(long, value_name = "WEIGHTS")]
    pub weights: Option<PathBuf>,
    /// Planner configuration: a JSON file, or the JSON itself when the value starts with `{`
    /// (e.g. `--config '{"search": {"budget_steps": 50000}}'`). Any of `rollout` (with
    /// `constraints`), `gains`, `switch`, `measure`, `reach` and `search`; unset fields keep
    /// their defaults (the work plate on). The schema is emg_planner's PlannerConfig,
    /// documented in docs/ARCHITECTURE.md.
    #[arg(long, value_name = "FILE|JSON")]
    pub config: Option<PathBuf>,
    /// Output path stem: writes STEM.json and STEM.csv (the planned path) and
    /// STEM.joint_trajectory.json (the motion timed rest to rest within the joint limits)
    /// (STEM-00000.json, ... for a task file holding several tasks); missing parent directories
    /// are created.
    #[arg(long, value_name = "STEM", default_value = "trajectory")]
    pub out: PathBuf,
    /// Also write a self-contained HTML page that animates the planned motion in 3D (for a
    /// task file holding several tasks: PATH-00000.html, ..., the extension kept).
    #[arg(long, value_name = "PATH")]
    pub html: Option<PathBuf>,
    /// Planner: `search` (the pipeline's plan first, then many candidate starts ranked by
    /// rollouts and detours repairing the longest, within the config's `search.budget_steps`;
    /// never shorter than the pipeline's plan) or `controller` (the paper's pipeline: one seed,
    /// one rollout).
    #[arg(long, value_name = "NAME", value_parser = PlannerKind::from_str, default_value = "search")]
    pub planner: PlannerKind,
    /// Null-space controller: `classical` (Eq. 3), `rl` (the PPO policy, Sec. 4.2) or `hybrid`
    /// (learned inside, classical near the joint limits, Sec. 4.3). Default: `hybrid` when a
    /// policy is trained for the robot (--policy or the shipped one), else `classical`.
    #[arg(long, value_name = "NAME", value_parser = ControllerKind::from_str)]
    pub controller: Option<ControllerKind>,
    /// Policy weights of `--controller rl` and `hybrid` (default: those shipped for a shipped
    /// robot).
    #[arg(long, value_name = "WEIGHTS")]
    pub policy: Option<PathBuf>,
    /// The part the line is drawn on, which the arm, all but the pen, keeps off: `plate` (a
    /// plate under the line, its top face in the plane through p0 with normal n: 0.2 m wide,
    /// from 0.05 m behind p0 to 2 m beyond, or less where it would meet the arm's base, 0.05 m
    /// thick; under a path it covers the path with those margins; the config's
    /// `rollout.constraints.work_surface` sets other sizes), `half-space` (everything beyond
    /// that plane) or `off` (the paper's protocol). Default: the --config file's
    /// `work_surface` when it sets one, else `plate`.
    #[arg(long, value_name = "plate|half-space|off", value_parser = WorkSurface::from_str)]
    pub surface: Option<WorkSurface>,
    /// How far the tool may leave the line or path (mm): the line tolerance of every step, of
    /// the bound, of the timed motion and of the checker. Default: the --config file's
    /// `rollout.constraints.line_tolerance_m`, else 20 mm (the paper's benchmark; a pen or a
    /// bead wants 0.5 mm or less).
    #[arg(long, value_name = "MM", value_parser = options::tolerance_mm, allow_hyphen_values = true)]
    pub tolerance: Option<f64>,
    /// Half-angle of the cone around the surface normal the tool axis stays in (degrees).
    /// Default: the --config file's `rollout.constraints.theta_max_deg`, else 30°.
    #[arg(long, value_name = "DEG", value_parser = options::cone_deg, allow_hyphen_values = true)]
    pub cone: Option<f64>,
    /// Scene file (JSON) of obstacles the whole arm, pen included, keeps clear of: half-spaces,
    /// boxes, spheres and capsules in the base frame, each with its clearance (see
    /// docs/scene.md). Replaces the --config file's `rollout.constraints.scene`.
    #[arg(long, value_name = "JSON")]
    pub scene: Option<PathBuf>,
    /// Also scan the task's reachability bound (how far along the line the arm can be placed
    /// at all, on a 1 cm grid), print it beside the path length and record it as
    /// `reachable_m`.
    #[arg(long, value_name = "on|off", default_value = "on")]
    pub reach: OnOff,
    /// Joint limits the joint trajectory is timed for (MoveIt joint_limits.yaml with velocity,
    /// acceleration and jerk limits). Default: <robot file stem>.joint_limits.yaml beside the
    /// robot file, else the robot file's velocity limits with assumed acceleration and jerk
    /// limits (5 rad/s², 300 rad/s³; said in the output).
    #[arg(long, value_name = "YAML")]
    pub limits: Option<PathBuf>,
    /// Scaling of the joint limits.
    #[command(flatten)]
    pub scaling: ScalingArgs,
    /// Largest tool speed of the timed motion (m/s): the tool moves at it wherever the joints
    /// allow. Default: the rollout's line speed (`rollout.speed_m_per_s`, 0.2).
    #[arg(long, value_name = "M_PER_S")]
    pub tool_speed: Option<f64>,
    /// Samples per second of the joint trajectory (1000 for libfranka).
    #[arg(long, value_name = "HZ", default_value_t = emg_planner::DEFAULT_RATE_HZ)]
    pub rate_hz: f64,
    /// The joint trajectories' export for a robot's own stack.
    #[command(flatten)]
    pub export: PlanExportArgs,
}

/// A feature switched on or off on the command line.
#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
pub enum OnOff {
    /// Enabled.
    On,
    /// Disabled.
    Off,
}

impl PlanArgs {
    /// The diffusion-seeder weights: `--weights`, else those shipped for the robot (if any).
    pub fn weights_path(&self) -> Option<PathBuf> {
        self.weights
            .clone()
            .or_else(|| robot::shipped_model(&self.robot, emg_planner::DIFFUSION_WEIGHTS_FILE))
    }

    /// The policy weights: `--policy`, else those shipped for the robot (if any).
    pub fn policy_path(&self) -> Option<PathBuf> {
        self.policy
            .clone()
            .or_else(|| robot::shipped_model(&self.robot, emg_planner::POLICY_WEIGHTS_FILE))
    }
}

/// What every task of a run is planned with.
struct Run {
    /// The planner, its robot and its configuration.
    planner: Planner,
    /// The planner, seed and controller asked for.
    request: PlanRequest,
    /// How the joint trajectories are timed.
    timing: MotionTiming,
}

/// Why a task was not planned.
enum Unplanned {
    /// Refused at its start: invalid, or no start holds every constraint.
    Refused(String),
    /// Planning or writing it failed.
    Failed(anyhow::Error),
}

/// The tasks of a run not planned, each with its index and why.
#[derive(Default)]
struct Shortfall {
    refused: Vec<(usize, String)>,
    failed: Vec<(usize, String)>,
}

/// Plans every task `args` ask for and writes each one's files as soon as it is planned; with
/// several tasks a refused or failed one is reported and the rest still run. A signal stops the
/// run between tasks.
pub fn run(args: &PlanArgs) -> Result<()> {
    let interrupt = Interrupt::install()?;
    let robot = args.chain.load_robot(&args.robot)?;
    let config = planner_config(args)?;
    let controller = models::controller(args.controller, args.policy_path().as_deref());
    let models = Models::load(
        &robot,
        models::diffusion_weights(args.seed.as_ref(), args.weights_path(), &args.robot)?.as_deref(),
        models::policy_weights(controller, args.policy_path(), &args.robot)?.as_deref(),
    )?;
    let tasks = args.tasks.requested(&robot)?;
    let indices = file_indices(tasks.len());
    refuse_overwriting_inputs(args, &indices)?;
    args.export
        .refuse(&args.robot, &robot, &args.out, &indices)?;
    let timing = motion_timing(args, &robot, &config)?;
    let run = Run {
        planner: Planner::new(robot, models, config)?,
        request: PlanRequest {
            planner: args.planner,
            seed: args.seed.clone(),
            controller,
        },
        timing,
    };
    print_assumptions(args, &run);
    let many = tasks.len() > 1;
    let mut shortfall = Shortfall::default();
    for (index, task) in tasks.iter().enumerate() {
        if let Some(stop) = interrupt.received() {
            let unplanned = shortfall.refused.len() + shortfall.failed.len();
            return Err(anyhow::Error::new(stop).context(format!(
                "{} of {} planned and written whole, {} refused, {} failed; the rest were not \
                 started",
                index - unplanned,
                output::count(tasks.len(), "task"),
                shortfall.refused.len(),
                shortfall.failed.len()
            )));
        }
        let label = if many {
            format!("task {index}: ")
        } else {
            String::new()
        };
        let written = plan_task(&run, args, task).and_then(|(task, plan)| {
            write_plan(&run, args, task, &plan, many.then_some(index)).map_err(Unplanned::Failed)
        });
        match written {
            Ok(report) => println!("{label}{report}"),
            Err(Unplanned::Refused(reason)) => {
                anyhow::ensure!(many, "refused, nothing written: {reason}");
                eprintln!("{label}refused, nothing written: {reason}");
                shortfall.refused.push((index, reason));
            }
            Err(Unplanned::Failed(error)) if !many => return Err(error),
            Err(Unplanned::Failed(error)) => {
                let text = error_text(&error);
                eprintln!("{label}error: {text}");
                shortfall.failed.push((index, text));
            }
        }
    }
    shortfall.into_result(tasks.len())
}

impl Shortfall {
    /// Success when every one of `tasks` tasks was planned, else the error listing those that
    /// were not.
    fn into_result(self, tasks: usize) -> Result<()> {
        if self.refused.is_empty() && self.failed.is_empty() {
            return Ok(());
        }
        let mut summary = format!(
            "{} of {} tasks planned; {} refused at their start, {} failed:",
            tasks - self.refused.len() - self.failed.len(),
            tasks,
            self.refused.len(),
            self.failed.len()
        );
        for (index, reason) in self.refused.iter().chain(&self.failed) {
            summary.push_str(&format!("\n  task {index}: {reason}"));
        }
        Err(anyhow::anyhow!(summary))
    }
}

/// Plans one task: the task and its plan, or why it was not planned (refused at its start:
/// invalid, or no start holds; or failed).
fn plan_task<'a>(
    run: &Run,
    args: &PlanArgs,
    task: &'a Result<Task, String>,
) -> Result<(&'a Task, Plan), Unplanned> {
    let task = task
        .as_ref()
        .map_err(|reason| Unplanned::Refused(reason.clone()))?;
    let refuse = |violation: Option<&emg_control::Violation>| {
        Unplanned::Refused(refusal::refusal(
            &run.planner,
            &args.robot,
            &run.request,
            task,
            violation,
        ))
    };
    match run.planner.plan(task, &run.request) {
        Ok(plan) => match &plan.trajectory.termination {
            emg_control::Termination::InvalidStart { violation } => Err(refuse(Some(violation))),
            _ => Ok((task, plan)),
        },
        // The search found no configuration at p0 to start from.
        Err(PlanError::Seed(SeedError::Projection { .. }))
            if run.request.planner == PlannerKind::Search =>
        {
            Err(refuse(None))
        }
        Err(error) => Err(Unplanned::Failed(plan_error(error, &run.request))),
    }
}

/// The planner configuration: `--config` (else the cell's), with what `--surface`,
/// `--tolerance`, `--cone` and `--scene` set.
fn planner_config(args: &PlanArgs) -> Result<PlannerConfig> {
    let mut config = match &args.config {
        Some(config) => read_config(config)?,
        None => PlannerConfig::cell(),
    };
    if let Some(surface) = args.surface {
        config.rollout.constraints.work_surface = surface;
    }
    if let Some(tolerance_mm) = args.tolerance {
        config.rollout.constraints.line_tolerance_m = tolerance_mm * 1e-3;
    }
    if let Some(cone_deg) = args.cone {
        config.rollout.constraints.theta_max_deg = cone_deg;
    }
    if let Some(path) = &args.scene {
        config.rollout.constraints.scene = emg_io::read_scene(path)?;
    }
    Ok(config)
}

/// Prints what the run assumes where the user gave nothing: the classical controller for a
/// robot without a policy, joint limits the robot file lacks.
fn print_assumptions(args: &PlanArgs, run: &Run) {
    if args.controller.is_none() && run.request.controller == ControllerKind::Classical {
        println!(
            "controller: classical (no policy is trained for robot {0}; `cargo xtask train-ppo \
             --robot {0}` trains one, --policy loads one)",
            args.robot.display()
        );
    }
    if run.timing.assumed() {
        println!(
            "joint limits: no {} beside the robot file, so the motion is timed with the robot \
             file's velocities and assumed acceleration and jerk limits ({} rad/s², {} rad/s³); \
             `emg import-robot` writes one, --limits reads another",
            emg_planner::limits_file_beside(&args.robot)
                .file_name()
                .unwrap_or_default()
                .to_string_lossy(),
            emg_timing::ASSUMED_ACCELERATION_RAD_S2,
            emg_timing::ASSUMED_JERK_RAD_S3
        );
    }
}

/// The index each task's files are named with: none for a single task (`STEM.json`), else its
/// place in the set (`STEM-00000.json`, ...).
fn file_indices(tasks: usize) -> Vec<Option<usize>> {
    match tasks {
        1 => vec![None],
        many => (0..many).map(Some).collect(),
    }
}

/// Refuses, before anything is planned, a run whose files (`--out`'s, `--html`'s, for each of
/// the tasks' file `indices`) would replace one of its inputs or one another.
fn refuse_overwriting_inputs(args: &PlanArgs, indices: &[Option<usize>]) -> Result<()> {
    let robot_files = [
        emg_kinematics::srdf_beside(&args.robot),
        emg_planner::limits_file_beside(&args.robot),
    ];
    let config_file = args
        .config
        .as_deref()
        .filter(|config| inline_json(config).is_none());
    let weights = args.weights_path();
    let policy = args.policy_path();
    let optional = [
        ("--config", config_file),
        ("--task-file", args.tasks.task_file.as_deref()),
        ("--path", args.tasks.path.as_deref()),
        ("--scene", args.scene.as_deref()),
        ("--limits", args.limits.as_deref()),
        ("--weights", weights.as_deref()),
        ("--policy", policy.as_deref()),
        ("robot's SRDF", Some(robot_files[0].as_path())),
        ("robot's joint limits", Some(robot_files[1].as_path())),
    ];
    let mut inputs = vec![("--robot", args.robot.as_path())];
    inputs.extend(
        optional
            .iter()
            .filter_map(|(name, path)| Some((*name, (*path)?))),
    );
    let files: Vec<(PlanPaths, Option<PathBuf>)> = indices
        .iter()
        .map(|&index| {
            let html = args.html.as_deref().map(|html| html_path(html, index));
            (PlanPaths::new(&args.out, index), html)
        })
        .collect();
    let mut outputs: Vec<(&str, &Path)> = Vec::with_capacity(4 * files.len());
    for (paths, html) in &files {
        for path in [&paths.json, &paths.csv, &paths.joint_trajectory] {
            outputs.push(("--out", path));
        }
        outputs.extend(html.as_deref().map(|html| ("--html", html)));
    }
    Ok(emg_io::refuse_overwriting(&inputs, &outputs)?)
}

/// How the joint trajectories are timed: the limits file (`--limits`, else the one beside the
/// robot file), scaling, tool speed and rate.
fn motion_timing(
    args: &PlanArgs,
    robot: &emg_kinematics::Robot,
    config: &PlannerConfig,
) -> Result<MotionTiming> {
    let tool_speed = args.tool_speed.unwrap_or(config.rollout.speed_m_per_s);
    MotionTiming::for_robot_file(
        robot,
        &args.robot,
        args.limits.as_deref(),
        args.scaling.scaling()?,
        tool_speed,
        args.rate_hz,
        &config.rollout.constraints,
    )
    .map_err(|error| match error {
        emg_planner::TimingSetupError::Request(e) => {
            let option = match &e {
                emg_timing::TimingError::Request {
                    field: "tool_speed_m_per_s",
                    ..
                } => format!("--tool-speed {tool_speed}"),
                emg_timing::TimingError::Request {
                    field: "rate_hz", ..
                } => format!("--rate-hz {}", args.rate_hz),
                _ => "the joint limits".to_string(),
            };
            anyhow::anyhow!("{e}").context(option)
        }
        other => anyhow::Error::new(other),
    })
}

/// A planning error with the option it comes from, and what to try.
fn plan_error(error: PlanError, request: &PlanRequest) -> anyhow::Error {
    let option = match &error {
        PlanError::Seed(_) => match &request.seed {
            Some(seed) => format!("--seed {}", seed.name()),
            None => "the default seed".to_string(),
        },
        PlanError::Controller(_) => format!("--controller {}", request.controller),
    };
    let hint = match (&error, request.planner) {
        (PlanError::Seed(SeedError::Projection { .. }), PlannerKind::Controller) => {
            " (--planner search, the default, goes on from other starts)"
        }
        _ => "",
    };
    anyhow::Error::new(error).context(format!("{option}{hint}"))
}

/// Writes one planned task's files and returns the lines to print.
fn write_plan(
    run: &Run,
    args: &PlanArgs,
    task: &Task,
    plan: &Plan,
    index: Option<usize>,
) -> Result<String> {
    let planner = &run.planner;
    let trajectory = &plan.trajectory;
    let bound = (args.reach == OnOff::On).then(|| planner.bound_note(task, plan));
    let paths = PlanPaths::new(&args.out, index);
    let robot = robot::reference(&args.robot)?.to_string();
    let files = PlanFiles::new(
        planner,
        task,
        plan,
        &PlanRecord {
            robot: &robot,
            request: &run.request,
            bound: bound.as_ref(),
            timing: &run.timing,
        },
    )?;
    files.write(&paths)?;
    let exported = args
        .export
        .after_plan(&args.robot, planner.robot(), &paths)?;
    let timed = &files.timing;
    let cut = match (&timed.cut_at_point, &timed.cut_reason) {
        (Some(point), Some(reason)) => {
            format!("; the smooth path ends at planned point {point} ({reason} beyond it)")
        }
        _ => String::new(),
    };
    let unreached = if timed.tool_speed_share < 0.005 && trajectory.path_length_m > 0.0 {
        format!(
            "\n  note: the joint limits never let the tool reach the requested {} m/s (--tool-speed): \
             it moves as fast as they allow",
            args.tool_speed
                .unwrap_or(planner.config().rollout.speed_m_per_s)
        )
    } else {
        String::new()
    };
    let rests = match timed.rests_s.len() {
        0 => String::new(),
        1 => ", at rest at its corner".to_string(),
        corners => format!(", at rest at each of its {corners} corners"),
    };
    let viewer = match &args.html {
        Some(html) => viewer::write_viewer(
            planner,
            task,
            &viewer::played_as_timed(trajectory, &files.step_times_s),
            &html_path(html, index),
        )?,
        None => String::new(),
    };
    let steps = trajectory.steps.len() - 1;
    let duration = trajectory.steps.last().map_or(0.0, |s| s.time_s);
    let projected = match plan.seed.projection_iterations {
        Some(n) => format!(", projected onto (p0, n) in {n} Newton iterations"),
        None => String::new(),
    };
    let (reachable, short) = match &bound {
        Some(bound) => (
            format!(" of at most {:.4} m reachable", bound.reachable_m),
            bound
                .shortfall
                .as_ref()
                .map_or(String::new(), |note| format!("\n  note: {note}")),
        ),
        None => (String::new(), String::new()),
    };
    Ok(format!(
        "path length {:.4} m{reachable}, {}, {duration:.2} s; ended: {}{short}\n  \
         seed: {} ({}){projected}\n  \
         timed rest to rest: {:.3} s ({:.3} s time-optimal without jerk limits), tool at the \
         requested speed {:.0} % of the time, {} at {} Hz{rests}{cut}{unreached}\n  \
         wrote {}, {} and {}{viewer}{exported}",
        trajectory.path_length_m,
        output::count(steps, "step"),
        trajectory.termination,
        plan.seed.source,
        emg_planner::seed_source_meaning(plan.seed.source),
        timed.duration_s,
        timed.time_optimal_s,
        timed.tool_speed_share * 100.0,
        output::count(
            (timed.duration_s * timed.rate_hz).round() as usize + 1,
            "point"
        ),
        timed.rate_hz,
        paths.json.display(),
        paths.csv.display(),
        paths.joint_trajectory.display()
    ))
}
