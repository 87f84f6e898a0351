//! Rest-to-rest timing of planned joint paths, for robots that enforce acceleration and jerk
//! limits (libfranka stops a motion whose acceleration jumps):
//!
//! 1. [`SmoothPath`]: a natural cubic spline ([`JointSpline`], C²) through the planned
//!    waypoints (on a path, their step-to-step jitter of posture smoothed out, every TCP kept;
//!    inner ones moved [`JOINT_INSET_RAD`] inside the joint limits, [`CLEARANCE_INSET_M`] clear
//!    of the arm's own links and [`CONE_INSET_DEG`] inside the tool cone where they ride them),
//!    checked against every task constraint on a dense sampling and
//!    refined where it fails;
//! 2. [`topp_ra`]: the time-optimal path speed under joint velocity and acceleration limits and
//!    a tool-speed cap (Pham & Pham 2018), from rest to rest;
//! 3. [`SmoothedProfile`]: jerk limiting by a moving average of the path position in time;
//! 4. [`time_motion`]: all of it, sampled at a fixed rate, slowed down locally wherever a sample
//!    still breaks a limit ([`first_breach`]); a path task's motion comes to rest at every corner
//!    its path does not blend ([`rest_waypoints`]), each stretch between rests timed on its own.
//!
//! A move through free space between strokes is a joint polyline: [`time_free_move`] keeps to
//! its edges, at rest at every vertex; [`time_blended_move`] rounds its corners and passes them
//! without stopping.
//!
//! Every timed motion comes with its [`MotionDefinition`]: its paths and the speed profile
//! along each, from which [`MotionDefinition::samples`] gives its samples again.
//!
//! Limits a URDF cannot hold come from a MoveIt `joint_limits.yaml` ([`DynamicLimits`]).

mod blend;
mod blended_path;
mod bound;
mod dynamics;
mod free;
mod inset;
mod limits;
mod motion;
mod path;
mod profile;
mod retime;
mod sampling;
mod spline;
mod topp;

pub use blend::time_blended_move;
pub use blended_path::MAX_BLEND_TURN_DEG;
pub use bound::{least_move_s, rest_to_rest_s};
pub use dynamics::{LimitBreach, TimedSample, breaches, first_breach};
pub use free::{FREE_GRID_PER_RAD, TimedMove, time_free_move};
pub use inset::{CLEARANCE_INSET_M, CONE_INSET_DEG, JOINT_INSET_RAD};
pub use limits::{
    ASSUMED_ACCELERATION_RAD_S2, ASSUMED_JERK_RAD_S3, DynamicLimits, LimitsError, Scaling,
};
pub use motion::{MAX_SAMPLES, MotionDefinition, ProfileGrid, SplineStretch};
pub use path::{
    CHECKS_PER_SEGMENT, KNOT_STEP_M_PER_RAD, KNOT_STRIDE, LINE_CHECK_MARGIN_M, MAX_REFINEMENTS,
    MIN_KNOT_STEP_M, SMOOTHING_ROUNDS, SmoothPath,
};
pub use profile::{PathState, SmoothedProfile, SpeedProfile};
pub use retime::{
    ACCELERATION_MARGIN, AT_TOOL_SPEED, GRID_STEP_M, MAX_FORCED_RESTS, MAX_SLOWDOWNS,
    MIN_GRID_INTERVALS, PASSING_WINDOW_RAD, REST_SNAP_M, SLOWDOWN, TimedMotion, TimingError,
    TimingReport, TimingRequest, rest_waypoints, time_motion, waypoint_progress,
};
pub use spline::{JointSpline, PathPoint};
pub use topp::{GridPoint, profile_duration, topp_ra};
