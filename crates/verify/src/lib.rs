//! The independent checker: it re-reads the robot file itself ([`ReferenceModel`]) and verifies
//! recorded motions ([`ReferenceModel::check_recording`]) and trajectory files ([`check_replay`])
//! point by point, with plain 4×4 transforms, its own collision-pair rule and its own
//! segment-distance routine.
//!
//! Its independence is enforced by the compiler: this crate depends on no other crate of the
//! workspace, so a shortcut or a bug in the planners' kinematics or constraint code cannot hide a
//! violation here. Planners hand it plain data ([`Line`], [`Bounds`], [`Recording`]).
//!
//! ```
//! use emg_verify::{Bounds, Ending, Line, RecordedStep, Recording, ReferenceModel};
//! let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../../data/robots/fr3_pen.urdf");
//! let model = ReferenceModel::from_urdf_file(&path, "link0", "pen_tip")?;
//! let q = emg_verify::Joints::from_column_slice(&[0.0, -0.5, 0.0, -2.0, 0.0, 1.6, 0.8]);
//! let (tcp, axis) = model.tcp_pose(&q);
//! let line = Line::straight(tcp, axis.cross(&nalgebra::Vector3::x()).normalize(), axis);
//! let bounds = Bounds {
//!     line_tolerance_m: 0.02,
//!     theta_max_deg: 30.0,
//!     collision_margin_m: 0.0,
//!     velocity_limit_fraction: Some(1.0),
//!     work_surface: None,
//!     obstacles: Vec::new(),
//! };
//! let start = RecordedStep { time_s: 0.0, q, tcp, tool_angle_deg: 0.0 };
//! let recording = Recording { steps: vec![start], ending: Ending::Stopped, path_length_m: 0.0 };
//! model.check_recording(&line, &recording, &bounds)?;
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```

mod check;
mod dynamics;
mod model;
mod record;
mod replay;
mod samples;

pub use check::{CheckFailure, FailedCheck};
pub use dynamics::{
    DYNAMICS_LIMIT_SLACK, DynamicsCheck, DynamicsFailure, DynamicsReport, JointDynamics,
    REST_TOLERANCE, check_dynamics,
};
pub use model::{ModelError, ReferenceModel};
pub use record::{
    Blame, Bounds, Ending, Joints, Line, MAX_JOINTS, MIN_JOINTS, Obstacle, PATH_CONTINUITY,
    PATH_CORNER_PASS_M, PATH_CORNER_RAD, PATH_PROGRESS_PER_DISTANCE, PATH_PROGRESS_SLACK_M,
    PATH_WINDOW_M, PathPiece, RecordedStep, Recording, Solid, Surface,
};
pub use replay::{
    DECLARED_VELOCITY_TOLERANCE, ReplayCheck, ReplayError, ReplayReport, VELOCITY_LIMIT_SLACK,
    check_joint_names, check_replay, point_velocities,
};
pub use samples::JointSamples;
