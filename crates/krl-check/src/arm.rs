//! The arm as the reader solves it: the KUKA KR 16-2's closed-form inverse kinematics
//! ([`OpwArm`] from KUKA's published dimensions, in KUKA's axis directions, which
//! ROS-Industrial's joint coordinates keep, and its `tool0` frame), and the Status and Turn of a
//! solution by KUKA's definition, computed here from that geometry (docs/robot-export.md states
//! the definition and its boundaries).

use std::f64::consts::FRAC_PI_2;

use emg_kinematics::Vec3;
use emg_program_check::{ClosedForm, OpwArm, Pose, on_side};
use nalgebra::{Quaternion, UnitQuaternion};
use rs_opw_kinematics::parameters::opw_kinematics::Parameters;

/// KUKA's Status and Turn.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct StatusTurn {
    /// Status: bit 0 the overhead area, bit 1 A3 at or above φ, bit 2 A5 negative.
    pub status: u8,
    /// Turn: bit `i` axis `i + 1` negative.
    pub turn: u8,
}

/// The KR 16-2 as the reader solves it.
pub struct Kr16 {
    arm: OpwArm,
    /// The A3 angle (rad) at which the wrist centre lies on the line through A2 and A3.
    phi: f64,
}

/// The KR 16-2's dimensions (KUKA's specification, "KR 16-2": A2 675 mm above the floor and
/// 260 mm in front of A1, the lower arm 680 mm, the forearm 670 mm with A4's axis 35 mm below
/// A3's at A3 = 0° (OPW's `a2` positive), the flange 158 mm beyond the wrist centre) as OPW
/// parameters in KUKA's axis directions (A1, A4 and A6 turn against the OPW convention) and
/// zeros (A2 at 0° holds the lower arm level).
pub fn kr16_parameters() -> Parameters {
    Parameters {
        a1: 0.260,
        a2: 0.035,
        b: 0.0,
        c1: 0.675,
        c2: 0.680,
        c3: 0.670,
        c4: 0.158,
        offsets: [0.0, -FRAC_PI_2, 0.0, 0.0, 0.0, 0.0],
        sign_corrections: [-1, 1, 1, -1, 1, -1],
        ..Parameters::new()
    }
}

impl Default for Kr16 {
    fn default() -> Self {
        let parameters = kr16_parameters();
        Self {
            // The wrist centre, `c3` along the forearm and `a2` below it, on the lower arm's
            // line where the forearm is turned up by atan(a2 / c3).
            phi: -libm::atan2(parameters.a2, parameters.c3),
            arm: OpwArm::new(parameters),
        }
    }
}

/// The turn by `angle` (rad) about the unit vector `axis`: the quaternion of its half angle.
fn about(axis: Vec3, angle: f64) -> UnitQuaternion<f64> {
    let (sin, cos) = libm::sincos(angle / 2.0);
    UnitQuaternion::new_normalize(Quaternion::new(
        cos,
        axis.x * sin,
        axis.y * sin,
        axis.z * sin,
    ))
}

/// A frame in ROS-Industrial's terms (z along the tool or out of the flange) from KUKA's (x
/// along it): turned by +90° about its own y axis.
pub fn ros_frame(kuka: &Pose) -> Pose {
    Pose {
        position: kuka.position,
        rotation: kuka.rotation * about(Vec3::y(), FRAC_PI_2),
    }
}

/// The pose KUKA's `X, Y, Z` (mm) and `A, B, C` (degrees: about z, then the new y, then the new
/// x) name.
pub fn kuka_pose([x, y, z, a, b, c]: [f64; 6]) -> Pose {
    Pose {
        position: Vec3::new(x, y, z) / 1e3,
        rotation: about(Vec3::z(), a.to_radians())
            * about(Vec3::y(), b.to_radians())
            * about(Vec3::x(), c.to_radians()),
    }
}

impl Kr16 {
    /// ROS-Industrial's `tool0` (z out of the flange) at joints `q` (rad, KUKA's axes).
    pub fn flange(&self, q: &[f64; 6]) -> Pose {
        self.arm.flange(q)
    }

    /// The signed measures the Status is read from: the wrist centre's x value in the A1
    /// coordinate system (m; A1 turns about −z), A3's angle above φ (rad) and A5's angle (rad).
    fn measures(&self, q: &[f64; 6]) -> [f64; 3] {
        let wrist = self.arm.wrist_centre(&self.flange(q));
        let (sin1, cos1) = libm::sincos(q[0]);
        [wrist.x * cos1 - wrist.y * sin1, q[2] - self.phi, q[4]]
    }

