//! The constraints every step must hold, and which one a configuration breaks.

use emg_kinematics::{JointVector, Kinematics, Robot, Vec3};
use serde::{Deserialize, Serialize};

use crate::config::ConstraintConfig;
use crate::task::Task;

/// A broken constraint, naming the joint or capsule pair involved.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(tag = "constraint", rename_all = "snake_case")]
pub enum Violation {
    /// A joint left its position limits.
    JointLimit {
        /// 1-based joint number.
        joint: usize,
        /// Joint position (rad).
        value_rad: f64,
        /// The limit it passed (rad).
        limit_rad: f64,
    },
    /// The TCP left the tolerance tube around the line.
    LineTolerance {
        /// Lateral distance from the line (m).
        distance_m: f64,
    },
    /// The tool axis left the cone around `n`.
    ToolCone {
        /// Angle between the tool axis and `n` (degrees).
        angle_deg: f64,
    },
    /// Two capsules of the arm touch.
    SelfCollision {
        /// Link carrying the first capsule.
        first_link: String,
        /// Link carrying the second capsule.
        second_link: String,
        /// Surface clearance (m), negative when interpenetrating.
        clearance_m: f64,
    },
}

impl Violation {
    /// Short machine-readable name of the constraint (`joint_limit`, `line_tolerance`, ...).
    pub fn kind(&self) -> &'static str {
        match self {
            Self::JointLimit { .. } => "joint_limit",
            Self::LineTolerance { .. } => "line_tolerance",
            Self::ToolCone { .. } => "tool_cone",
            Self::SelfCollision { .. } => "self_collision",
        }
    }
}

impl std::fmt::Display for Violation {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Self::JointLimit {
                joint,
                value_rad,
                limit_rad,
            } => write!(
                f,
                "joint {joint} reached its limit ({value_rad:.4} rad past {limit_rad:.4} rad)"
            ),
            Self::LineTolerance { distance_m } => {
                write!(
                    f,
                    "TCP left the line tolerance ({:.2} mm off the line)",
                    distance_m * 1e3
                )
            }
            Self::ToolCone { angle_deg } => {
                write!(
                    f,
                    "tool axis left the cone ({angle_deg:.2}° from the normal)"
                )
            }
            Self::SelfCollision {
                first_link,
                second_link,
                clearance_m,
            } => write!(
                f,
                "self-collision between {first_link} and {second_link} (clearance {:.2} mm)",
                clearance_m * 1e3
            ),
        }
    }
}

/// Angle between the tool axis `z` and the normal `n` (degrees).
pub fn tool_angle_deg(z: &Vec3, n: &Vec3) -> f64 {
    z.cross(n).norm().atan2(z.dot(n)).to_degrees()
}

/// The first constraint `q` breaks, checked in the order joint limits, line, cone, collision.
pub fn first_violation(
    robot: &Robot,
    task: &Task,
    q: &JointVector,
    kin: &Kinematics,
    cfg: &ConstraintConfig,
) -> Option<Violation> {
    let limits = robot.limits();
    if let Some(i) = limits.first_violation(q, 0.0) {
        let limit = if q[i] < limits.lower[i] {
            limits.lower[i]
        } else {
            limits.upper[i]
        };
        return Some(Violation::JointLimit {
            joint: i + 1,
            value_rad: q[i],
            limit_rad: limit,
        });
    }
    let distance = task.lateral_error(&kin.tcp()).norm();
    // NaN counts as a violation.
    if distance.is_nan() || distance > cfg.line_tolerance_m {
        return Some(Violation::LineTolerance {
            distance_m: distance,
        });
    }
    let angle = tool_angle_deg(&kin.tool_axis(), &task.n);
    if angle.is_nan() || angle > cfg.theta_max_deg {
        return Some(Violation::ToolCone { angle_deg: angle });
    }
    robot
        .first_collision(kin, cfg.collision_margin_m)
        .map(|hit| {
            let capsules = robot.capsules();
            Violation::SelfCollision {
                first_link: capsules[hit.pair.first].link.clone(),
                second_link: capsules[hit.pair.second].link.clone(),
                clearance_m: hit.clearance,
            }
        })
}
