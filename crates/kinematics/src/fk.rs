//! Forward kinematics: joint frames, TCP position `p(q)`, tool axis `z(q)` and their Jacobians.

use nalgebra::{Isometry3, Matrix3, SMatrix, Translation3, UnitQuaternion};

use crate::robot::Robot;
use crate::vectors::{JointVector, MAX_DOF, Vec3};

/// The 3×n position Jacobian `J = ∂p/∂q` of the TCP, zero-padded to 3×[`MAX_DOF`] (columns
/// past the arm's joints are exactly zero).
pub type PositionJacobian = SMatrix<f64, 3, MAX_DOF>;

/// Everything forward kinematics yields for one configuration; computed on the stack.
///
/// Segment `s` is the rigid body after joint `s` (segment 0 is the base): its frame is the
/// frame of joint `s`, turned by `q_s` about its local +z.
#[derive(Clone, Debug)]
pub struct Kinematics {
    configuration: JointVector,
    dof: usize,
    rotations: [Matrix3<f64>; MAX_DOF + 1],
    positions: [Vec3; MAX_DOF + 1],
    tcp: Vec3,
    tcp_rotation: Matrix3<f64>,
    jacobian: PositionJacobian,
}

impl Robot {
    /// Forward kinematics of configuration `q` (no allocation).
    pub fn forward(&self, q: &JointVector) -> Kinematics {
        let mut kinematics = Kinematics {
            configuration: *q,
            dof: self.dof,
            rotations: [Matrix3::identity(); MAX_DOF + 1],
            positions: [Vec3::zeros(); MAX_DOF + 1],
            tcp: Vec3::zeros(),
            tcp_rotation: Matrix3::identity(),
            jacobian: PositionJacobian::zeros(),
        };
        self.forward_into(q, &mut kinematics);
        kinematics
    }

    /// [`Robot::forward`] of `q` written over `kinematics` (a `Kinematics` of this robot), so a
    /// caller that keeps its kinematics in place (the rollout's step) copies none of it.
    pub fn forward_into(&self, q: &JointVector, kinematics: &mut Kinematics) {
        let Kinematics {
            configuration,
            dof: _,
            rotations,
            positions,
            tcp,
            tcp_rotation,
            jacobian,
        } = kinematics;
        *configuration = *q;
        // Every sine and cosine first: a library call clobbers every floating-point register,
        // so calls inside the loop would spill the chain of rotations around each of them.
        let turns: [(f64, f64); MAX_DOF] = std::array::from_fn(|i| libm::sincos(q[i]));
        for (i, (joint, &(sin, cos))) in self.joints.iter().zip(&turns).enumerate() {
            let (parent_rotation, parent_position) = (rotations[i], positions[i]);
            let fixed: Matrix3<f64> = parent_rotation * joint.rotation;
            let (c0, c1) = (fixed.column(0), fixed.column(1));
            let mut rotation = fixed;
            rotation.set_column(0, &(c0 * cos + c1 * sin));
            rotation.set_column(1, &(c1 * cos - c0 * sin));
            rotations[i + 1] = rotation;
            positions[i + 1] = parent_position + parent_rotation * joint.translation;
        }
        // The TCP hangs off the last joint's segment; an absent joint's slot (zero axis) after
        // it turns nothing that is read.
        let last = rotations[self.dof];
        *tcp = positions[self.dof] + last * self.tcp_offset.translation;
        *tcp_rotation = last * self.tcp_offset.rotation;
        for i in 0..MAX_DOF {
            let axis = rotations[i + 1].column(2).into_owned();
            jacobian.set_column(i, &axis.cross(&(*tcp - positions[i + 1])));
        }
    }
}

impl Kinematics {
    /// The configuration `q` these kinematics are of.
    pub fn configuration(&self) -> &JointVector {
        &self.configuration
    }

    /// TCP (pen tip) position `p(q)`, metres.
    pub fn tcp(&self) -> Vec3 {
        self.tcp
    }

    /// Tool axis `z(q)`: the TCP frame's unit z-axis.
    pub fn tool_axis(&self) -> Vec3 {
        self.tcp_rotation.column(2).into_owned()
    }

    /// TCP orientation as a rotation matrix (columns are the TCP frame axes).
    pub fn tcp_rotation(&self) -> &Matrix3<f64> {
        &self.tcp_rotation
    }

    /// Position Jacobian `J(q)`, column `i` = `ω_i × (p − o_i)`.
    pub fn jacobian(&self) -> &PositionJacobian {
        &self.jacobian
    }

    /// `JJᵀ` (3×3), computed on each call.
    pub fn jacobian_gram(&self) -> Matrix3<f64> {
        self.jacobian * self.jacobian.transpose()
    }

    /// The arm's number of joints `n` ([`Robot::dof`]).
    pub fn dof(&self) -> usize {
        self.dof
    }

    /// Unit rotation axis `ω_i` of joint `i` (0-based) in the base frame; zero for `i ≥ n`.
    pub fn joint_axis(&self, i: usize) -> Vec3 {
        self.rotations[i + 1].column(2).into_owned()
    }

    /// Position `o_i` of joint `i` (0-based) in the base frame.
    pub fn joint_origin(&self, i: usize) -> Vec3 {
        self.positions[i + 1]
    }

    /// Tool-axis Jacobian `∂z/∂q`: column `i` = `ω_i × z`.
    pub fn tool_axis_jacobian(&self) -> PositionJacobian {
        let z = self.tool_axis();
        PositionJacobian::from_fn(|r, c| self.joint_axis(c).cross(&z)[r])
    }

    /// Pose of segment `s` (0 = base, `s` = the body after joint `s`) in the base frame.
    pub fn segment_frame(&self, s: usize) -> Isometry3<f64> {
        let rotation = nalgebra::Rotation3::from_matrix_unchecked(self.rotations[s]);
        Isometry3::from_parts(
            Translation3::from(self.positions[s]),
            UnitQuaternion::from_rotation_matrix(&rotation),
        )
    }

    /// Maps a point given in segment `s`'s frame to the base frame.
    pub fn segment_point(&self, s: usize, local: &Vec3) -> Vec3 {
        self.positions[s] + self.rotations[s] * local
    }
}
