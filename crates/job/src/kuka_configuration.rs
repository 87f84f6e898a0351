//! KUKA's Status and Turn of a six-axis serial arm with a spherical wrist (the `S` and `T` of
//! an `E6POS`): which of the inverse kinematics' solutions a Cartesian target means.
//!
//! The definition used, after KUKA's *KUKA System Software 8.x, Operating and Programming
//! Instructions for System Integrators* ("Status" and "Turn" of the position data), with every
//! boundary stated, since open implementations disagree on them:
//!
//! * Status `S = b0 + 2·b1 + 4·b2` (bits 3 and 4 are 0):
//!   * `b0` = 1 in the overhead area: the wrist root point's (the wrist centre's) x value in the
//!     A1 coordinate system (the robot root frame turned by A1, which turns about −z) is
//!     negative; 0 in the basic area, with x = 0 counted as basic.
//!   * `b1` = 1 where A3 ≥ φ, 0 where A3 < φ: φ is the A3 angle at which the wrist centre lies
//!     on the line through A2 and A3 (0° on arms whose A3 and A4 axes intersect; on the KR 16-2,
//!     whose A4 axis lies 35 mm from A3's, −2.99°). It depends on A3 alone: not on the area
//!     (the overhead area does not flip it). Measured here as the side of that line the wrist
//!     centre lies on: on the side it lies at KUKA's HOME (A2 −90°, A3 +90°) or on the line,
//!     `b1` = 1.
//!   * `b2` = 1 where A5 < 0°, 0 where A5 ≥ 0°.
//! * Turn `T`: bit `i` (0 to 5) is 1 where axis `i + 1` stands below 0°, 0 at or above it.
//!
//! The joint values are the controller's: ROS-Industrial's KUKA descriptions keep KUKA's axis
//! directions (A1 turns about −z, A4 and A6 about −x) and zeros.

use emg_kinematics::{JointVector, Robot};

use crate::wrist::WristSides;

/// `S` and `T` of a configuration.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct KukaConfiguration {
    /// Status: overhead area, A3 at or above φ, A5 negative (bits 0, 1, 2).
    pub status: u8,
    /// Turn: axis `i + 1` negative (bit `i`).
    pub turn: u8,
}

impl KukaConfiguration {
    /// The Status and Turn of `q` on `robot` (six joints, its wrist centre at axis 5's origin),
    /// as the module documentation defines them.
    pub fn of(robot: &Robot, q: &JointVector) -> Self {
        let sides = WristSides::of(robot, q);
        let overhead = sides.ahead_of_axis1 < 0.0;
        let at_or_above_phi = sides.beside_lower_arm >= 0.0;
        let axis5_negative = q[4] < 0.0;
        let turn = (0..6)
            .filter(|&axis| q[axis] < 0.0)
            .fold(0u8, |bits, axis| bits | (1 << axis));
        Self {
            status: u8::from(overhead)
                + 2 * u8::from(at_or_above_phi)
                + 4 * u8::from(axis5_negative),
            turn,
        }
    }

