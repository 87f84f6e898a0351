//! `emg`: plan extreme straight-line motions for a 7-DoF arm holding a pen.
//!
//! ```text
//! emg plan                                   # built-in demo task → trajectory.json, trajectory.csv
//! emg plan --p0 0.4,0.1,0.3 --d 0,1,0 --n 0,0,-1 --seed home --out runs/line
//! emg plan --task-file tasks.json --config plan.json --out runs/set   # runs/set-00000.json, ...
//! emg check runs/line.joint_trajectory.json  # verify a file with the independent checker
//! ```
//!
//! * Robot: `--robot fr3` (the default), `--robot iiwa14`, or `--robot <urdf>` for any 7-DoF
//!   serial arm; the chain runs from the file's root link to its only leaf unless `--base-link`
//!   and `--tip-link` name its ends. A shipped robot brings its own trained models.
//! * Task: `--p0 x,y,z --d x,y,z --n x,y,z`, or `--task-file <file>` (JSON by the `.json`
//!   extension, else the binary `EMGTASKS` set), or nothing for the demo task: from the
//!   mid-range configuration, `p0` = its TCP, `n` = its tool axis, `d` = +y made ⟂ `n` (the
//!   first task of the robot's task population when that configuration is near a singularity).
//! * Seed: `--seed dp` (the diffusion seeder over `--weights`, default the robot's shipped
//!   `diffusion-v1.weights`), `generating` (the task's `q0_seed`), `home` (the
//!   mid-range configuration of the joint limits; the robot file carries no home pose) or
//!   `q=v1,...,v7` (radians). Default: `dp` when the weights file exists, else `generating` when
//!   the task has a `q0_seed`, else `home`. A seed not already at `p0` with its tool axis in the
//!   cone is Newton-projected onto the exact pose `(p0, n)`.
//! * `--config <json>`: optional `rollout`, `gains`, `switch` (`tau_enter`, `tau_exit`) and
//!   `measure` objects; unset fields keep SPEC defaults.
//! * `--controller hybrid` (default: the PPO policy over `--policy`, default the robot's shipped
//!   `ppo-v1.weights`, inside; the classical controller near the joint limits),
//!   `rl` or `classical`.
//! * `--out <stem>` (default `trajectory`): `<stem>.json` + `<stem>.csv` +
//!   `<stem>.joint_trajectory.json`; a task file with several tasks gives `<stem>-00000.json`,
//!   ... and so on, each written as soon as its task is planned. Parent directories are created.
//! * `--html <path>`: also a self-contained HTML page that animates the motion in 3D
//!   (`<path without extension>-00000.html`, ... for several tasks).
//!
//! `emg check <FILE>` (alias `replay`) reads any of the three files back and verifies it with
//! the independent checker (`--robot`, `--task-from`, `--p0/--d/--n`, `--config` as needed).
//!
//! The file layouts are documented in `docs/trajectory-format.md` and
//! `docs/joint-trajectory-format.md`. Errors go to stderr with a
//! nonzero exit status; with several tasks a failing task is reported and the rest still run.

mod args;
mod check;
mod output;
mod plan;
mod robot;
mod seed;
mod settings;
mod tasks;

use std::process::ExitCode;

use anyhow::{Context, Result};
use clap::Parser;
use emg_kinematics::Robot;

use emg_diffusion::{DenoiserWeights, DpSeedConfig, DpSeeder};
use emg_policy::{PolicyWeights, RlController};

use crate::args::{Cli, Command, PlanArgs, SeedRequest};
use crate::output::{
    TrajectoryFile, html_path, joint_trajectory_path, result_paths, write_html,
    write_joint_trajectory, write_result,
};
use crate::settings::Settings;

fn main() -> ExitCode {
    let result = match Cli::parse().command {
        Command::Plan(args) => run_plan(&args),
        Command::Check(args) => check::run_check(&args),
    };
    match result {
        Ok(()) => ExitCode::SUCCESS,
        Err(error) => {
            eprintln!("error: {error:#}");
            ExitCode::FAILURE
        }
    }
}

fn run_plan(args: &PlanArgs) -> Result<()> {
    let robot = robot::load_robot(
        &args.robot,
        args.base_link.as_deref(),
        args.tip_link.as_deref(),
    )?;
    let settings = Settings::load(args.config.as_deref())?;
    let dp = load_dp_seeder(args)?;
    let policy = load_policy(args)?;
    let tasks = tasks::requested_tasks(&robot, args)?;
    let many = tasks.len() > 1;
    let mut failures = 0;
    for (index, task) in tasks.iter().enumerate() {
        let label = if many {
            format!("task {index}: ")
        } else {
            String::new()
        };
        match plan_and_write(
            &robot,
            args,
            &settings,
            dp.as_ref(),
            policy.as_ref(),
            task,
            many.then_some(index),
        ) {
            Ok(report) => println!("{label}{report}"),
            Err(error) if many => {
                failures += 1;
                eprintln!("{label}error: {error:#}");
            }
            Err(error) => return Err(error),
        }
    }
    anyhow::ensure!(failures == 0, "{failures} of {} tasks failed", tasks.len());
    Ok(())
}

