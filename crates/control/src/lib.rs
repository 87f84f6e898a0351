//! Straight-line and path tasks, their constraints, the one rollout loop every controller shares, the
//! classical null-space controller, the task and path populations, and the hand-over of rollouts to the
//! independent checker (`emg-verify`).
//!
//! A controller implements [`NullSpaceController`]: at each step it sees a [`StepContext`]
//! (kinematics, gradients, the basis `B(q)`, `ρ(q)`) and returns an action `a ∈ [−1, 1]⁴`;
//! [`rollout`] applies `q̇ = J⁺ẋ + a_max B a` (Eq. 2) and stops at the first broken constraint.
//!
//! ```
//! use emg_control::{CheckRollout, ClassicalController, RolloutConfig, Task, rollout};
//! use emg_verify::ReferenceModel;
//! use emg_kinematics::{Robot, Vec3};
//! let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../../data/robots/fr3_pen.urdf");
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

mod classical;
mod config;
mod constraints;
mod controller;
mod path;
mod path_population;
mod rollout;
mod sampler;
mod step;
mod task;
mod tracking;
mod verification;

pub use classical::{ClassicalController, lead_axis};
pub use config::{
    ClassicalGains, ConstraintConfig, MAX_STEPS_CAP, OutOfRange, RolloutConfig, Tracking,
    VelocityLimitFraction,
};
pub use constraints::{Violation, WORK_SURFACE, first_contact, first_violation, tool_angle_deg};
pub use controller::{ActingController, NullSpaceController};
pub use path::{
    CORNER_RAD, Located, MIN_SEGMENT_M, PATH_FORMAT_VERSION, PLANE_TOLERANCE_M,
    PROGRESS_CONTINUITY, Path, PathError, PathExtent, PathSpec, Piece, SegmentSpec,
};
pub use path_population::{PathShape, path_tasks, population_path};
pub use rollout::{
    Episode, StepOutcome, StepRecord, Termination, Trajectory, continue_rollout, rollout,
};
pub use sampler::{SamplerConfig, TaskSampler, candidate, surface_clears};
pub use step::{NullAction, StepContext};
pub use task::{
    ARRIVAL_M, Along, PERPENDICULAR_TOLERANCE, PROGRESS_PER_DISTANCE, PROGRESS_SLACK_M,
    SEED_POSITION_TOLERANCE_M, TRACKING_WINDOW_M, Task, TaskError, progress_window_m,
};
pub use tracking::{
    CORRECTION_DAMPING, CORRECTION_TRIGGER, MAX_CORRECTIONS, correct_onto_task, onto_task,
};
pub use verification::{CheckRollout, task_bounds};
