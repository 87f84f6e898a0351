//! The vector types and joint counts every module computes with.

/// Most revolute joints a supported arm may have: the length of every [`JointVector`].
pub const MAX_DOF: usize = 7;

/// Fewest revolute joints a supported arm may have: three fix the TCP's position and at least
/// three more move it in the null space (the pen's free roll and its tilt inside the cone), as
/// the null-space step needs.
pub const MIN_DOF: usize = 6;

/// A joint-space vector (configuration, velocity or gradient), radians. An arm of
/// [`Robot::dof`](crate::Robot::dof) `< MAX_DOF` joints uses the leading entries; the others are
/// zero and stay zero (its Jacobian's trailing columns are zero, so no step moves them).
pub type JointVector = nalgebra::SVector<f64, MAX_DOF>;

/// A Cartesian 3-vector, metres or unit direction.
pub type Vec3 = nalgebra::Vector3<f64>;
