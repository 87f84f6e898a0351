//! ABB's configuration data of a six-axis serial arm with a spherical wrist (RAPID's
//! `confdata`, `[cf1, cf4, cf6, cfx]`): which of the inverse kinematics' solutions a Cartesian
//! target means.
//!
//! The definition used, after ABB's *Technical reference manual – RAPID Instructions,
//! Functions and Data types* (data type `confdata`, "Robot configuration data for serial
//! link robots"), with every boundary stated, since open implementations disagree on them:
//!
//! * `cf1`, `cf4`, `cf6`: the quadrant of axis 1, 4 and 6, `⌊θ / 90°⌋` (0 for `[0°, 90°)`, 1 for
//!   `[90°, 180°)`, −1 for `[−90°, 0°)`, −2 for `[−180°, −90°)`, and so on past ±180°).
//! * `cfx = 4·b1 + 2·b2 + b5`, each bit 0 or 1:
//!   * `b1`, the wrist centre behind axis 1: the wrist centre's component along the arm's
//!     forward direction (the base's x axis turned by axis 1 about its own axis), measured from
//!     axis 1, is negative; on axis 1 itself it counts as in front.
//!   * `b2`, the wrist centre behind the lower arm: it lies on the other side of the line
//!     through axis 2 and axis 3 than the forward direction, that is
//!     `((o₃ − o₂) × (w − o₂)) · a₂ < 0` for the axis 2 and 3 origins `o₂`, `o₃`, the wrist
//!     centre `w` and axis 2's direction `a₂` (at the calibration pose the wrist centre lies in
//!     front); on the line itself (the elbow's stretched or folded singularity) it counts as
//!     in front.
//!   * `b5`: axis 5's angle is negative (0° counts as positive).
//!
//! The joint values are the controller's: ROS-Industrial's ABB descriptions keep ABB's axis
//! directions and zeros, so at the calibration pose (every axis 0°) the configuration is
//! `[0, 0, 0, 0]`.

use emg_kinematics::{JointVector, Robot};

use crate::wrist::WristSides;

/// `[cf1, cf4, cf6, cfx]` of a configuration.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct AbbConfiguration {
    /// The quadrant of axis 1.
    pub cf1: i32,
    /// The quadrant of axis 4.
    pub cf4: i32,
    /// The quadrant of axis 6.
    pub cf6: i32,
    /// The wrist centre's side of axis 1 and of the lower arm, and axis 5's sign (0 to 7).
    pub cfx: i32,
}

impl AbbConfiguration {
    /// The configuration data of `q` on `robot` (six joints, its wrist centre at axis 5's
    /// origin), as the module documentation defines them.
    pub fn of(robot: &Robot, q: &JointVector) -> Self {
        let sides = WristSides::of(robot, q);
        let behind_axis1 = sides.ahead_of_axis1 < 0.0;
        let behind_lower_arm = sides.beside_lower_arm < 0.0;
        let axis5_negative = q[4] < 0.0;
        Self {
            cf1: quadrant(q[0]),
            cf4: quadrant(q[3]),
            cf6: quadrant(q[5]),
            cfx: 4 * i32::from(behind_axis1)
                + 2 * i32::from(behind_lower_arm)
                + i32::from(axis5_negative),
        }
    }

    /// `[cf1, cf4, cf6, cfx]` as RAPID writes it.
    pub fn text(&self) -> String {
        format!("[{}, {}, {}, {}]", self.cf1, self.cf4, self.cf6, self.cfx)
    }
}

/// The quadrant of an angle (rad): `⌊θ / 90°⌋`.
pub fn quadrant(angle: f64) -> i32 {
    (angle / std::f64::consts::FRAC_PI_2).floor() as i32
}

#[cfg(test)]
mod tests {
    use super::*;

