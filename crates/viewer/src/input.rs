//! What one viewer page of a planned line shows.

use emg_control::{ConstraintConfig, Task, Trajectory};
use emg_kinematics::Robot;

/// Everything one viewer page shows: the arm, its task, the planned motion and its limits.
#[derive(Clone, Copy, Debug)]
pub struct ViewerInput<'a> {
    /// The arm that moves (its capsules are drawn).
    pub robot: &'a Robot,
    /// The straight-line task `(p0, d, n)`.
    pub task: &'a Task,
    /// The planned rollout; its timestamps drive the playback.
    pub trajectory: &'a Trajectory,
    /// The constraints it was planned under (line tolerance, tool-cone half-angle, work surface
    /// and obstacles are drawn).
    pub constraints: &'a ConstraintConfig,
    /// Page title and heading (plain text; escaped as needed).
    pub title: &'a str,
}
