//! `emg`: plan extreme straight-line motions for an arm of six or seven joints holding a pen.
//!
//! ```text
//! emg plan                                   # built-in demo task → trajectory.json, trajectory.csv
//! emg plan --p0 0.4,0.1,0.3 --d 0,1,0 --n 0,0,-1 --seed home --out runs/line
//! emg plan --task-file tasks.json --config plan.json --out runs/set   # runs/set-00000.json, ...
//! emg check runs/line.joint_trajectory.json  # verify a file with the independent checker
//! ```
//!
//! * Robot: `--robot fr3` (the default), `--robot iiwa14`, `--robot ur5e`, or `--robot <urdf>`
//!   for any serial arm of six or seven revolute joints; the chain runs from the file's only
//!   root link to its only leaf unless `--base-link` or `--tip-link` names an end. A shipped
//!   robot brings its own trained models.
//! * Task: `--p0 x,y,z --d x,y,z --n x,y,z`, or `--task-file <file>` (JSON or the binary
//!   `EMGTASKS` set, told apart by the content), or nothing for the demo task: from the
//!   mid-range configuration, `p0` = its TCP, `n` = its tool axis, `d` = +y made ⟂ `n` (the
//!   first task of the robot's task population when that configuration is near a singularity).
//! * Seed: `--seed dp` (the diffusion seeder over `--weights`, default the robot's shipped
//!   `diffusion-v1.weights`), `generating` (the task's `q0_seed`), `home` (the
//!   mid-range configuration of the joint limits; the robot file carries no home pose),
//!   `q_mu` / `q_jl` (heuristic ascents from `q0_seed`) or `q=v1,...,vN` (radians, one per
//!   joint). Default: `dp` when the weights file exists, else `generating` when the task has a
//!   `q0_seed`, else `home`. A seed not already at `p0` with its tool axis in the
//!   cone is Newton-projected onto the exact pose `(p0, n)`.
//! * `--config <file|json>`: an `emg_planner::PlannerConfig` (a file, or inline JSON starting
//!   with `{`): optional `rollout`, `gains`, `switch` (`tau_enter`, `tau_exit`), `measure`,
//!   `reach` and `search` objects; unset fields keep their defaults.
//! * `--planner search` (default: `emg_planner`'s search: the pipeline's plan first, then many
//!   candidate starts ranked by rollouts and detours repairing the longest, within a step
//!   budget; never shorter than the pipeline's plan) or `controller` (the paper's pipeline, one
//!   seed and one rollout). The seed option names the pipeline's seed, which the search tries
//!   first.
//! * `--controller hybrid` (default: the PPO policy over `--policy`, default the robot's shipped
//!   `ppo-v1.weights`, inside; the classical controller near the joint limits),
//!   `rl` or `classical`.
//! * `--out <stem>` (default `trajectory`): `<stem>.json` + `<stem>.csv` +
//!   `<stem>.joint_trajectory.json`; a task file with several tasks gives `<stem>-00000.json`,
//!   ... and so on, each written as soon as its task is planned. Parent directories are created.
//!   A run whose files would replace one of its inputs (robot, task, path, config, scene, limits,
//!   model files) or one another is refused before anything is planned.
//!   SIGINT (Ctrl-C) or SIGTERM lets the task being planned finish and write its files whole,
//!   starts no further task, and exits with 128 + the signal number (130, 143).
//! * `--reach on|off` (default on): also the task's reachability bound, how far along the line
//!   the arm can be placed at all (`emg_planner::reach`), printed beside the path length and
//!   recorded as `reachable_m`.
//! * `--surface plate|half-space|off` (default `plate`): the part the line is drawn on, which
//!   the arm, all but the pen, keeps off: a plate under the line or path (its top face in the
//!   plane through `p0` with normal `n`; on a path it covers the path with its margins, along a
//!   line it ends where it would meet the arm's base), the whole half-space beyond that plane,
//!   or none; `--scene <json>`: obstacles (half-spaces, boxes, spheres, capsules, each with a
//!   clearance) the whole arm keeps clear of (`docs/scene.md`). Both are constraints of every
//!   step, of the search and of the checker, and are recorded in the written files.
//! * `--html <path>`: also a self-contained HTML page that animates the motion in 3D
//!   (`<path without extension>-00000.html`, ... for several tasks).
//!
//! `emg check <FILE>` (alias `replay`) reads any of the three files back and verifies it with
//! the independent checker (`--robot`, `--task-from`, `--p0/--d/--n`, `--config` as needed).
//!
//! `emg import-robot <URDF> --out <URDF>` turns a vendor description (meshes, boxes, cylinders)
//! into a capsule URDF with a pen (`docs/robot-import.md`).
//!
//! The file layouts are documented in `docs/trajectory-format.md` and
//! `docs/joint-trajectory-format.md`. Errors go to stderr with a
//! nonzero exit status; with several tasks a failing task is reported and the rest still run.
//! Output to a closed pipe (`emg place … | head`) is dropped: every file is still written.

