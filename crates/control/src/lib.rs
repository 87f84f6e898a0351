//! Straight-line tasks, their constraints, the one rollout loop every controller shares, the
//! classical null-space controller, an independent trajectory checker, trajectory files a robot
//! stack can replay, and the task population.
//!
//! A controller implements [`NullSpaceController`]: at each step it sees a [`StepContext`]
//! (kinematics, gradients, the basis `B(q)`, `ρ(q)`) and returns an action `a ∈ [−1, 1]⁴`;
//! [`rollout`] applies `q̇ = J⁺ẋ + a_max B a` (Eq. 2) and stops at the first broken constraint.
//!
//! ```
//! use emg_control::{ClassicalController, ReferenceModel, RolloutConfig, Task, rollout};
//! use emg_kinematics::{Robot, Vec3};
//! let path = emg_kinematics::default_robot_path();
//! let robot = Robot::from_urdf_file(&path, "link0", "pen_tip")?;
//! let seed = robot.mid_range();
//! let kin = robot.forward(&seed);
//! let task = Task::new(&robot, kin.tcp(), Vec3::y(), kin.tool_axis(), Some(seed))?;
//! let config = RolloutConfig::default();
//! let mut controller = ClassicalController::default();
//! let trajectory = rollout(&robot, &task, &seed, &mut controller, &config);
//! assert!(trajectory.path_length_m > 0.1);
//! let checker = ReferenceModel::from_urdf_file(&path, "link0", "pen_tip")?;
//! checker.check(&task, &trajectory, &config.constraints)?;
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```

mod checker;
mod classical;
mod config;
mod constraints;
mod controller;
mod evaluation;
mod joint_trajectory;
mod rollout;
mod sampler;
mod step;
mod task;
mod task_file;

pub use checker::{CheckFailure, ReferenceModel};
pub use classical::ClassicalController;
pub use config::{ClassicalGains, ConstraintConfig, RolloutConfig, VelocityLimitFraction};
pub use constraints::{Violation, first_violation, tool_angle_deg};
pub use controller::{ActingController, NullSpaceController};
pub use evaluation::{
    Summary, joint_limit_histogram, rollout_all, rollout_from, termination_histogram,
};
pub use joint_trajectory::{
    CSV_HEADER, DECLARED_VELOCITY_TOLERANCE, GAP_ROUNDING_NOISE_NS, JOINT_TRAJECTORY_FORMAT,
    JointSamples, JointTrajectory, JointTrajectoryError, JointTrajectoryPoint, ReplayError,
    ReplayReport, TimeFromStart, VELOCITY_LIMIT_SLACK, check_joint_names, check_replay,
    point_velocities, read_csv, times_from_start, trajectory_csv,
};
pub use rollout::{Episode, StepOutcome, StepRecord, Termination, Trajectory, rollout};
pub use sampler::{SamplerConfig, TaskSampler, candidate};
pub use step::{NullAction, StepContext};
pub use task::{PERPENDICULAR_TOLERANCE, SEED_POSITION_TOLERANCE_M, Task, TaskError};
pub use task_file::{TASK_FORMAT_VERSION, TaskFileError, TaskSpec, read_tasks, write_task_set};
