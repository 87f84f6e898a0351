//! The tangent space of the self-motion family: motions that keep the pose `(p0, tool axis)`.

use emg_kinematics::{JointVector, MAX_DOF, PoseTarget, Robot, pose_residual};
use nalgebra::SMatrix;

/// The orthogonal projector `P = I − Mᵀ(MMᵀ + εI)⁻¹M` onto the null space of the pose rows `M`
/// of [`pose_residual`] at `q` (rank 2 for a roll-free target, 1 with a roll axis): joint
/// motions along `P v` keep the TCP position and tool axis to first order. The rows and columns
/// past the arm's joints are zero (those joints do not exist, so no motion moves them).
/// Allocation-free.
pub fn self_motion_projector(
    robot: &Robot,
    q: &JointVector,
    target: &PoseTarget,
    damping: f64,
) -> SMatrix<f64, MAX_DOF, MAX_DOF> {
    let (rows, _) = pose_residual(&robot.forward(q), target);
    let gram = rows * rows.transpose() + SMatrix::<f64, 6, 6>::identity() * damping;
    let identity = SMatrix::<f64, MAX_DOF, MAX_DOF>::identity();
    let mut projector = match gram.cholesky() {
        Some(c) => identity - rows.transpose() * c.solve(&rows),
        None => SMatrix::zeros(),
    };
    for absent in robot.dof()..MAX_DOF {
        projector.row_mut(absent).fill(0.0);
        projector.column_mut(absent).fill(0.0);
    }
    projector
}
