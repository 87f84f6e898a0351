//! An independent reader of the URScript programs written for the UR5e, checked against the
//! job's plan (or the timed motion) they were written from.
//!
//! Two forms are read: a job's native program (`emg job --export urscript`; [`read_native`]),
//! and the joint stream of `servoj` targets every 2 ms (`--urscript servoj`, one or more
//! programs; [`read_servoj`], [`read_servoj_motion`]). The native reader holds a parser of the
//! subset of URScript such a program holds ([`parse_program`]), an interpreter of its moves as
//! the Universal Robots URScript manual defines them (`movej` linear in joint space, `movel` on a
//! straight line with its orientation slerped, runs of `movep` on straight lines joined by
//! circular blends; [`movep_path`]), the UR5e's closed-form inverse kinematics as the controller
//! follows a Cartesian move ([`ur5e_inverse`], [`ur5e_follow`]), and the checks of what the
//! program makes the arm do against the job's plan, measured with the independent checker
//! (`emg_verify`). The servoj reader checks each target against the plan's sample at its time,
//! and the joints, speeds and accelerations against the plan's limits.
//!
//! **Invariant:** the reader shares no code with the exporters (`emg_job::ur_program`, the
//! URScript writer of `emg_io::export`): the plan's data types and the checker are all it reads
//! besides the script, so an exporter's mistake cannot cancel out in its reading.

mod error;
mod geometry;
mod native;
mod script;
mod servoj;
mod ur5e;

pub use error::ReadError;
pub use geometry::{Pose, Rotation, angle_deg, wrap};
pub use native::{
    JOINT_MATCH_RAD, JOINT_STEP_RAD, JointPiece, MAX_JOINT_JUMP_RAD, NativeReport, PATH_STEP_M,
    POSE_MATCH, Piece, TURN_STEP_RAD, movej_path, movep_path, read_native,
};
pub use script::{Form, Output, Program, Statement, parse_program};
pub use servoj::{
    ACCELERATION_SLACK, SERVO_PERIOD_S, ServojReport, TARGET_MATCH_RAD, TimedMotion, quintic,
    read_servoj, read_servoj_motion,
};
pub use ur5e::{
    Branch, IkSolution, UR5E_A, UR5E_ALPHA, UR5E_D, checker_joints, checker_tcp,
    nearest_equivalent, ur5e_flange, ur5e_follow, ur5e_inverse,
};
