//! Every file format of the workspace's motions and tasks, and the one atomic write they share.
//!
//! * [`TrajectoryFile`] / [`RolloutRecord`]: the `emg-trajectory/1` JSON of a planned task (task,
//!   settings, every step, why it ended), written and read back.
//! * [`JointTrajectory`]: the `emg-joint-trajectory/2` JSON a robot stack replays (ROS
//!   `trajectory_msgs/JointTrajectory`-like: a rest-to-rest motion at a fixed rate with
//!   positions, velocities and accelerations, times in whole nanoseconds).
//! * [`trajectory_csv`] / [`read_csv`]: the CSV table of a rollout.
//! * [`TrajectoryContents`]: any of the three, told apart by content, as the independent
//!   checker's [`emg_verify::JointSamples`].
//! * [`read_tasks`] / [`write_task_set`]: task sets (binary `EMGTASKS` or JSON).
//! * [`read_scene`]: the obstacles of a cell (JSON, see [`emg_kinematics::Scene`]).
//! * [`read_path`]: a path task's segments (JSON, see [`emg_control::PathSpec`]).
//! * [`import_robot`]: a vendor description (boxes, cylinders, STL/OBJ meshes) as a standard
//!   capsule URDF with a pen, and [`read_mesh`]: mesh files as triangles.
//! * [`export`]: a joint trajectory for a robot's own stack: a ROS 2 `JointTrajectory` in an
//!   MCAP file (its points thinned, [`ThinningReport`]) or a URScript program
//!   (`docs/robot-export.md`).
//! * [`RobotRef`]: how every written file names its robot (a shipped robot by name, any other
//!   robot file by its path as given, each with the digest of its file), resolved again where
//!   the file is read.
//! * [`write_atomically`]: every file of the workspace is written through a uniquely named `.partial`
//!   sibling renamed into place; [`open_journal`]: a resumable job's journal directory, claimed
//!   for one job's identity.
//!
//! Velocities in the rollout files follow [`emg_verify::point_velocities`], so the checker
//! recomputes exactly what the writers declare.
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
//! let limits_file = path.with_file_name("fr3_pen.joint_limits.yaml");
//! let limits = emg_timing::DynamicLimits::read(&limits_file, &robot)?;
//! let request = emg_timing::TimingRequest {
//!     limits: limits.clone(), tool_speed_m_per_s: 0.2, rate_hz: 1000.0,
//! };
//! let waypoints: Vec<_> = trajectory.steps.iter().map(|s| s.q).collect();
//! let motion = emg_timing::time_motion(&robot, &task, &config.constraints, &waypoints, &request)?;
//! let record = emg_io::TimingLimits {
//!     joint_limits_file: limits_file.display().to_string(),
//!     velocity_scaling: 1.0, acceleration_scaling: 1.0, tool_speed_m_per_s: 0.2,
//!     max_velocity: limits.velocity.as_slice().to_vec(),
//!     max_acceleration: limits.acceleration.as_slice().to_vec(),
//!     max_jerk: limits.jerk.as_slice().to_vec(),
//! };
//! let file = JointTrajectory::new("fr3", robot.joint_names(), &task, &config.constraints,
//!                                 record, &motion, 1000.0)?;
//! let back = JointTrajectory::from_json(&file.to_json())?;
//! assert_eq!(back, file);
//!
//! let checker = emg_verify::ReferenceModel::from_urdf_file(&path, "link0", "pen_tip")?;
//! let report = emg_verify::check_replay(&checker, &(&back.task).into(),
//!                                       &(&back.constraints).into(), &back.samples(), None,
//!                                       Some(&back.limits.dynamics()))?;
//! assert_eq!(report.points, motion.samples.len());
//! assert!(report.dynamics.is_some());
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```

mod atomic;
mod contents;
mod csv;
mod error;
mod export;
mod joint_trajectory;
mod mesh;
mod path_file;
mod paths;
mod robot_import;
mod robot_ref;
mod rollout_file;
mod scene_file;
mod svg;
mod task_file;

pub use atomic::{JournalError, open_journal, write_atomically};
pub use contents::{Carried, ReadError, TrajectoryContents, VerifyFailure, task_file_beside};
pub use csv::{csv_header, read_csv, samples_from_steps, trajectory_csv};
pub use error::FormatError;
pub use export::{
    DRIVER_PROFILES, DriverProfile, Export, ExportError, ExportFormat, ExportOptions, ExportRobot,
    JOINT_TRAJECTORY_TYPE, TOOL_OUTPUT_TOPIC, TOOL_OUTPUT_TYPE, ThinningReport, TimedPoints,
    ToolSwitch, ToolSwitching, UR_JOINT_NAMES, export, home_check, is_universal_robots_arm,
    joint_list, read_joint_trajectory,
};
pub use joint_trajectory::{
    JOINT_TRAJECTORY_FORMAT, JointTrajectory, JointTrajectoryPoint, TimeFromStart, TimingLimits,
    TimingSummary,
};
pub use mesh::{MeshError, mesh_volume, read_mesh};
pub use path_file::{PathFileError, parse_path, read_path};
pub use paths::{OutputClash, PlanPaths, html_path, refuse_overwriting};
pub use robot_import::{
    DisabledBecause, ImportError, ImportOptions, ImportedRobot, LinkFit, PEN_LINK,
    PEN_PROTRUSION_M, PEN_REACH_TOLERANCE_M, PackagePath, Pen, REP_199_TOOL_LINKS, ToolLinkChoice,
    ToolReach, import_robot,
};
pub use robot_ref::{RobotRef, RobotRefError, file_sha256};
pub use rollout_file::{RolloutRecord, TRAJECTORY_FORMAT, TrajectoryFile};
pub use scene_file::{SceneFileError, read_scene};
pub use svg::{
    Drawing, DrawingBounds, MAX_SMOOTH_JOIN_DEG, MIN_CURVE_TOLERANCE_M, Placement, SVG_PX_M,
    SvgError, SvgFileError, SvgOptions, read_svg, read_svg_file, scattered_strokes_svg,
};
pub use task_file::{
    TASK_FORMAT_VERSION, TaskFileError, TaskSpec, parse_tasks, read_each_task, read_tasks,
    write_task_set,
};
