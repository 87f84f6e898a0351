//! The built-in demo task of a robot.

use emg_control::{ClassicalGains, RolloutConfig, SamplerConfig, Task, TaskError, TaskSampler};
use emg_kinematics::{Robot, Vec3};

/// Smallest singular value (m/rad) of the position Jacobian at which the mid-range
/// configuration still makes a demo: below it the arm is too near a singularity (an arm whose
/// mid-range configuration is stretched out, like the iiwa's, cannot move its TCP sideways).
const DEMO_MIN_SINGULAR_VALUE: f64 = 0.05;

/// Candidates of the task population tried for a demo task before the mid-range task is used
/// all the same.
const DEMO_MAX_CANDIDATES: u64 = 4096;

/// The built-in demo task: from the mid-range configuration, `p0` = its TCP, `n` = its tool
/// axis, `d` = +y made perpendicular to `n`; `q0_seed` = the mid-range configuration. When the
/// mid-range configuration is near a singularity, the first task of the robot's task population
/// (`emg_control::TaskSampler` with its default settings) instead (or, should none of its
/// first `DEMO_MAX_CANDIDATES` candidates be accepted, the mid-range task all the same).
pub fn demo_task(robot: &Robot) -> Result<Task, TaskError> {
    let seed = robot.mid_range();
    let kinematics = robot.forward(&seed);
    let smallest = kinematics.jacobian().singular_values().min();
    if smallest < DEMO_MIN_SINGULAR_VALUE {
        let (rollout, gains) = (RolloutConfig::default(), ClassicalGains::default());
        let config = SamplerConfig::default();
        let mut sampler = TaskSampler::new(robot, &rollout, &gains, &config);
        if let Some(task) = sampler.take(1, DEMO_MAX_CANDIDATES, &|_| {}).pop() {
            return Ok(task);
        }
    }
    let n = kinematics.tool_axis();
    let y = Vec3::y();
    let d = (y - n * y.dot(&n)).normalize();
    Task::new(robot, kinematics.tcp(), d, n, Some(seed))
}