/// `println!` for every module of the binary: prints through [`output::print_line`], which drops
/// what a closed standard output (a pipe whose reader has gone) cannot take instead of
/// panicking, so that a command still writes its files.
macro_rules! println {
    () => {
        $crate::output::print_line(format_args!(""))
    };
    ($($arg:tt)*) => {
        $crate::output::print_line(format_args!($($arg)*))
    };
}

mod args;
mod check;
mod check_script;
mod export;
mod import;
mod interrupt;
mod job;
mod output;
mod place;
mod refusal;
mod report;
mod robot;
mod tasks;

use std::path::Path;
use std::process::ExitCode;

use anyhow::Result;
use clap::Parser;
use emg_control::{Task, Trajectory};
use emg_io::{PlanPaths, html_path};
use emg_planner::{
    ControllerKind, Models, MotionTiming, Plan, PlanError, PlanFiles, PlanRecord, PlanRequest,
    Planner, PlannerConfig, PlannerKind, SeedError, SeedSource,
};

use crate::args::{Cli, Command, OnOff, PlanArgs};
use crate::interrupt::{Interrupt, Interrupted};
use crate::output::write_text;
use crate::report::error_text;

fn main() -> ExitCode {
    let result = match Cli::parse().command {
        Command::Plan(args) => run_plan(&args),
        Command::Check(args) => check::run_check(&args),
        Command::ImportRobot(args) => import::run_import(&args),
        Command::Export(args) => export::run_export(&args),
        Command::Job(args) => Interrupt::install().and_then(|stop| job::run_job(&args, &stop)),
        Command::Place(args) => {
            Interrupt::install().and_then(|stop| place::run_place(&args, &stop))
        }
    };
    match result {
        Ok(()) => ExitCode::SUCCESS,
        Err(error) if error.is::<Interrupted>() => {
            eprintln!("{}", error_text(&error));
            error
                .downcast_ref::<Interrupted>()
                .map_or(ExitCode::FAILURE, |stop| ExitCode::from(stop.exit_code()))
        }
        Err(error) => {
            eprintln!("error: {}", error_text(&error));
            ExitCode::FAILURE
        }
    }
}

