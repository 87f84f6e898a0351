//! Every file format of the workspace's motions and tasks, and the one atomic write they share.
//!
//! * [`TrajectoryFile`] / [`RolloutRecord`]: the `emg-trajectory/1` JSON of a planned task (task,
//!   settings, every step, why it ended), written and read back.
//! * [`JointTrajectory`]: the `emg-joint-trajectory/1` JSON a robot stack replays (ROS
//!   `trajectory_msgs/JointTrajectory`-like, times in whole nanoseconds).
//! * [`trajectory_csv`] / [`read_csv`]: the CSV table of a rollout.
//! * [`TrajectoryContents`]: any of the three, told apart by content, as the independent
//!   checker's [`emg_verify::JointSamples`].
//! * [`read_tasks`] / [`write_task_set`]: task sets (binary `EMGTASKS` or JSON).
//! * [`write_atomically`]: every file of the workspace is written through a uniquely named `.partial`
//!   sibling renamed into place; [`open_journal`]: a resumable job's journal directory, claimed
//!   for one job's identity.
//!
//! Velocities in every file follow [`emg_verify::point_velocities`], so the checker recomputes
//! exactly what the writers declare.
//!
//! ```
//! use emg_control::{ClassicalController, RolloutConfig, Task, rollout};
//! use emg_io::JointTrajectory;
//! use emg_kinematics::{Robot, Vec3};
//! let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../../data/robots/fr3_pen.urdf");
//! let robot = Robot::from_urdf_file(&path, "link0", "pen_tip")?;
//! let seed = robot.mid_range();
//! let kin = robot.forward(&seed);
//! let task = Task::new(&robot, kin.tcp(), Vec3::y(), kin.tool_axis(), Some(seed))?;
//! let config = RolloutConfig { max_steps: 20, ..RolloutConfig::default() };
//! let trajectory = rollout(&robot, &task, &seed, &mut ClassicalController::default(), &config);
//!
//! let file = JointTrajectory::new("fr3", robot.joint_names(), &task, &config.constraints,
//!                                 &trajectory)?;
//! let back = JointTrajectory::from_json(&file.to_json())?;
//! assert_eq!(back, file);
//!
//! let checker = emg_verify::ReferenceModel::from_urdf_file(&path, "link0", "pen_tip")?;
//! let report = emg_verify::check_replay(&checker, &(&back.task).into(),
//!                                       &(&back.constraints).into(), &back.samples(), None)?;
//! assert_eq!(report.points, 21);
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```

mod atomic;
mod contents;
mod csv;
mod error;
mod joint_trajectory;
mod paths;
mod rollout_file;
mod task_file;

pub use atomic::{JournalError, open_journal, write_atomically};
pub use contents::{Carried, ReadError, TrajectoryContents, VerifyFailure};
pub use csv::{CSV_HEADER, read_csv, samples_from_steps, trajectory_csv};
pub use error::FormatError;
pub use joint_trajectory::{
    GAP_ROUNDING_NOISE_NS, JOINT_TRAJECTORY_FORMAT, JointTrajectory, JointTrajectoryPoint,
    TimeFromStart, times_from_start,
};
pub use paths::{PlanPaths, html_path};
pub use rollout_file::{RolloutRecord, TRAJECTORY_FORMAT, TrajectoryFile};
pub use task_file::{
    TASK_FORMAT_VERSION, TaskFileError, TaskSpec, parse_tasks, read_tasks, write_task_set,
};