    /// The Status and Turn of joints `q`.
    pub fn status_turn(&self, q: &[f64; 6]) -> StatusTurn {
        let [x, above_phi, a5] = self.measures(q);
        StatusTurn {
            status: u8::from(x < 0.0) + 2 * u8::from(above_phi >= 0.0) + 4 * u8::from(a5 < 0.0),
            turn: (0..6)
                .filter(|&axis| q[axis] < 0.0)
                .fold(0, |bits, axis| bits | (1 << axis)),
        }
    }

    /// Whether joints `q` hold the Status `status`, counting a measure within
    /// `emg_program_check::BOUNDARY_SLACK` of its boundary for either side.
    pub fn holds_status(&self, q: &[f64; 6], status: u8) -> bool {
        let [x, above_phi, a5] = self.measures(q);
        on_side(x, status & 1 != 0)
            && on_side(above_phi, status & 2 == 0)
            && on_side(a5, status & 4 != 0)
    }

    /// Whether joints `q` hold `configuration` (Status and Turn), within the slack.
    pub fn holds(&self, q: &[f64; 6], configuration: StatusTurn) -> bool {
        self.holds_status(q, configuration.status)
            && (0..6).all(|axis| on_side(q[axis], configuration.turn & (1 << axis) != 0))
    }

    /// The solution of `flange` within `limits` that holds `configuration`, if exactly one does;
    /// else how many do.
    pub fn solve(
        &self,
        flange: &Pose,
        configuration: StatusTurn,
        limits: &[(f64, f64)],
    ) -> Result<[f64; 6], usize> {
        self.arm
            .solve(flange, limits, |q| self.holds(q, configuration))
    }
}

impl ClosedForm for Kr16 {
    /// The Status: a `LIN` keeps the arm's configuration.
    type Held = u8;

    fn flange(&self, q: &[f64; 6]) -> Pose {
        self.arm.flange(q)
    }

    fn follow(
        &self,
        flange: &Pose,
        previous: &[f64; 6],
        limits: &[(f64, f64)],
        status: u8,
    ) -> Option<([f64; 6], f64)> {
        self.arm
            .follow(flange, previous, limits, |q| self.holds_status(q, status))
    }

    fn wrist_reach(&self, flange: &Pose) -> (f64, f64) {
        self.arm.wrist_reach(flange)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::{RngExt, SeedableRng};
    use rand_chacha::ChaCha8Rng;

    /// KUKA's specification ranges of the KR 16-2 (rad).
    fn limits() -> Vec<(f64, f64)> {
        [
            (-185.0, 185.0),
            (-155.0, 35.0),
            (-130.0, 154.0),
            (-350.0, 350.0),
            (-130.0, 130.0),
            (-350.0, 350.0),
        ]
        .iter()
        .map(|(a, b): &(f64, f64)| (a.to_radians(), b.to_radians()))
        .collect()
    }

    #[test]
    fn home_stands_where_kuka_puts_it() {
        let arm = Kr16::default();
        let home = [0.0, -FRAC_PI_2, FRAC_PI_2, 0.0, 0.0, 0.0];
        // The lower arm up (675 + 680 mm), the forearm level 35 mm lower, reaching 260 + 670
        // + 158 mm forward, the flange facing forward.
        let flange = arm.flange(&home);
        assert!((flange.position - Vec3::new(1.088, 0.0, 1.32)).norm() < 1e-9);
        assert!((flange.rotation * Vec3::z() - Vec3::x()).norm() < 1e-9);
        assert_eq!(arm.status_turn(&home), StatusTurn { status: 2, turn: 2 });
        // A1 turns about −z: positive A1 turns the arm to the right (−y).
        let turned = arm.flange(&[0.5, -FRAC_PI_2, FRAC_PI_2, 0.0, 0.0, 0.0]);
        assert!(turned.position.y < 0.0);
    }

    #[test]
    fn ten_thousand_configurations_are_solved_back_from_their_pose_and_status_turn() {
        let arm = Kr16::default();
        let limits = limits();
        let mut rng = ChaCha8Rng::seed_from_u64(80);
        let (mut solved, mut worst) = (0, 0.0f64);
        while solved < 10_000 {
            let q: [f64; 6] = std::array::from_fn(|j| rng.random_range(limits[j].0..limits[j].1));
            // Within a hair of a singularity or a boundary the data cannot tell the solutions
            // apart; the writer plans away from them.
            let [x, above_phi, a5] = arm.measures(&q);
            if a5.abs() < 1e-3
                || x.abs() < 1e-4
                || above_phi.abs() < 1e-4
                || q.iter().any(|v| v.abs() < 1e-5)
            {
                continue;
            }
            let back = arm
                .solve(&arm.flange(&q), arm.status_turn(&q), &limits)
                .unwrap_or_else(|n| panic!("{q:?}: {n} solutions"));
            worst = worst.max(emg_program_check::largest_change(&back, &q));
            solved += 1;
        }
        assert!(worst < 1e-6, "worst joint error {worst} rad");
    }
}
