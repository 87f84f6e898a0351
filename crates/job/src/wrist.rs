//! Where a six-joint arm's wrist centre stands relative to its axes: the measures the vendors'
//! configuration data (ABB's `cfx`, KUKA's Status) are read from, one definition for both.

use emg_kinematics::{JointVector, Robot, Vec3};

/// The wrist centre's place relative to axis 1 and the lower arm, at one configuration.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct WristSides {
    /// The wrist centre's component (m) along the arm's forward direction (the base's x axis
    /// turned by axis 1 about its own axis: KUKA's "A1 coordinate system"), measured from axis
    /// 1: negative behind axis 1 (ABB) or in the overhead area (KUKA).
    pub(crate) ahead_of_axis1: f64,
    /// `((o₃ − o₂) × (w − o₂)) · a₂` (m²) for the axis 2 and 3 origins `o₂`, `o₃`, the wrist
    /// centre `w` and axis 2's direction `a₂`: zero where the wrist centre lies on the line
    /// through axes 2 and 3 (the elbow stretched or folded), its sign the side of that line.
    pub(crate) beside_lower_arm: f64,
}

impl WristSides {
    /// The sides of the wrist centre (axis 5's origin) of `robot` at `q`.
    pub(crate) fn of(robot: &Robot, q: &JointVector) -> Self {
        let kinematics = robot.forward(q);
        let (o2, o3, wrist) = (
            kinematics.joint_origin(1),
            kinematics.joint_origin(2),
            kinematics.joint_origin(4),
        );
        let forward = turned_about(&Vec3::x(), &kinematics.joint_axis(0), q[0]);
        Self {
            ahead_of_axis1: (wrist - kinematics.joint_origin(0)).dot(&forward),
            beside_lower_arm: (o3 - o2)
                .cross(&(wrist - o2))
                .dot(&kinematics.joint_axis(1)),
        }
    }
}

/// `v` turned by `angle` (rad) about the unit vector `axis` (Rodrigues' formula).
fn turned_about(v: &Vec3, axis: &Vec3, angle: f64) -> Vec3 {
    let (sin, cos) = libm::sincos(angle);
    v * cos + axis.cross(v) * sin + axis * (axis.dot(v) * (1.0 - cos))
}
