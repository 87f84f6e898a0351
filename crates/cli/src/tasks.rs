//! Where the tasks to plan come from: the command line, a task file, a path file, or the
//! built-in demo.

use anyhow::{Context, Result};
use emg_control::Task;
use emg_io::{read_each_task, read_path};
use emg_kinematics::{Robot, Vec3};

use crate::args::PlanArgs;

/// The tasks requested by `args`, each validated by [`Task::new`] (a path by
/// [`Task::on_path`]): the file's own faults are the error; a task file's invalid tasks are
/// there with the reason, so that the others are planned.
pub fn requested_tasks(robot: &Robot, args: &PlanArgs) -> Result<Vec<Result<Task, String>>> {
    if let Some(file) = &args.path {
        let path = read_path(file)?;
        let task = Task::on_path(robot, path, None)
            .with_context(|| format!("the path of {} is not a task", file.display()))?;
        return Ok(vec![Ok(task)]);
    }
    if let Some(path) = &args.task_file {
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
    match (args.line.p0, args.line.d, args.line.n) {
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
