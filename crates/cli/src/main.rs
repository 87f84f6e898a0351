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

// The commands, each owning its options and run by its `run`.
mod check;
mod export;
mod import;
mod job;
mod place;
mod plan;

// What the commands share; none of these uses a command.
mod config;
mod exporting;
mod interrupt;
mod job_input;
mod options;
mod output;
mod program;
mod report;
mod robot;

use std::process::ExitCode;

use clap::{Parser, Subcommand};

use crate::interrupt::{Interrupt, Interrupted};
use crate::report::error_text;

/// Extreme straight-line motion on an arm of six or seven joints holding a pen.
#[derive(Debug, Parser)]
#[command(name = "emg", version, about)]
pub struct Cli {
    /// What to do.
    #[command(subcommand)]
    pub command: Command,
}

/// The subcommands.
#[derive(Debug, Subcommand)]
#[allow(
    clippy::large_enum_variant,
    reason = "parsed once per run: boxing saves nothing worth the indirection"
)]
pub enum Command {
    /// Plan straight-line motions: seed, roll out a controller, write the trajectories.
    Plan(plan::PlanArgs),
    /// Verify a trajectory file (emg-trajectory/1 JSON, emg-joint-trajectory/2 JSON or the CSV)
    /// with the independent checker; exit status 1 names the point and the constraint.
    #[command(visible_alias = "replay")]
    Check(check::CheckArgs),
    /// Import a vendor robot description: fit capsules to every link's collision geometry
    /// (boxes, cylinders, spheres, STL and OBJ meshes), attach the pen to the tool link, and
    /// write a standard URDF the planners and the checker read, with an SRDF beside it listing
    /// the link pairs not checked for self-collision (see docs/robot-import.md).
    ImportRobot(import::ImportArgs),
    /// Export a joint trajectory for a robot's own stack: `ros2-mcap` (a ROS 2
    /// trajectory_msgs/msg/JointTrajectory in an MCAP bag, joint names as the vendor's driver
    /// names them), `urscript` (a program for a Universal Robots e-Series controller) or `rapid`
    /// (a job's program as a module for an ABB controller); see docs/robot-export.md.
    Export(export::ExportArgs),
    /// Plan a job: a job file or an SVG drawing, every stroke to the limit (resumed after a
    /// reconfiguration where one motion cannot finish it), safe moves between strokes, one timed
    /// program written as an emg-job/3 file (see docs/jobs.md).
    Job(job::JobArgs),
    /// Find where to put a job's part (shifted on its surface, turned about its normal) so the
    /// arm draws the most of it: places screened by the strokes' reachability bounds, the best
    /// planned as full jobs; writes the program at the chosen place, and on request the heat
    /// map and the job file with the place as its transform (see docs/placement.md).
    Place(place::PlaceArgs),
}

fn main() -> ExitCode {
    let result = match Cli::parse().command {
        Command::Plan(args) => plan::run(&args),
        Command::Check(args) => check::run(&args),
        Command::ImportRobot(args) => import::run(&args),
        Command::Export(args) => export::run(&args),
        Command::Job(args) => Interrupt::install().and_then(|stop| job::run(&args, &stop)),
        Command::Place(args) => Interrupt::install().and_then(|stop| place::run(&args, &stop)),
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
