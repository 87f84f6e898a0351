//! `emg check`: read a trajectory file back and verify it with the independent checker.
//!
//! Reads `emg-trajectory/1` JSON, `emg-joint-trajectory/2` JSON or the CSV (told apart by the
//! content: JSON starts with `{`, and its `format` field names the layout), resolves the robot,
//! the task and the constraints, and runs [`emg_verify::check_replay`]. The layouts and what is
//! verified are documented in `docs/joint-trajectory-format.md`.

mod exported;
mod krl;
mod rapid;
mod script;

use std::path::{Path, PathBuf};

use anyhow::{Context, Result, bail};
use clap::Args;
use emg_control::{ConstraintConfig, Task};
use emg_io::{Carried, TrajectoryContents};
use emg_kinematics::{Robot, Vec3};
use emg_planner::MotionTiming;
use emg_verify::{JointDynamics, ReplayReport};

use crate::config::read_config;
use crate::options::{ChainArgs, ScalingArgs, TaskLineArgs};
use crate::output::count;
use crate::program::read_job_file;
use crate::robot;

/// Options of `emg check`.
#[derive(Debug, Args)]
pub struct CheckArgs {
    /// The file to verify: `<stem>.json`, `<stem>.joint_trajectory.json`, `<stem>.csv`, a job's
    /// program (emg-job/3), a URScript program exported from one for the UR5e (`.script`), a
    /// RAPID module exported from one for the IRB 120 (`.mod`) or a KRL program exported from
    /// one for the KR 16 (`.src`, its `.dat` beside it).
    #[arg(value_name = "FILE")]
    pub file: PathBuf,
    /// A URScript program's, RAPID module's or KRL program's job program (emg-job/3), which it
    /// is read back against. Default: the `.json` of its name (`drawing.job.script`,
    /// `drawing.job-part1.script` and `drawing.job.mod` → `drawing.job.json`; `drawing.src` →
    /// `drawing.job.json`).
    #[arg(long, value_name = "JOB")]
    pub program: Option<PathBuf>,
    /// Robot: a shipped robot's name (`fr3`, `iiwa14`, `ur5e`, `irb120`, `kr16`) or a robot file (URDF). Default: the
    /// file's `robot` field (a JSON file, or the --task-from file for a CSV), else `fr3`.
    #[arg(long, value_name = "NAME|URDF", value_parser = robot::parse_robot)]
    pub robot: Option<PathBuf>,
    /// The kinematic chain's ends.
    #[command(flatten)]
    pub chain: ChainArgs,
    /// Take the task (and, without --config, the constraints) from this emg-trajectory/1 or
    /// emg-joint-trajectory/2 file instead of FILE (a CSV carries none).
    #[arg(long, value_name = "JSON", conflicts_with = "p0")]
    pub task_from: Option<PathBuf>,
    /// A task given on the command line instead of the file's.
    #[command(flatten)]
    pub line: TaskLineArgs,
    /// As `plan --config` (a JSON file, or inline JSON starting with `{`): its
    /// `rollout.constraints` replace the file's.
    #[arg(long, value_name = "FILE|JSON")]
    pub config: Option<PathBuf>,
    /// Check a joint-trajectory file against these joint limits (MoveIt joint_limits.yaml,
    /// scaled by --velocity-scaling and --acceleration-scaling) instead of the file's own.
    #[arg(long, value_name = "YAML")]
    pub limits: Option<PathBuf>,
    /// Scaling of the --limits file.
    #[command(flatten)]
    pub scaling: ScalingArgs,
}

/// Runs `emg check`: prints the report and `OK`, or fails naming the point and the constraint.
pub fn run(args: &CheckArgs) -> Result<()> {
    let file = &args.file;
    if file.extension().is_some_and(|e| e == "script") {
        return script::check_script(
            file,
            args.program.as_deref(),
            args.robot.as_deref(),
            &args.chain,
        );
    }
    if file.extension().is_some_and(|e| e == "src") {
        return krl::check_program(
            file,
            args.program.as_deref(),
            args.robot.as_deref(),
            &args.chain,
        );
    }
    if file.extension().is_some_and(|e| e == "mod") {
        return rapid::check_module(
            file,
            args.program.as_deref(),
            args.robot.as_deref(),
            &args.chain,
        );
    }
    match read_job_file(file)? {
        Some(job) => check_job(args, file, &job),
        None => check_trajectory(args, file),
    }
}

