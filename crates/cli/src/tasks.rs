//! Where the tasks to plan come from: the command line, a task file, or the built-in demo.

use anyhow::{Context, Result};
use emg_control::{ClassicalGains, RolloutConfig, SamplerConfig, Task, TaskSampler, read_tasks};
use emg_kinematics::{Robot, Vec3};

use crate::args::PlanArgs;

/// The tasks requested by `args`, each validated by [`Task::new`].
pub fn requested_tasks(robot: &Robot, args: &PlanArgs) -> Result<Vec<Task>> {
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
        _ => Ok(vec![demo_task(robot)?]),
    }
}

/// Smallest singular value (m/rad) of the position Jacobian at which the mid-range
/// configuration still makes a demo: below it the arm is too near a singularity (an arm whose
/// mid-range configuration is stretched out, like the iiwa's, cannot move its TCP sideways).
const DEMO_MIN_SINGULAR_VALUE: f64 = 0.05;

/// The built-in demo task: from the mid-range configuration, `p0` = its TCP, `n` = its tool
/// axis, `d` = +y made perpendicular to `n`; `q0_seed` = the mid-range configuration. When the
/// mid-range configuration is near a singularity, the first task of the robot's task population
/// (`emg_control::TaskSampler` with its default settings) instead.
pub fn demo_task(robot: &Robot) -> Result<Task> {
    let seed = robot.mid_range();
    let kinematics = robot.forward(&seed);
    let smallest = kinematics.jacobian().singular_values().min();
    if smallest < DEMO_MIN_SINGULAR_VALUE {
        let (rollout, gains) = (RolloutConfig::default(), ClassicalGains::default());
        let config = SamplerConfig::default();
        let mut sampler = TaskSampler::new(robot, &rollout, &gains, &config);
        return sampler
            .take(1, &|_| {})
            .pop()
            .context("the robot's task population yields no demo task");
    }
    let n = kinematics.tool_axis();
    let y = Vec3::y();
    let d = (y - n * y.dot(&n)).normalize();
    Task::new(robot, kinematics.tcp(), d, n, Some(seed))
        .context("the built-in demo task is invalid")
}