    /// `S s,T t` as a KUKA `.dat` file writes them (decimal).
    pub fn text(&self) -> String {
        format!("S {},T {}", self.status, self.turn)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// An arm of the KR 16-2's geometry (ROS-Industrial's `kuka_kr16_support`, as rtb-data
    /// 2.0.0 ships it): A2 675 mm up and 260 mm forward, the lower arm 680 mm, the wrist
    /// centre 670 mm along the forearm and 35 mm below A3, KUKA's axis directions.
    fn kr16() -> Robot {
        let joint = |n: usize, xyz: &str, axis: &str| {
            let parent = if n == 1 {
                "base_link".to_string()
            } else {
                format!("link_{}", n - 1)
            };
            format!(
                "<joint name=\"joint_a{n}\" type=\"revolute\"><parent link=\"{parent}\"/>\
                 <child link=\"link_{n}\"/><origin xyz=\"{xyz}\" rpy=\"0 0 0\"/>\
                 <axis xyz=\"{axis}\"/><limit lower=\"-7\" upper=\"7\" effort=\"1\" \
                 velocity=\"1\"/></joint>"
            )
        };
        let links: String = std::iter::once("base_link".to_string())
            .chain((1..=6).map(|n| format!("link_{n}")))
            .map(|l| format!("<link name=\"{l}\"/>"))
            .collect();
        let joints = [
            joint(1, "0 0 0.675", "0 0 -1"),
            joint(2, "0.26 0 0", "0 1 0"),
            joint(3, "0.68 0 0", "0 1 0"),
            joint(4, "0.67 0 -0.035", "-1 0 0"),
            joint(5, "0 0 0", "0 1 0"),
            joint(6, "0 0 0", "-1 0 0"),
        ]
        .concat();
        let urdf = format!("<robot name=\"kr16\">{links}{joints}</robot>");
        Robot::from_urdf_str(&urdf, "base_link", "link_6").expect("the test arm loads")
    }

    fn conf(robot: &Robot, q: [f64; 6]) -> KukaConfiguration {
        KukaConfiguration::of(robot, &robot.joint_vector(&q))
    }

    const HOME: [f64; 6] = [
        0.0,
        -std::f64::consts::FRAC_PI_2,
        std::f64::consts::FRAC_PI_2,
        0.0,
        0.0,
        0.0,
    ];

    #[test]
    fn home_is_basic_area_above_phi_a5_positive() {
        let robot = kr16();
        let home = conf(&robot, HOME);
        assert_eq!(home, KukaConfiguration { status: 2, turn: 2 });
        assert_eq!(home.text(), "S 2,T 2");
    }

    #[test]
    fn each_turn_bit_flips_below_zero_and_not_at_it() {
        let robot = kr16();
        let e = 1e-9;
        for axis in 0..6 {
            let mut q = [0.3, -1.2, 1.4, 0.2, 0.5, 0.1];
            q[axis] = 0.0;
            assert_eq!(conf(&robot, q).turn & (1 << axis), 0, "axis {}", axis + 1);
            q[axis] = -e;
            assert_eq!(
                conf(&robot, q).turn & (1 << axis),
                1 << axis,
                "axis {}",
                axis + 1
            );
        }
    }

    #[test]
    fn each_status_bit_flips_where_its_boundary_lies() {
        let robot = kr16();
        let e = 1e-6;
        // A5 at either side of zero.
        assert_eq!(conf(&robot, [0.0, -1.2, 1.4, 0.0, 0.0, 0.0]).status & 4, 0);
        assert_eq!(conf(&robot, [0.0, -1.2, 1.4, 0.0, -e, 0.0]).status & 4, 4);
        // A3 at φ: the wrist centre (0.67 m along the forearm, 0.035 m below A3) on the line
        // through A2 and A3 where −0.67 sin φ − 0.035 cos φ = 0.
        let phi = libm::atan2(-0.035, 0.67);
        assert!((phi.to_degrees() + 2.99).abs() < 0.01);
        assert_eq!(
            conf(&robot, [0.0, -1.2, phi + e, 0.0, 0.4, 0.0]).status & 2,
            2
        );
        assert_eq!(
            conf(&robot, [0.0, -1.2, phi - e, 0.0, 0.4, 0.0]).status & 2,
            0
        );
        // The overhead area: the lower arm leaning back (A2 below −90°) until the wrist
        // centre passes above A1's axis: its x value 0.26 + 0.68 cos A2 + 0.67 cos(A2 + A3)
        // − 0.035 sin(A2 + A3) in the A1 frame turns negative (found by bisection).
        let a3 = 0.5;
        let x = |a2: f64| {
            0.26 + 0.68 * libm::cos(a2) + 0.67 * libm::cos(a2 + a3) - 0.035 * libm::sin(a2 + a3)
        };
        let (mut low, mut high) = (-std::f64::consts::PI, -std::f64::consts::FRAC_PI_2);
        for _ in 0..100 {
            let mid = 0.5 * (low + high);
            if x(mid) < 0.0 { low = mid } else { high = mid }
        }
        let over = 0.5 * (low + high);
        for turn in [-2.5, 0.0, 1.0] {
            let basic = conf(&robot, [turn, over + e, a3, 0.0, 0.4, 0.0]);
            let overhead = conf(&robot, [turn, over - e, a3, 0.0, 0.4, 0.0]);
            assert_eq!((basic.status & 1, overhead.status & 1), (0, 1), "A1 {turn}");
            // Bit 1 follows A3 alone, whatever the area.
            assert_eq!((basic.status & 2, overhead.status & 2), (2, 2), "A1 {turn}");
        }
    }
}