    /// An arm of the IRB 120's geometry (ROS-Industrial's `abb_irb120_support`, as compas_fab
    /// 2.0.1 ships it): axis 2 290 mm up, the lower arm 270 mm, 70 mm up to the forearm axis,
    /// the wrist centre 302 mm along it, the flange 72 mm further.
    fn irb120() -> Robot {
        let joint = |name: &str, parent: &str, child: &str, xyz: &str, axis: &str| {
            format!(
                "<joint name=\"{name}\" type=\"revolute\"><parent link=\"{parent}\"/>\
                 <child link=\"{child}\"/><origin xyz=\"{xyz}\" rpy=\"0 0 0\"/>\
                 <axis xyz=\"{axis}\"/><limit lower=\"-7\" upper=\"7\" effort=\"1\" \
                 velocity=\"1\"/></joint>"
            )
        };
        let links: String = [
            "base_link",
            "link_1",
            "link_2",
            "link_3",
            "link_4",
            "link_5",
        ]
        .iter()
        .chain(["link_6"].iter())
        .map(|l| format!("<link name=\"{l}\"/>"))
        .collect();
        let joints = [
            joint("joint_1", "base_link", "link_1", "0 0 0", "0 0 1"),
            joint("joint_2", "link_1", "link_2", "0 0 0.29", "0 1 0"),
            joint("joint_3", "link_2", "link_3", "0 0 0.27", "0 1 0"),
            joint("joint_4", "link_3", "link_4", "0 0 0.07", "1 0 0"),
            joint("joint_5", "link_4", "link_5", "0.302 0 0", "0 1 0"),
            joint("joint_6", "link_5", "link_6", "0.072 0 0", "1 0 0"),
        ]
        .concat();
        let urdf = format!("<robot name=\"irb120\">{links}{joints}</robot>");
        Robot::from_urdf_str(&urdf, "base_link", "link_6").expect("the test arm loads")
    }

    fn conf(robot: &Robot, q: [f64; 6]) -> AbbConfiguration {
        AbbConfiguration::of(robot, &robot.joint_vector(&q))
    }

    #[test]
    fn the_calibration_pose_is_configuration_zero() {
        let robot = irb120();
        assert_eq!(
            conf(&robot, [0.0; 6]),
            AbbConfiguration {
                cf1: 0,
                cf4: 0,
                cf6: 0,
                cfx: 0
            }
        );
        assert_eq!(conf(&robot, [0.0; 6]).text(), "[0, 0, 0, 0]");
    }

    #[test]
    fn each_quadrant_changes_at_its_boundary_and_not_before() {
        let e = 1e-9;
        for (degrees, expected) in [
            (0.0, 0),
            (-e, -1),
            (90.0, 1),
            (90.0 - e, 0),
            (-90.0, -1),
            (-90.0 - e, -2),
            (180.0, 2),
            (-180.0, -2),
            (-180.0 - e, -3),
            (400.0, 4),
        ] {
            assert_eq!(quadrant(f64::to_radians(degrees)), expected, "{degrees}°");
        }
        let robot = irb120();
        let turned = conf(&robot, [1.7, 0.0, 0.0, -0.3, 0.5, -3.5]);
        assert_eq!((turned.cf1, turned.cf4, turned.cf6), (1, -1, -3));
    }

    #[test]
    fn each_bit_of_cfx_flips_where_the_wrist_centre_crosses_its_boundary() {
        let robot = irb120();
        let e = 1e-6;
        // Axis 5 at either side of zero.
        assert_eq!(conf(&robot, [0.0, 0.0, 0.0, 0.0, e, 0.0]).cfx, 0);
        assert_eq!(conf(&robot, [0.0, 0.0, 0.0, 0.0, -e, 0.0]).cfx, 1);
        // The lower arm: the wrist centre (0.302 m along the forearm, 0.07 m above axis 3) lies
        // on the line through axis 2 and axis 3 where 0.302 cos θ₃ + 0.07 sin θ₃ = 0, the
        // forearm turned up by atan(0.302 / 0.07): either side of that the bit differs (the
        // lower arm leaning forward, so that the wrist centre stays in front of axis 1).
        let on_line = -libm::atan2(0.302, 0.07);
        assert_eq!(conf(&robot, [0.0, 0.3, on_line + e, 0.0, 0.1, 0.0]).cfx, 0);
        assert_eq!(conf(&robot, [0.0, 0.3, on_line - e, 0.0, 0.1, 0.0]).cfx, 2);
        // Axis 1: with the lower arm leaning back until the wrist centre passes above axis 1.
        // At axis 2 = −a, axis 3 = 0, the wrist centre's forward offset is
        // 0.302 cos a − 0.34 sin a: zero at a = atan(0.302 / 0.34).
        let over = -libm::atan2(0.302, 0.34);
        assert_eq!(conf(&robot, [0.0, over + e, 0.0, 0.0, 0.1, 0.0]).cfx, 0);
        assert_eq!(conf(&robot, [0.0, over - e, 0.0, 0.0, 0.1, 0.0]).cfx, 4);
        // Turned by axis 1, the forward direction turns with it: the same pose behind is 4
        // whichever way the arm faces.
        for turn in [-2.5, -1.0, 1.0, 2.5] {
            assert_eq!(conf(&robot, [turn, over - e, 0.0, 0.0, 0.1, 0.0]).cfx, 4);
            assert_eq!(conf(&robot, [turn, over + e, 0.0, 0.0, -0.1, 0.0]).cfx, 1);
        }
    }
}