fn run_plan(args: &PlanArgs) -> Result<()> {
    let interrupt = Interrupt::install()?;
    let robot = robot::load_robot(
        &args.robot,
        args.base_link.as_deref(),
        args.tip_link.as_deref(),
    )?;
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
    let controller = controller(args);
    let models = Models::load(
        &robot,
        diffusion_weights(args)?.as_deref(),
        policy_weights(args, controller)?.as_deref(),
    )?;
    let tasks = tasks::requested_tasks(&robot, args)?;
    refuse_overwriting_inputs(args, tasks.len())?;
    export::refuse_plan_export(args, &robot, tasks.len())?;
    let timing = motion_timing(args, &robot, &config)?;
    let planner = Planner::new(robot, models, config)?;
    let request = PlanRequest {
        planner: args.planner,
        seed: args.seed.clone(),
        controller,
    };
    if args.controller.is_none() && controller == ControllerKind::Classical {
        println!(
            "controller: classical (no policy is trained for robot {0}; `cargo xtask train-ppo \
             --robot {0}` trains one, --policy loads one)",
            args.robot.display()
        );
    }
    if timing.assumed() {
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
    let many = tasks.len() > 1;
    let mut failures: Vec<(usize, String)> = Vec::new();
    let mut refused: Vec<(usize, String)> = Vec::new();
    for (index, task) in tasks.iter().enumerate() {
        if let Some(stop) = interrupt.received() {
            let written = index - failures.len() - refused.len();
            return Err(anyhow::Error::new(stop).context(format!(
                "{written} of {} planned and written whole, {} refused, {} failed; the rest \
                 were not started",
                output::count(tasks.len(), "task"),
                refused.len(),
                failures.len()
            )));
        }
        let label = if many {
            format!("task {index}: ")
        } else {
            String::new()
        };
        // A task is planned, refused at its start (invalid, or no start holds), or failed.
        let planned = match task {
            Err(reason) => Err(reason.clone()),
            Ok(task) => {
                let refuse = |violation: Option<&emg_control::Violation>| {
                    refusal::refusal(&planner, &args.robot, &request, task, violation)
                };
                match planner.plan(task, &request) {
                    Ok(plan) => match &plan.trajectory.termination {
                        emg_control::Termination::InvalidStart { violation } => {
                            Err(refuse(Some(violation)))
                        }
                        _ => Ok((task, plan)),
                    },
                    // The search found no configuration at p0 to start from.
                    Err(PlanError::Seed(SeedError::Projection { .. }))
                        if request.planner == PlannerKind::Search =>
                    {
                        Err(refuse(None))
                    }
                    Err(error) if !many => return Err(plan_error(error, &request)),
                    Err(error) => {
                        let error = plan_error(error, &request);
                        let text = error_text(&error);
                        eprintln!("{label}error: {text}");
                        failures.push((index, text));
                        continue;
                    }
                }
            }
        };
        let (task, plan) = match planned {
            Ok(planned) => planned,
            Err(reason) => {
                anyhow::ensure!(many, "refused, nothing written: {reason}");
                eprintln!("{label}refused, nothing written: {reason}");
                refused.push((index, reason));
                continue;
            }
        };
        let record = Record {
            request: &request,
            timing: &timing,
        };
        match write_plan(&planner, args, &record, task, &plan, many.then_some(index)) {
            Ok(report) => println!("{label}{report}"),
            Err(error) if !many => return Err(error),
            Err(error) => {
                let text = error_text(&error);
                eprintln!("{label}error: {text}");
                failures.push((index, text));
            }
        }
    }
    if refused.is_empty() && failures.is_empty() {
        return Ok(());
    }
    let mut summary = format!(
        "{} of {} tasks planned; {} refused at their start, {} failed:",
        tasks.len() - refused.len() - failures.len(),
        tasks.len(),
        refused.len(),
        failures.len()
    );
    for (index, reason) in refused.iter().chain(&failures) {
        summary.push_str(&format!("\n  task {index}: {reason}"));
    }
    Err(anyhow::anyhow!(summary))
}

/// The `--config` option: inline JSON when it starts with `{`, else a file.
pub(crate) fn read_config(config: &Path) -> Result<PlannerConfig> {
    match inline_json(config) {
        Some(text) => Ok(PlannerConfig::from_json("--config", text)?),
        None => Ok(PlannerConfig::read(config)?),
    }
}

/// The JSON text of a `--config` value given inline (starting with `{`), `None` for a file.
fn inline_json(config: &Path) -> Option<&str> {
    config
        .to_str()
        .map(str::trim_start)
        .filter(|text| text.starts_with('{'))
}

/// Refuses, before anything is planned, a run whose files (`--out`'s, `--html`'s, for each of
/// its `tasks` tasks) would replace one of its inputs or one another.
fn refuse_overwriting_inputs(args: &PlanArgs, tasks: usize) -> Result<()> {
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
        ("--task-file", args.task_file.as_deref()),
        ("--path", args.path.as_deref()),
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
    let indices: Vec<Option<usize>> = match tasks {
        1 => vec![None],
        many => (0..many).map(Some).collect(),
    };
    let files: Vec<(PlanPaths, Option<std::path::PathBuf>)> = indices
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

/// The controller: `--controller`, else hybrid when a policy is trained for the robot (given
/// with --policy or shipped), else classical.
fn controller(args: &PlanArgs) -> ControllerKind {
    args.controller.unwrap_or_else(|| {
        if args.policy_path().is_some_and(|path| path.exists()) {
            ControllerKind::Hybrid
        } else {
            ControllerKind::Classical
        }
    })
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

/// What a plan was asked for beyond the task: the request and the timing.
struct Record<'a> {
    request: &'a PlanRequest,
    timing: &'a MotionTiming,
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

/// The diffusion weights to load: `--weights`, or the robot's shipped ones when the seed may
/// be `dp` and they exist; `--seed dp` without any is an error.
fn diffusion_weights(args: &PlanArgs) -> Result<Option<std::path::PathBuf>> {
    let explicit = matches!(args.seed, Some(SeedSource::Dp));
    match args.weights_path() {
        Some(path) if explicit || (args.seed.is_none() && path.exists()) => Ok(Some(path)),
        None if explicit => anyhow::bail!(
            "--seed dp: no diffusion weights are shipped for robot {0}; pass --weights, or train \
             them with `cargo xtask make-tasks --robot {0}`, `cargo xtask label-seeds --robot {0}` \
             and `cargo xtask train-diffusion --robot {0}`",
            args.robot.display()
        ),
        _ => Ok(None),
    }
}

/// The policy weights of `--controller rl` and `hybrid`: `--policy`, else the robot's shipped
/// ones.
fn policy_weights(
    args: &PlanArgs,
    controller: ControllerKind,
) -> Result<Option<std::path::PathBuf>> {
    if !controller.needs_policy() {
        return Ok(None);
    }
    match args.policy_path() {
        Some(path) => Ok(Some(path)),
        None => anyhow::bail!(
            "--controller {}: no policy is shipped for robot {1}; pass --policy, train one with \
             `cargo xtask make-tasks --robot {1}` and `cargo xtask train-ppo --robot {1}`, or use \
             --controller classical",
            controller,
            args.robot.display()
        ),
    }
}

/// Writes one planned task's files and returns the lines to print.
fn write_plan(
    planner: &Planner,
    args: &PlanArgs,
    record: &Record<'_>,
    task: &Task,
    plan: &Plan,
    index: Option<usize>,
) -> Result<String> {
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
            request: record.request,
            bound: bound.as_ref(),
            timing: record.timing,
        },
    )?;
    files.write(&paths)?;
    let exported = export::after_plan(args, planner.robot(), &paths)?;
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
        Some(html) => write_viewer(
            planner,
            task,
            &played_as_timed(trajectory, &files.step_times_s),
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

/// `trajectory` with each step at the time the timed motion passes it: the viewer plays the
/// motion the robot executes, at rest where it starts and ends.
fn played_as_timed(trajectory: &Trajectory, step_times_s: &[f64]) -> Trajectory {
    let mut played = trajectory.clone();
    for (step, time_s) in played.steps.iter_mut().zip(step_times_s) {
        step.time_s = *time_s;
    }
    played
}

/// Writes the `--html` viewer page of one planned task to `path`; returns the line to print.
fn write_viewer(
    planner: &Planner,
    task: &Task,
    trajectory: &Trajectory,
    path: &Path,
) -> Result<String> {
    let name = path
        .file_stem()
        .unwrap_or(path.as_os_str())
        .to_string_lossy();
    let acted: Vec<&str> = trajectory
        .acting_controllers()
        .into_iter()
        .map(emg_control::ActingController::name)
        .collect();
    let title = match acted.as_slice() {
        [] => format!("{name}: no step taken"),
        [one] => format!("{name}: steps by the {one} controller"),
        [first @ .., last] => format!(
            "{name}: steps by the {} and {last} controllers",
            first.join(", ")
        ),
    };
    let page = emg_viewer::render_html(&emg_viewer::ViewerInput {
        robot: planner.robot(),
        task,
        trajectory,
        constraints: &planner.config().rollout.constraints,
        title: &title,
    });
    write_text(path, &page)?;
    Ok(format!("\n  wrote {}", path.display()))
}
