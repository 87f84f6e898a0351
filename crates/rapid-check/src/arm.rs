//! The arm as the reader solves it: the ABB IRB 120-3/0.58's closed-form inverse kinematics
//! ([`OpwArm`] from its published OPW parameters, ROS-Industrial's joint coordinates and
//! `tool0` frame), and the configuration data of a solution by ABB's definition, computed here
//! from that geometry (docs/robot-export.md states the definition and its boundaries).

use std::f64::consts::FRAC_PI_2;

use emg_kinematics::Vec3;
use emg_program_check::{BOUNDARY_SLACK, ClosedForm, OpwArm, Pose, on_side};
use nalgebra::{Quaternion, UnitQuaternion};
use rs_opw_kinematics::parameters::opw_kinematics::Parameters;

/// A pose from RAPID's `[x, y, z]` (mm) and `[q1, q2, q3, q4]` (`[w, x, y, z]`).
pub fn rapid_pose(position_mm: [f64; 3], quaternion: [f64; 4]) -> Option<Pose> {
    let [w, x, y, z] = quaternion;
    let q = Quaternion::new(w, x, y, z);
    (q.norm() > 0.5).then(|| Pose {
        position: Vec3::from(position_mm) / 1e3,
        rotation: UnitQuaternion::from_quaternion(q),
    })
}

/// `[cf1, cf4, cf6, cfx]`.
pub type Configuration = [i32; 4];

/// The IRB 120 as the reader solves it.
pub struct Irb120 {
    arm: OpwArm,
}

impl Default for Irb120 {
    fn default() -> Self {
        Self {
            arm: OpwArm::new(Parameters::irb120_3_58()),
        }
    }
}

/// The quadrant of an angle (rad): `⌊θ / 90°⌋`.
fn quadrant(angle: f64) -> i32 {
    (angle / FRAC_PI_2).floor() as i32
}

/// Whether `angle` (rad) lies in quadrant `quadrant`, within [`BOUNDARY_SLACK`] of its edges.
fn in_quadrant(angle: f64, quadrant: i32) -> bool {
    let low = f64::from(quadrant) * FRAC_PI_2;
    angle >= low - BOUNDARY_SLACK && angle < low + FRAC_PI_2 + BOUNDARY_SLACK
}

impl Irb120 {
    /// The flange (`tool0`) at joints `q` (rad, ABB's axes).
    pub fn flange(&self, q: &[f64; 6]) -> Pose {
        self.arm.flange(q)
    }

    /// The configuration data of joints `q`: the quadrants of axes 1, 4 and 6, and `cfx` from
    /// where the wrist centre lies: behind axis 1 (its component along the arm's forward
    /// direction negative), behind the lower arm (on the other side of the line through axes
    /// 2 and 3 than the forward direction), and axis 5 negative.
    pub fn configuration(&self, q: &[f64; 6]) -> Configuration {
        let [behind_axis1, behind_lower_arm, axis5] = self.sides(q);
        [
            quadrant(q[0]),
            quadrant(q[3]),
            quadrant(q[5]),
            4 * i32::from(behind_axis1 < 0.0)
                + 2 * i32::from(behind_lower_arm < 0.0)
                + i32::from(axis5 < 0.0),
        ]
    }

    /// Whether joints `q` hold `configuration`, counting a solution within [`BOUNDARY_SLACK`]
    /// of a boundary for either side of it.
    pub fn holds(&self, q: &[f64; 6], configuration: Configuration) -> bool {
        let [cf1, cf4, cf6, cfx] = configuration;
        in_quadrant(q[0], cf1)
            && in_quadrant(q[3], cf4)
            && in_quadrant(q[5], cf6)
            && self.holds_cfx(q, cfx)
    }

    /// Whether joints `q` hold the bits of `cfx`, within [`BOUNDARY_SLACK`].
    fn holds_cfx(&self, q: &[f64; 6], cfx: i32) -> bool {
        let sides = self.sides(q);
        (0..3).all(|bit| on_side(sides[bit], cfx & (4 >> bit) != 0))
    }

