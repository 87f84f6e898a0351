//! Where the tasks to plan come from: the command line, a task file, a path file, or the
//! built-in demo.

use std::path::PathBuf;

use anyhow::{Context, Result};
use clap::Args;
use emg_control::Task;
use emg_io::{read_each_task, read_path};
use emg_kinematics::{Robot, Vec3};

use crate::options::TaskLineArgs;

/// The options of `emg plan` that say what to plan: a line, a task file or a path (none: the
/// demo task).
#[derive(Debug, Args)]
pub struct TaskArgs {
    /// A task given on the command line.
    #[command(flatten)]
    pub line: TaskLineArgs,
    /// Task set to plan: JSON or the binary EMGTASKS layout (told apart by the content).
    #[arg(long, value_name = "FILE", conflicts_with = "p0")]
    pub task_file: Option<PathBuf>,
    /// A path to follow instead of a line: a JSON path file (start, surface normal, straight
    /// and circular segments, blend radius; docs/paths.md). The plan says how far along the
    /// path the tool gets.
    #[arg(long, value_name = "FILE", conflicts_with_all = ["p0", "task_file"])]
    pub path: Option<PathBuf>,
}

impl TaskArgs {
    /// The tasks requested, each validated by [`Task::new`] (a path by [`Task::on_path`]) for
    /// `robot`: the file's own faults are the error; a task file's invalid tasks are there with
    /// the reason, so that the others are planned.
    pub fn requested(&self, robot: &Robot) -> Result<Vec<Result<Task, String>>> {
        if let Some(file) = &self.path {
            let path = read_path(file)?;
            let task = Task::on_path(robot, path, None)
                .with_context(|| format!("the path of {} is not a task", file.display()))?;
            return Ok(vec![Ok(task)]);
        }
        if let Some(path) = &self.task_file {
            let tasks = read_each_task(path, robot)
                .with_context(|| format!("cannot read task file {}", path.display()))?;
            anyhow::ensure!(
                !tasks.is_empty(),
                "task file {} holds no tasks",
                path.display()
            );
            return Ok(tasks
                .into_iter()
                .map(|task| task.map_err(|error| error.to_string()))
                .collect());
        }
        match (self.line.p0, self.line.d, self.line.n) {
            (Some(p0), Some(d), Some(n)) => {
                let task = Task::new(robot, Vec3::from(p0), Vec3::from(d), Vec3::from(n), None)
                    .context("invalid task given on the command line")?;
                Ok(vec![Ok(task)])
            }
            _ => Ok(vec![Ok(
                emg_planner::demo_task(robot).context("the built-in demo task is invalid")?
            )]),
        }
    }
}