/// `emg check` on a trajectory file (either JSON layout or the CSV): its task and constraints
/// resolved from the options, the file or the file beside it, and every point verified.
fn check_trajectory(args: &CheckArgs, file: &Path) -> Result<()> {
    let contents = TrajectoryContents::read(file)?;
    let carried = contents.carried();
    // A CSV carries no task: by default it is taken from the JSON written beside it.
    let beside = (carried.is_none() && args.line.p0.is_none() && args.task_from.is_none())
        .then(|| emg_io::task_file_beside(file))
        .flatten();
    let task_from = match args.task_from.as_deref().or(beside.as_deref()) {
        Some(path) => Some((path, read_task_from(path)?)),
        None => None,
    };

    let robot_path = match (&args.robot, &task_from, &carried) {
        (Some(path), _, _) => path.clone(),
        (None, _, Some(c)) => robot::resolve(&c.robot, file)?,
        (None, Some((path, c)), None) => robot::resolve(&c.robot, path)?,
        (None, None, None) => robot::default_robot(),
    };
    let (robot, model) = args.chain.robot_and_checker(&robot_path)?;

    let (task, task_origin) = match (args.line.p0, args.line.d, args.line.n, &task_from, &carried) {
        (Some(p0), Some(d), Some(n), _, _) => (
            Task::new(&robot, Vec3::from(p0), Vec3::from(d), Vec3::from(n), None)
                .context("invalid task given on the command line")?,
            "--p0/--d/--n".to_string(),
        ),
        (_, _, _, Some((path, c)), _) => (
            validated(&robot, &c.task)
                .with_context(|| format!("field 'task' of {}", path.display()))?,
            format!("--task-from {}", path.display()),
        ),
        (_, _, _, None, Some(c)) => (
            validated(&robot, &c.task)
                .with_context(|| format!("field 'task' of {}", file.display()))?,
            "the file".to_string(),
        ),
        _ => bail!(
            "{} is a CSV file, which carries no task, and no {} lies beside it: give \
             --task-from <emg-trajectory JSON> or --p0 x,y,z --d x,y,z --n x,y,z",
            file.display(),
            file.with_extension("json").display()
        ),
    };
    let (constraints, constraints_origin) = match (&args.config, &carried, &task_from) {
        (Some(path), _, _) => (
            read_config(path)?.rollout.constraints,
            format!("--config {}", path.display()),
        ),
        (None, Some(c), _) => (c.constraints.clone(), "the file".to_string()),
        (None, None, Some((path, c))) => (
            c.constraints.clone(),
            format!("--task-from {}", path.display()),
        ),
        (None, None, None) => (ConstraintConfig::default(), "the defaults".to_string()),
    };

    let limits = match &args.limits {
        Some(path) => Some(checked_limits(path, args, &robot, &constraints)?),
        None => None,
    };
    // The recorded trajectory is verified as recorded (its TCP, tool angles, path length and
    // end) only against its own task.
    let own_task = args.line.p0.is_none() && task_from.is_none();
    let report = contents
        .verify(
            &model,
            robot.joint_names(),
            &task,
            &constraints,
            own_task,
            limits.as_ref(),
        )
        .map_err(|failure| anyhow::anyhow!("{} does not hold up: {failure}", file.display()))?;
    let recorded = match &contents {
        TrajectoryContents::Rollout(rollout) if own_task => Some(&rollout.trajectory),
        _ => None,
    };

    println!(
        "{}: {}, robot {}",
        file.display(),
        contents.layout(),
        robot_path.display()
    );
    println!(
        "  task from {task_origin}; constraints from {constraints_origin}: {}",
        describe(&constraints)
    );
    let limits_origin = match (&args.limits, &contents) {
        (Some(path), _) => Some(format!("--limits {}", path.display())),
        (None, TrajectoryContents::Joint(_)) => Some("the file".to_string()),
        _ => None,
    };
    print_report(&report, limits_origin.as_deref());
    println!(
        "  {}",
        match recorded {
            Some(trajectory) => format!("recorded end verified: {}", trajectory.termination),
            None => "not verifiable from this file: why the motion ended".to_string(),
        }
    );
    println!("OK");
    Ok(())
}

/// The joint limits of `--limits` (scaled), each velocity limit at most the robot file's times
/// the constraints' fraction: the bounds a timed motion for these constraints holds.
fn checked_limits(
    path: &Path,
    args: &CheckArgs,
    robot: &Robot,
    constraints: &ConstraintConfig,
) -> Result<JointDynamics> {
    let scaling = args.scaling.scaling()?;
    // Tool speed and rate play no part in the limits.
    let timing = MotionTiming::new(robot, path, scaling, 1.0, 1.0, constraints)?;
    let limits = &timing.request().limits;
    let joints = ..robot.dof();
    Ok(JointDynamics {
        velocity: limits.velocity.as_slice()[joints].to_vec(),
        acceleration: limits.acceleration.as_slice()[joints].to_vec(),
        jerk: limits.jerk.as_slice()[joints].to_vec(),
    })
}