    /// The signed measures `cfx` is read from: the wrist centre's component along the arm's
    /// forward direction (m), its side of the lower arm's line (m², positive in front) and axis
    /// 5's angle (rad).
    fn sides(&self, q: &[f64; 6]) -> [f64; 3] {
        let p = self.arm.parameters();
        let wrist = self.arm.wrist_centre(&self.flange(q));
        let (sin1, cos1) = libm::sincos(q[0]);
        let forward = Vec3::new(cos1, sin1, 0.0);
        let axis2 = Vec3::new(-sin1, cos1, 0.0);
        let shoulder = forward * p.a1 + Vec3::z() * p.c1;
        let (sin2, cos2) = libm::sincos(q[1]);
        let elbow = shoulder + (forward * sin2 + Vec3::z() * cos2) * p.c2;
        [
            wrist.dot(&forward),
            (elbow - shoulder).cross(&(wrist - shoulder)).dot(&axis2),
            q[4],
        ]
    }

    /// The solution of `flange` within `limits` that holds `configuration` ([`Irb120::holds`]),
    /// if exactly one does; else how many do.
    pub fn solve(
        &self,
        flange: &Pose,
        configuration: Configuration,
        limits: &[(f64, f64)],
    ) -> Result<[f64; 6], usize> {
        self.arm
            .solve(flange, limits, |q| self.holds(q, configuration))
    }
}

impl ClosedForm for Irb120 {
    /// `cfx`: `ConfL \On` keeps the wrist's sides along a `MoveL`.
    type Held = i32;

    fn flange(&self, q: &[f64; 6]) -> Pose {
        self.arm.flange(q)
    }

    fn follow(
        &self,
        flange: &Pose,
        previous: &[f64; 6],
        limits: &[(f64, f64)],
        cfx: i32,
    ) -> Option<([f64; 6], f64)> {
        self.arm
            .follow(flange, previous, limits, |q| self.holds_cfx(q, cfx))
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

    /// ABB's data sheet ranges of the IRB 120 (rad).
    fn limits() -> Vec<(f64, f64)> {
        [
            (-165.0, 165.0),
            (-110.0, 110.0),
            (-110.0, 70.0),
            (-160.0, 160.0),
            (-120.0, 120.0),
            (-400.0, 400.0),
        ]
        .iter()
        .map(|(a, b): &(f64, f64)| (a.to_radians(), b.to_radians()))
        .collect()
    }

    #[test]
    fn ten_thousand_configurations_are_solved_back_from_their_pose_and_configuration_data() {
        let arm = Irb120::default();
        let limits = limits();
        let mut rng = ChaCha8Rng::seed_from_u64(80);
        let mut solved = 0;
        let mut worst: f64 = 0.0;
        while solved < 10_000 {
            let q: [f64; 6] = std::array::from_fn(|j| rng.random_range(limits[j].0..limits[j].1));
            // Within a hair of a singularity or a quadrant's edge the data cannot tell the
            // solutions apart; the writer plans away from them.
            let configuration = arm.configuration(&q);
            let flange = arm.flange(&q);
            if q[4].abs() < 1e-3
                || q.iter()
                    .any(|v| (v / FRAC_PI_2 - (v / FRAC_PI_2).round()).abs() < 1e-6)
            {
                continue;
            }
            let back = arm
                .solve(&flange, configuration, &limits)
                .unwrap_or_else(|n| {
                    panic!("{q:?}: {n} solutions match {configuration:?}");
                });
            let error = back
                .iter()
                .zip(&q)
                .map(|(a, b)| (a - b).abs())
                .fold(0.0, f64::max);
            worst = worst.max(error);
            solved += 1;
        }
        assert!(worst < 1e-6, "worst joint error {worst} rad");
    }

    #[test]
    fn the_calibration_pose_is_configuration_zero_and_the_flange_is_where_abb_puts_it() {
        let arm = Irb120::default();
        assert_eq!(arm.configuration(&[0.0; 6]), [0, 0, 0, 0]);
        let flange = arm.flange(&[0.0; 6]);
        // 302 + 72 mm forward, 290 + 270 + 70 mm up, z out of the flange along x.
        assert!((flange.position - Vec3::new(0.374, 0.0, 0.63)).norm() < 1e-9);
        assert!((flange.rotation * Vec3::z() - Vec3::x()).norm() < 1e-9);
    }
}