/// The diffusion seeder: required by `--seed dp`, used by default when `--weights` exists.
fn load_dp_seeder(args: &PlanArgs) -> Result<Option<DpSeeder>> {
    let explicit = matches!(args.seed, Some(SeedRequest::Dp));
    let path = match args.weights_path() {
        Some(path) if explicit || (args.seed.is_none() && path.exists()) => path,
        None if explicit => anyhow::bail!(
            "--seed dp: no diffusion weights are shipped for robot {}; pass --weights",
            args.robot.display()
        ),
        _ => return Ok(None),
    };
    let weights = DenoiserWeights::read(&path).with_context(|| {
        format!(
            "--seed dp: cannot load diffusion weights {}",
            path.display()
        )
    })?;
    let seeder = DpSeeder::new(&weights, DpSeedConfig::default())
        .with_context(|| format!("--seed dp: unusable diffusion weights {}", path.display()))?;
    Ok(Some(seeder))
}

/// The policy of `--controller rl` and `hybrid`, loaded from `--policy`.
fn load_policy(args: &PlanArgs) -> Result<Option<RlController>> {
    if !args.controller.kind().needs_policy() {
        return Ok(None);
    }
    let Some(path) = args.policy_path() else {
        anyhow::bail!(
            "--controller {}: no policy is shipped for robot {}; pass --policy or use --controller classical",
            args.controller.kind().name(),
            args.robot.display()
        );
    };
    let weights = PolicyWeights::read(&path).with_context(|| {
        format!(
            "--controller {}: cannot load policy weights {}",
            args.controller.kind().name(),
            path.display()
        )
    })?;
    Ok(Some(RlController::new(&weights)))
}

/// Plans one task, writes its files and returns the lines to print.
fn plan_and_write(
    robot: &Robot,
    args: &PlanArgs,
    settings: &Settings,
    dp: Option<&DpSeeder>,
    policy: Option<&RlController>,
    task: &emg_control::Task,
    index: Option<usize>,
) -> Result<String> {
    let plan = plan::plan_task(
        robot,
        task,
        args.seed.as_ref(),
        dp,
        args.controller,
        policy,
        settings,
    )?;
    let trajectory = &plan.trajectory;
    let (json_path, csv_path) = result_paths(&args.out, index);
    let file = TrajectoryFile::new(
        &args.robot,
        robot.joint_names(),
        task,
        plan.seed.source,
        args.controller.kind().name(),
        &settings.rollout,
        &settings.gains,
        trajectory,
    );
    write_result(&file, &json_path, &csv_path)?;
    let joint_path = joint_trajectory_path(&args.out, index);
    let joint_file = emg_control::JointTrajectory::new(
        &file.robot,
        robot.joint_names(),
        task,
        &settings.rollout.constraints,
        trajectory,
    )
    .context("cannot build the joint trajectory")?;
    write_joint_trajectory(&joint_file, &joint_path)?;
    let viewer = write_viewer(robot, args, settings, task, trajectory, index)?;
    let steps = trajectory.steps.len() - 1;
    let duration = trajectory.steps.last().map_or(0.0, |s| s.time_s);
    let projected = match plan.seed.projection_iterations {
        Some(n) => format!(", projected onto (p0, n) in {n} Newton iterations"),
        None => String::new(),
    };
    Ok(format!(
        "path length {:.4} m, {steps} steps, {duration:.2} s; ended: {}\n  \
         seed: {}{projected}\n  wrote {}, {} and {}{viewer}",
        trajectory.path_length_m,
        trajectory.termination,
        plan.seed.source,
        json_path.display(),
        csv_path.display(),
        joint_path.display()
    ))
}

/// Writes the `--html` viewer page of one planned task; returns the line to print (empty without
/// `--html`).
fn write_viewer(
    robot: &Robot,
    args: &PlanArgs,
    settings: &Settings,
    task: &emg_control::Task,
    trajectory: &emg_control::Trajectory,
    index: Option<usize>,
) -> Result<String> {
    let Some(html) = &args.html else {
        return Ok(String::new());
    };
    let path = html_path(html, index);
    let name = path
        .file_stem()
        .unwrap_or(path.as_os_str())
        .to_string_lossy();
    let title = format!("{name}: {} controller", args.controller.kind().name());
    let page = emg_viewer::render_html(&emg_viewer::ViewerInput {
        robot,
        task,
        trajectory,
        constraints: &settings.rollout.constraints,
        title: &title,
    });
    write_html(&path, &page)?;
    Ok(format!("\n  wrote {}", path.display()))
}
