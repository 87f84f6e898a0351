//! The options every evaluation over a task set shares: its worker threads, its task set, its
//! robot and the directory it writes its results to. A command flattens them into its own
//! options and words their help for itself where it differs (`mut_arg`).

use std::path::PathBuf;

use crate::workspace;

/// Worker threads, task set, robot file and output directory of an evaluation.
#[derive(clap::Args)]
pub struct TaskSetOptions {
    /// Worker threads (0 = one per core); the results do not depend on it.
    #[arg(long, default_value_t = 0)]
    pub threads: usize,
    /// Task set.
    #[arg(long, default_value_os_t = workspace::data("tasks/eval-v1.tasks"))]
    pub task_file: PathBuf,
    /// Robot file.
    #[arg(long, value_parser = workspace::robot_file, default_value_os_t = workspace::default_robot())]
    pub robot: PathBuf,
    /// Output directory of the result files.
    #[arg(long, default_value_os_t = workspace::results_dir())]
    pub out_dir: PathBuf,
}

impl TaskSetOptions {
    /// The [`workspace::PlannerSetup`] of the robot file and the first `count` tasks of the task
    /// set; `command` names the caller in errors.
    pub fn planner_setup(
        &self,
        count: usize,
        command: &str,
    ) -> anyhow::Result<workspace::PlannerSetup> {
        workspace::planner_setup(&self.robot, &self.task_file, count, command)
    }
}

/// The help of `--threads` for an evaluation whose times depend on the worker threads.
pub const THREADS_TIMED: &str =
    "Worker threads (0 = one per core); the results other than times do not depend on it";

/// The help of `--robot` for an evaluation that times motions within the robot's joint limits.
pub const ROBOT_WITH_JOINT_LIMITS: &str =
    "Robot file (its joint limits are the `.joint_limits.yaml` beside it)";