/// Task and constraints of a `--task-from` file (either JSON layout).
fn read_task_from(path: &Path) -> Result<Carried> {
    let text =
        std::fs::read_to_string(path).with_context(|| format!("cannot read {}", path.display()))?;
    let contents = TrajectoryContents::parse_json(&text)
        .with_context(|| format!("--task-from {}: not a trajectory JSON file", path.display()))?;
    contents
        .carried()
        .with_context(|| format!("--task-from {}: carries no task", path.display()))
}

/// `emg check` on a job's program: every segment replayed by the independent checker.
fn check_job(args: &CheckArgs, file: &Path, job: &emg_job::JobFile) -> Result<()> {
    let robot_path = match &args.robot {
        Some(path) => path.clone(),
        None => robot::resolve(&job.robot, file)?,
    };
    let (robot, model) = args.chain.robot_and_checker(&robot_path)?;
    let check = emg_job::verify_job(job, &model, robot.joint_names())
        .map_err(|failure| anyhow::anyhow!("{} does not hold up: {failure}", file.display()))?;
    println!(
        "{}: {} program, robot {}",
        file.display(),
        emg_job::JOB_FILE_FORMAT,
        robot_path.display()
    );
    println!(
        "  {} on their paths ({}), {} clear of the arm, the plates and the scene; {} from rest \
         to rest within the file's joint limits",
        count(check.stroke_parts, "stroke part"),
        describe(&job.constraints),
        count(check.moves, "move"),
        count(check.points, "point")
    );
    println!(
        "  claims as the samples draw them: pen down {:.4} m of {:.4} m, {} of {} whole{}",
        check.drawn_m,
        check.total_m,
        check.whole_strokes,
        count(check.strokes, "stroke"),
        match &job.home {
            Some(_) if job.summary.ends_at_home => ", from home and back",
            Some(_) => ", from home",
            None => "",
        }
    );
    println!("OK");
    Ok(())
}

/// `task` validated again for `robot` (a validated task comes back bit for bit).
fn validated(robot: &Robot, task: &Task) -> Result<Task> {
    Ok(task.revalidated(robot)?)
}

/// The constraints in words, as the reports print them.
fn describe(constraints: &ConstraintConfig) -> String {
    let speeds = match constraints.velocity_limit_fraction {
        Some(fraction) => format!("joint speeds ≤ {} × limit", fraction.get()),
        None => "joint speeds not limited".to_string(),
    };
    format!(
        "line {} mm, cone {}°, clearance ≥ {} mm, {speeds}",
        constraints.line_tolerance_m * 1e3,
        constraints.theta_max_deg,
        constraints.collision_margin_m * 1e3
    )
}

/// Prints what the checker verified of a trajectory file; `limits_origin` names where the
/// joint limits checked come from, if any were.
fn print_report(report: &ReplayReport, limits_origin: Option<&str>) {
    println!(
        "  {}, {:.3} s, path length {:.4} m",
        count(report.points, "point"),
        report.duration_s,
        report.path_length_m
    );
    let fractions = |values: &[f64]| -> String {
        let text: Vec<String> = values.iter().map(|f| format!("{f:.3}")).collect();
        text.join(" ")
    };
    match (&report.dynamics, limits_origin) {
        (Some(dynamics), Some(origin)) => {
            println!("  joint limits from {origin}; rest at both ends");
            println!(
                "  peak joint velocity / limit: {}",
                fractions(&dynamics.peak_velocity_fraction)
            );
            println!(
                "  peak joint acceleration / limit: {}",
                fractions(&dynamics.peak_acceleration_fraction)
            );
            println!(
                "  peak joint jerk / limit: {}",
                fractions(&dynamics.peak_jerk_fraction)
            );
        }
        _ => {
            println!(
                "  peak joint speed / limit: {}",
                fractions(&report.peak_speed_fraction)
            );
            println!(
                "  peak joint acceleration between points (rad/s², not bounded by the planner): {}",
                report
                    .peak_acceleration_rad_s2
                    .iter()
                    .map(|a| format!("{a:.2}"))
                    .collect::<Vec<_>>()
                    .join(" ")
            );
            let [first, last] = report.boundary_speed_fraction;
            println!(
                "  fastest joint at the first point {first:.3} × its limit, at the last point \
                 {last:.3} × (the file starts and ends at those speeds)"
            );
        }
    }
    let (clearance, a, b) = &report.min_clearance;
    println!(
        "  max line deviation {:.3} mm, max tool angle {:.2}°, min clearance {:.1} mm ({a}, {b})",
        report.max_line_deviation_m * 1e3,
        report.max_tool_angle_deg,
        clearance * 1e3
    );
    if let Some(error) = report.max_declared_velocity_error {
        println!(
            "  declared velocities agree with positions and times (largest difference {error:.1e} rad/s)"
        );
    }
}
