//! Lengths every stage of a job measures by: a leaf module the stages share.

/// Pen-down lengths closer than this (m) count as the same: of two starts of a stroke that draw
/// as far, the nearer one to the arm is taken; places that draw as much rank by duration.
pub const SAME_LENGTH_M: f64 = 1e-3;

/// A job's line tolerance unless it is given another (m): what a pen, a bead or a seam needs.
pub const JOB_TOLERANCE_M: f64 = 5e-4;
