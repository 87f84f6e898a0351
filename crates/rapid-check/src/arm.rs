//! The arm as the reader solves it: the ABB IRB 120-3/0.58's closed-form inverse kinematics
//! (`rs-opw-kinematics`, from its published OPW parameters, ROS-Industrial's joint coordinates
//! and `tool0` frame), and the configuration data of a solution by ABB's definition, computed
//! here from that geometry (docs/robot-export.md states the definition and its boundaries).

use std::f64::consts::{FRAC_PI_2, TAU};

use emg_kinematics::Vec3;
use nalgebra::{Quaternion, UnitQuaternion};
use rs_opw_kinematics::glam::{DQuat, DVec3};
use rs_opw_kinematics::kinematic_traits::{Kinematics, Pose as OpwPose};
use rs_opw_kinematics::kinematics_impl::OPWKinematics;
use rs_opw_kinematics::parameters::opw_kinematics::Parameters;

/// A pose: position (m) and orientation.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Pose {
    /// The position (m).
    pub position: Vec3,
    /// The orientation.
    pub rotation: UnitQuaternion<f64>,
}

impl Pose {
    /// `self` then `other` (`other` given in `self`'s frame).
    pub fn then(&self, other: &Pose) -> Pose {
        Pose {
            position: self.position + self.rotation * other.position,
            rotation: self.rotation * other.rotation,
        }
    }

    /// The pose that undoes `self`.
    pub fn inverse(&self) -> Pose {
        let rotation = self.rotation.inverse();
        Pose {
            position: -(rotation * self.position),
            rotation,
        }
    }

    /// The distance (m) and the angle (rad) between `self` and `other`.
    pub fn difference(&self, other: &Pose) -> (f64, f64) {
        (
            (self.position - other.position).norm(),
            self.rotation.angle_to(&other.rotation),
        )
    }

    /// The pose `t` of the way from `self` to `other`: the position on the line, the
    /// orientation slerped.
    pub fn toward(&self, other: &Pose, t: f64) -> Pose {
        Pose {
            position: self.position + (other.position - self.position) * t,
            rotation: self
                .rotation
                .try_slerp(&other.rotation, t, 1e-12)
                .unwrap_or(self.rotation),
        }
    }

    /// A pose from RAPID's `[x, y, z]` (mm) and `[q1, q2, q3, q4]` (`[w, x, y, z]`).
    pub fn from_rapid(position_mm: [f64; 3], quaternion: [f64; 4]) -> Option<Pose> {
        let [w, x, y, z] = quaternion;
        let q = Quaternion::new(w, x, y, z);
        (q.norm() > 0.5).then(|| Pose {
            position: Vec3::from(position_mm) / 1e3,
            rotation: UnitQuaternion::from_quaternion(q),
        })
    }
}

/// `[cf1, cf4, cf6, cfx]`.
pub type Configuration = [i32; 4];

/// How far (m) beyond the stretched elbow's reach a wrist centre may lie and be solved on that
/// edge: a plan that reaches as far as the arm does runs along it, and its poses, printed to a
/// nanometre and interpolated, stray past it by about 1e-7 m.
pub const REACH_SLACK_M: f64 = 1e-6;

/// The IRB 120 as the reader solves it.
pub struct Irb120 {
    kinematics: OPWKinematics,
    parameters: Parameters,
}

impl Default for Irb120 {
    fn default() -> Self {
        let parameters = Parameters::irb120_3_58();
        Self {
            kinematics: OPWKinematics::new(parameters),
            parameters,
        }
    }
}

/// `pose` as the solver takes it: its quaternion normalised again (the solver finds no
/// solution of a quaternion 1e-12 off unit length, as slerps leave them).
fn opw_pose(pose: &Pose) -> OpwPose {
    let q = pose.rotation.quaternion();
    OpwPose {
        translation: DVec3::new(pose.position.x, pose.position.y, pose.position.z),
        rotation: DQuat::from_xyzw(q.i, q.j, q.k, q.w).normalize(),
    }
}

fn from_opw(pose: &OpwPose) -> Pose {
    let (t, r) = (pose.translation, pose.rotation);
    Pose {
        position: Vec3::new(t.x, t.y, t.z),
        rotation: UnitQuaternion::from_quaternion(Quaternion::new(r.w, r.x, r.y, r.z)),
    }
}

/// The quadrant of an angle (rad): `⌊θ / 90°⌋`.
fn quadrant(angle: f64) -> i32 {
    (angle / FRAC_PI_2).floor() as i32
}

/// How near (rad, or m for the wrist centre's sides) a solution may lie to a boundary of the
/// configuration data and count for either side: a target's printed digits move its solution
/// by about 1e-8 rad, and a plan that holds an axis at 0° stands on a quadrant's edge.
pub const BOUNDARY_SLACK: f64 = 1e-6;

/// Whether `angle` (rad) lies in quadrant `quadrant`, within [`BOUNDARY_SLACK`] of its edges.
fn in_quadrant(angle: f64, quadrant: i32) -> bool {
    let low = f64::from(quadrant) * FRAC_PI_2;
    angle >= low - BOUNDARY_SLACK && angle < low + FRAC_PI_2 + BOUNDARY_SLACK
}

/// Whether a signed measure `value` is on the side `negative` says, within [`BOUNDARY_SLACK`].
fn on_side(value: f64, negative: bool) -> bool {
    if negative {
        value < BOUNDARY_SLACK
    } else {
        value > -BOUNDARY_SLACK
    }
}

