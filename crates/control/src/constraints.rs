//! The constraints every step must hold, and which one a configuration breaks.

use emg_kinematics::{Kinematics, Robot, ToolContact, Vec3};
use serde::{Deserialize, Serialize};

use crate::config::ConstraintConfig;
use crate::task::{Along, Task};

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
    /// A capsule of the arm came closer to an obstacle of the scene, or to the task's work
    /// surface, than its clearance.
    SceneContact {
        /// Link carrying the capsule.
        link: String,
        /// The obstacle's name ([`WORK_SURFACE`] for the work surface).
        obstacle: String,
        /// Surface distance (m) between capsule and obstacle, negative when they overlap.
        clearance_m: f64,
    },
}

/// The name the work surface goes by in violations and reports.
pub const WORK_SURFACE: &str = "work surface";

impl Violation {
    /// Short machine-readable name of the constraint (`joint_limit`, `line_tolerance`, ...).
    pub fn kind(&self) -> &'static str {
        match self {
            Self::JointLimit { .. } => "joint_limit",
            Self::LineTolerance { .. } => "line_tolerance",
            Self::ToolCone { .. } => "tool_cone",
            Self::SelfCollision { .. } => "self_collision",
            Self::SceneContact { .. } => "scene_contact",
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
            Self::SceneContact {
                link,
                obstacle,
                clearance_m,
            } => write!(
                f,
                "{link} touched the {obstacle} (clearance {:.2} mm)",
                clearance_m * 1e3
            ),
        }
    }
}

/// Angle between the tool axis `z` and the normal `n` (degrees).
pub fn tool_angle_deg(z: &Vec3, n: &Vec3) -> f64 {
    libm::atan2(z.cross(n).norm(), z.dot(n)).to_degrees()
}

/// The first constraint that the configuration of `kin` (its forward kinematics,
/// [`Robot::forward`]) breaks, checked in the order joint limits, line, cone, collision
/// (self-collision, then the work surface, then the scene's obstacles).
pub fn first_violation(
    robot: &Robot,
    task: &Task,
    kin: &Kinematics,
    cfg: &ConstraintConfig,
) -> Option<Violation> {
    admit(robot, task, kin, cfg).err()
}

/// The tool angle (degrees) of the configuration `q` of `kin` when `q` holds every constraint,
/// else the first constraint it breaks (in the order of [`first_violation`]). The angle is the
/// cone check's own measurement, so an accepted step needs no second one.
pub(crate) fn admit(
    robot: &Robot,
    task: &Task,
    kin: &Kinematics,
    cfg: &ConstraintConfig,
) -> Result<f64, Violation> {
    let q = kin.configuration();
    let limits = robot.limits();
    if let Some(i) = limits.first_violation(q, 0.0) {
        let limit = if q[i] < limits.lower[i] {
            limits.lower[i]
        } else {
            limits.upper[i]
        };
        return Err(Violation::JointLimit {
            joint: i + 1,
            value_rad: q[i],
            limit_rad: limit,
        });
    }
    let distance = task.distance(&kin.tcp());
    // NaN counts as a violation.
    if distance.is_nan() || distance > cfg.line_tolerance_m {
        return Err(Violation::LineTolerance {
            distance_m: distance,
        });
    }
    let angle = tool_angle_deg(&kin.tool_axis(), &task.n);
    if angle.is_nan() || angle > cfg.theta_max_deg {
        return Err(Violation::ToolCone { angle_deg: angle });
    }
    match first_contact(robot, task, kin, cfg) {
        Some(violation) => Err(violation),
        None => Ok(angle),
    }
}

/// Whether the TCP lies within the line tolerance of the point of the line or path its progress
/// has reached (`along`, [`Task::along`]): on a path, a stricter measure than [`admit`]'s
/// distance from the nearest point of the whole path, which a TCP near both legs of a
/// reversal holds on either.
pub(crate) fn within_reached(along: &Along, cfg: &ConstraintConfig) -> Result<(), Violation> {
    let distance = along.lateral.norm();
    if distance.is_nan() || distance > cfg.line_tolerance_m {
        return Err(Violation::LineTolerance {
            distance_m: distance,
        });
    }
    Ok(())
}

/// The first contact of the arm at `kin`: a capsule pair closer than the collision margin, a
/// capsule other than the tool's on the far side of the work surface (when it is on), or a
/// capsule closer to an obstacle of the scene than its clearance.
pub fn first_contact(
    robot: &Robot,
    task: &Task,
    kin: &Kinematics,
    cfg: &ConstraintConfig,
) -> Option<Violation> {
    if let Some(hit) = robot.first_collision(kin, cfg.collision_margin_m) {
        let capsules = robot.capsules();
        return Some(Violation::SelfCollision {
            first_link: capsules[hit.pair.first].link.clone(),
            second_link: capsules[hit.pair.second].link.clone(),
            clearance_m: hit.clearance,
        });
    }
    let scene_contact = |obstacle: &str, hit: emg_kinematics::ContactHit| Violation::SceneContact {
        link: robot.capsules()[hit.capsule].link.clone(),
        obstacle: obstacle.to_string(),
        clearance_m: hit.clearance,
    };
    if let Some(surface) = task
        .work_surface(&cfg.work_surface)
        .shape(&task.p0, &task.d, &task.n)
        && let Some(hit) = robot.first_contact(kin, &surface, 0.0, ToolContact::Allowed)
    {
        return Some(scene_contact(WORK_SURFACE, hit));
    }
    cfg.scene.obstacles.iter().find_map(|obstacle| {
        robot
            .first_contact(
                kin,
                &obstacle.shape,
                obstacle.clearance_m,
                obstacle.tool_contact(),
            )
            .map(|hit| scene_contact(&obstacle.name, hit))
    })
}
