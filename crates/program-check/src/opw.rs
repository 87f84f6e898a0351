//! A six-axis arm with a spherical wrist solved in closed form (`rs-opw-kinematics`, from the
//! vendor's published dimensions as OPW parameters, in ROS-Industrial's joint coordinates and
//! `tool0` frame): what the RAPID and KRL readers solve their arms with, each adding its
//! vendor's configuration data.

use std::f64::consts::TAU;

use emg_kinematics::Vec3;
use nalgebra::{Quaternion, UnitQuaternion};
use rs_opw_kinematics::glam::{DQuat, DVec3};
use rs_opw_kinematics::kinematic_traits::{Kinematics, Pose as OpwPose};
use rs_opw_kinematics::kinematics_impl::OPWKinematics;
use rs_opw_kinematics::parameters::opw_kinematics::Parameters;

use crate::controller::{Pose, largest_change};

/// How far (m) beyond the stretched elbow's reach a wrist centre may lie and be solved on that
/// edge: a plan that reaches as far as the arm does runs along it, and its poses, printed to a
/// nanometre and interpolated, stray past it by about 1e-7 m.
pub const REACH_SLACK_M: f64 = 1e-6;

/// How near (rad, or m for the wrist centre's sides) a solution may lie to a boundary of the
/// configuration data and count for either side: a target's printed digits move its solution
/// by about 1e-8 rad, and a plan that holds an axis at 0° stands on a quadrant's edge.
pub const BOUNDARY_SLACK: f64 = 1e-6;

/// Whether a signed measure `value` is on the side `negative` says, within [`BOUNDARY_SLACK`].
pub fn on_side(value: f64, negative: bool) -> bool {
    if negative {
        value < BOUNDARY_SLACK
    } else {
        value > -BOUNDARY_SLACK
    }
}

/// An arm solved in closed form.
pub struct OpwArm {
    kinematics: OPWKinematics,
    parameters: Parameters,
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

impl OpwArm {
    /// The arm of `parameters`.
    pub fn new(parameters: Parameters) -> Self {
        Self {
            kinematics: OPWKinematics::new(parameters),
            parameters,
        }
    }

    /// Its OPW parameters.
    pub fn parameters(&self) -> &Parameters {
        &self.parameters
    }

    /// The flange (`tool0`, z out of the flange) at joints `q` (rad).
    pub fn flange(&self, q: &[f64; 6]) -> Pose {
        from_opw(&self.kinematics.forward(q))
    }

    /// The wrist centre of the flange pose `flange`.
    pub fn wrist_centre(&self, flange: &Pose) -> Vec3 {
        flange.position - flange.rotation * Vec3::z() * self.parameters.c4
    }

    /// How far (m) the wrist centre of `flange` lies from axis 2 (with axis 1 turned toward
    /// it), and the farthest the arm reaches it (the elbow stretched).
    pub fn wrist_reach(&self, flange: &Pose) -> (f64, f64) {
        let p = &self.parameters;
        let wrist = self.wrist_centre(flange);
        let across = (wrist.x * wrist.x + wrist.y * wrist.y).sqrt();
        let from_shoulder = ((across - p.a1).powi(2) + (wrist.z - p.c1).powi(2)).sqrt();
        (from_shoulder, p.c2 + (p.a2 * p.a2 + p.c3 * p.c3).sqrt())
    }

    /// Every solution of the flange pose `flange` within `limits` (axes 1 and 4 also a turn
    /// either way, axis 6 up to two, where the limits allow). A pose whose wrist centre lies
    /// beyond the stretched elbow's reach by at most [`REACH_SLACK_M`] (where a plan runs along
    /// the edge of the workspace, as far as it reaches) is solved with the wrist centre on that
    /// edge.
    pub fn solutions(&self, flange: &Pose, limits: &[(f64, f64)]) -> Vec<[f64; 6]> {
        let within = |q: &[f64; 6]| q.iter().zip(limits).all(|(v, (lo, hi))| v >= lo && v <= hi);
        let mut solved = self.kinematics.inverse(&opw_pose(flange));
        let (wrist, reach) = self.wrist_reach(flange);
        if solved.is_empty() && wrist > reach && wrist <= reach + REACH_SLACK_M {
            let p = &self.parameters;
            let centre = self.wrist_centre(flange);
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

    /// The one solution of `flange` within `limits` that `holds` accepts (solutions within
    /// [`BOUNDARY_SLACK`] of each other counted once); else how many it accepts.
    pub fn solve(
        &self,
        flange: &Pose,
        limits: &[(f64, f64)],
        holds: impl Fn(&[f64; 6]) -> bool,
    ) -> Result<[f64; 6], usize> {
        let mut matching: Vec<[f64; 6]> = Vec::new();
        for q in self.solutions(flange, limits) {
            let seen = matching
                .iter()
                .any(|m| largest_change(m, &q) < BOUNDARY_SLACK);
            if !seen && holds(&q) {
                matching.push(q);
            }
        }
        match matching.as_slice() {
            [only] => Ok(*only),
            _ => Err(matching.len()),
        }
    }

    /// The solution of `flange` within `limits` nearest `previous` (largest joint change) among
    /// those `keeps` accepts (all where none does), with that change: how a controller follows
    /// a Cartesian path, keeping the configuration.
    pub fn follow(
        &self,
        flange: &Pose,
        previous: &[f64; 6],
        limits: &[(f64, f64)],
        keeps: impl Fn(&[f64; 6]) -> bool,
    ) -> Option<([f64; 6], f64)> {
        let solutions = self.solutions(flange, limits);
        let holding: Vec<[f64; 6]> = solutions.iter().copied().filter(|q| keeps(q)).collect();
        let candidates = if holding.is_empty() {
            solutions
        } else {
            holding
        };
        candidates
            .into_iter()
            .map(|q| (q, largest_change(&q, previous)))
            .min_by(|a, b| a.1.total_cmp(&b.1))
    }
}
