//! Kinematics of a serial arm of six or seven revolute joints holding a tool, as used by extreme
//! straight-line motion.
//!
//! A [`Robot`] is read once from a URDF file (the chain between two named links, its joint
//! limits, velocity limits and capsule collision geometry) and then shared freely across
//! threads. Everything else is a plain function of the robot and a joint vector, computed on
//! the stack with fixed-size `nalgebra` types so the control step allocates nothing:
//!
//! * [`Robot::forward`]: every joint frame, the TCP position `p(q)` and the tool axis `z(q)`;
//!   from it the 3×n position Jacobian and the tool-axis Jacobian ([`Kinematics`]).
//! * [`directional_manipulability`]: `w_d` and its Hessian-based analytic gradient.
//! * [`tool_alignment_gradient`]: the gradient of `z(q)·n`.
//! * [`damped_pseudo_inverse`]: `J⁺` with variable damping (Eq. 2 of the paper).
//! * [`null_space_basis`] and [`task_aligned_basis`]: `N` and the Gram–Schmidt basis `B(q)`.
//! * [`Robot::first_collision`] and [`Robot::min_clearance`]: capsule clearances between bodies at
//!   least three links apart, or between every two bodies but those an SRDF file beside the robot
//!   file disables ([`PairRule`]).
//! * [`fit_capsules`]: bounding capsules of meshes and other collision geometry.
//! * [`Robot::first_contact`]: capsule clearances from the obstacles of a [`Scene`] and from a
//!   task's work surface ([`WorkSurface`]: a finite [`Plate`] or a half-space).
//! * [`project_to_pose`]: Newton projection onto an exact `(p0, n[, roll])` pose within limits.
//!
//! ```
//! use emg_kinematics::{JointVector, Robot, Vec3};
//! use std::f64::consts::{FRAC_PI_2, FRAC_PI_4};
//! let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../../data/robots/fr3_pen.urdf");
//! let robot = Robot::from_urdf_file(path, "link0", "pen_tip")?;
//! let home = JointVector::from_column_slice(&[0.0, -FRAC_PI_4, 0.0, -3.0 * FRAC_PI_4, 0.0, FRAC_PI_2, FRAC_PI_4]);
//! let kin = robot.forward(&home);
//! assert!((kin.tcp() - Vec3::new(0.306891, 0.0, 0.386882)).norm() < 1e-6);
//! assert!((kin.tool_axis() - Vec3::new(0.0, 0.0, -1.0)).norm() < 1e-9);
//! assert!(robot.first_collision(&kin, 0.0).is_none());
//! # Ok::<(), emg_kinematics::RobotError>(())
//! ```

mod broad_phase;
mod capsule;
mod clearance_floor;
mod collision;
mod error;
mod fit;
mod fk;
mod manipulability;
mod nullspace;
mod projection;
mod pseudo_inverse;
mod robot;
mod rotation;
mod scene;
mod srdf;
mod vectors;

pub use capsule::{Capsule, CollisionHit, CollisionPair, MAX_CAPSULES, segment_distance};
pub use error::RobotError;
pub use fit::{Ball, Covered, FittedCapsule, fit_capsules};
pub use fk::{Kinematics, PositionJacobian};
pub use manipulability::{directional_manipulability, tool_alignment_gradient};
pub use nullspace::{BasisConfig, NullSpaceBasis, TaskBasis, null_space_basis, task_aligned_basis};
pub use projection::{
    POINT_ITERATIONS, POINT_TOLERANCE_M, PoseTarget, ProjectionConfig, ProjectionError,
    pose_residual, project_to_point, project_to_pose,
};
pub use pseudo_inverse::{DampedPseudoInverse, DampingConfig, damped_pseudo_inverse};
pub use robot::{CONTINUOUS_JOINT_RANGE_RAD, JointLimits, Robot};
pub use rotation::{Transform, rotation_about, rotation_from_rpy, rotation_onto, rpy_of};
pub use scene::{
    ContactHit, Obstacle, ObstacleError, Plate, Scene, Shape, ToolContact, WorkSurface,
    capsule_ray_entry,
};
pub use srdf::{MIN_LINK_SEPARATION, PairRule, disabled_pairs, srdf_beside};
pub use vectors::{JointVector, MAX_DOF, MIN_DOF, Vec3};
