//! Where the tasks to plan come from: the command line, a task file, a path file, or the
//! built-in demo.

use anyhow::{Context, Result};
use emg_control::Task;
use emg_io::{read_path, read_tasks};
use emg_kinematics::{Robot, Vec3};

use crate::args::PlanArgs;

/// The tasks requested by `args`, each validated by [`Task::new`] (a path by
/// [`Task::on_path`]).
pub fn requested_tasks(robot: &Robot, args: &PlanArgs) -> Result<Vec<Task>> {
    if let Some(file) = &args.path {
        let path = read_path(file)?;
        let task = Task::on_path(robot, path, None)
            .with_context(|| format!("the path of {} is not a task", file.display()))?;
        return Ok(vec![task]);
    }
    if let Some(path) = &args.task_file {
        let tasks = read_tasks(path, robot)
            .with_context(|| format!("cannot read task file {}", path.display()))?;
        anyhow::ensure!(
            !tasks.is_empty(),
            "task file {} holds no tasks",
            path.display()
        );
        return Ok(tasks);
    }
    match (args.line.p0, args.line.d, args.line.n) {
        (Some(p0), Some(d), Some(n)) => {
            let task = Task::new(robot, Vec3::from(p0), Vec3::from(d), Vec3::from(n), None)
                .context("invalid task given on the command line")?;
            Ok(vec![task])
        }
        _ => Ok(vec![
            emg_planner::demo_task(robot).context("the built-in demo task is invalid")?,
        ]),
    }
}