impl Irb120 {
    /// The flange (`tool0`) at joints `q` (rad, ABB's axes).
    pub fn flange(&self, q: &[f64; 6]) -> Pose {
        from_opw(&self.kinematics.forward(q))
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
        let sides = self.sides(q);
        in_quadrant(q[0], cf1)
            && in_quadrant(q[3], cf4)
            && in_quadrant(q[5], cf6)
            && (0..3).all(|bit| on_side(sides[bit], cfx & (4 >> bit) != 0))
    }

    /// The signed measures `cfx` is read from: the wrist centre's component along the arm's
    /// forward direction (m), its side of the lower arm's line (m², positive in front) and axis
    /// 5's angle (rad).
    fn sides(&self, q: &[f64; 6]) -> [f64; 3] {
        let p = &self.parameters;
        let flange = self.flange(q);
        let wrist = flange.position - flange.rotation * Vec3::z() * p.c4;
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

    /// Every solution of the flange pose `flange` within `limits` (axes 1, 4 and 6 also a turn
    /// either way, where the limits allow). A pose whose wrist centre lies beyond the stretched
    /// elbow's reach by at most [`REACH_SLACK_M`] (where a plan runs along the edge of the
    /// workspace, as far as it reaches) is solved with the wrist centre on that edge.
    pub fn solutions(&self, flange: &Pose, limits: &[(f64, f64)]) -> Vec<[f64; 6]> {
        let within = |q: &[f64; 6]| q.iter().zip(limits).all(|(v, (lo, hi))| v >= lo && v <= hi);
        let mut solved = self.kinematics.inverse(&opw_pose(flange));
        let (wrist, reach) = self.wrist_reach(flange);
        if solved.is_empty() && wrist > reach && wrist <= reach + REACH_SLACK_M {
            let p = &self.parameters;
            let centre = flange.position - flange.rotation * Vec3::z() * p.c4;
            let across = Vec3::new(centre.x, centre.y, 0.0);
            let shoulder =
                across.try_normalize(1e-12).unwrap_or(Vec3::x()) * p.a1 + Vec3::z() * p.c1;
            let inward = (shoulder - centre).normalize() * (wrist - reach + 1e-12);
            let edge = Pose {
                position: flange.position + inward,
                rotation: flange.rotation,
            };
            solved = self.kinematics.inverse(&opw_pose(&edge));
        }
        let mut out = Vec::new();
        for solution in solved {
            for turns1 in -1..=1 {
                for turns4 in -1..=1 {
                    for turns6 in -2..=2 {
                        let mut q = solution;
                        q[0] += f64::from(turns1) * TAU;
                        q[3] += f64::from(turns4) * TAU;
                        q[5] += f64::from(turns6) * TAU;
                        if within(&q) {
                            out.push(q);
                        }
                    }
                }
            }
        }
        out
    }

    /// The solution of `flange` within `limits` that holds `configuration` ([`Irb120::holds`]),
    /// if exactly one does (solutions within [`BOUNDARY_SLACK`] of each other counted once);
    /// else how many do.
    pub fn solve(
        &self,
        flange: &Pose,
        configuration: Configuration,
        limits: &[(f64, f64)],
    ) -> Result<[f64; 6], usize> {
        let mut matching: Vec<[f64; 6]> = Vec::new();
        for q in self.solutions(flange, limits) {
            let seen = matching.iter().any(|m| {
                m.iter()
                    .zip(&q)
                    .all(|(a, b)| (a - b).abs() < BOUNDARY_SLACK)
            });
            if !seen && self.holds(&q, configuration) {
                matching.push(q);
            }
        }
        match matching.as_slice() {
            [only] => Ok(*only),
            _ => Err(matching.len()),
        }
    }

    /// How far (m) the wrist centre of `flange` lies from axis 2 (with axis 1 turned toward
    /// it), and the farthest the arm reaches it (the elbow stretched).
    pub fn wrist_reach(&self, flange: &Pose) -> (f64, f64) {
        let p = &self.parameters;
        let wrist = flange.position - flange.rotation * Vec3::z() * p.c4;
        let across = (wrist.x * wrist.x + wrist.y * wrist.y).sqrt();
        let from_shoulder = ((across - p.a1).powi(2) + (wrist.z - p.c1).powi(2)).sqrt();
        (from_shoulder, p.c2 + (p.a2 * p.a2 + p.c3 * p.c3).sqrt())
    }

    /// The solution of `flange` within `limits` nearest `previous` (largest joint change) among
    /// those whose wrist holds the bits of `cfx` ([`Irb120::holds`]'s slack; all where none
    /// does), with that change: how the controller follows a Cartesian path, keeping the
    /// configuration.
    pub fn follow(
        &self,
        flange: &Pose,
        previous: &[f64; 6],
        limits: &[(f64, f64)],
        cfx: i32,
    ) -> Option<([f64; 6], f64)> {
        let solutions = self.solutions(flange, limits);
        let holding: Vec<[f64; 6]> = solutions
            .iter()
            .copied()
            .filter(|q| {
                let sides = self.sides(q);
                (0..3).all(|bit| on_side(sides[bit], cfx & (4 >> bit) != 0))
            })
            .collect();
        let candidates = if holding.is_empty() {
            solutions
        } else {
            holding
        };
        candidates
            .into_iter()
            .map(|q| {
                let change = q
                    .iter()
                    .zip(previous)
                    .map(|(a, b)| (a - b).abs())
                    .fold(0.0, f64::max);
                (q, change)
            })
            .min_by(|a, b| a.1.total_cmp(&b.1))
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
