//! The baseline today's tools offer: a MoveIt-style Cartesian path (`computeCartesianPath`).
//! The tool's whole pose is held fixed — its axis on `n`, its roll where the start left it —
//! while waypoints every `eef_step_m` along the line are each solved by inverse kinematics from
//! the previous waypoint's solution; the path ends at the first waypoint that inverse
//! kinematics cannot reach, that breaks a constraint, or whose joints jump. Unlike the
//! controllers, it never uses the tilt the cone allows nor the redundancy's null space.

use emg_control::{ConstraintConfig, OutOfRange, Task, Violation, first_violation};
use emg_kinematics::{JointVector, PoseTarget, ProjectionConfig, Robot, project_to_pose};
use serde::{Deserialize, Serialize};

/// Settings of a Cartesian path, as `computeCartesianPath` takes them.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct CartesianConfig {
    /// Distance between waypoints along the line (m): MoveIt's `eef_step`.
    pub eef_step_m: f64,
    /// Largest change of any joint from one waypoint to the next (rad): an absolute jump
    /// threshold (MoveIt's `jump_threshold` set as an absolute revolute threshold).
    pub jump_threshold_rad: f64,
    /// Longest path tried (m).
    pub max_length_m: f64,
}

impl Default for CartesianConfig {
    fn default() -> Self {
        Self {
            eef_step_m: 0.01,
            jump_threshold_rad: 0.2,
            max_length_m: 3.0,
        }
    }
}

impl CartesianConfig {
    /// Checks every value against its range; the error names the field.
    pub fn validate(&self) -> Result<(), OutOfRange> {
        OutOfRange::require("cartesian.eef_step_m", self.eef_step_m, "(0, 1]", |v| {
            v > 0.0 && v <= 1.0
        })?;
        OutOfRange::require(
            "cartesian.jump_threshold_rad",
            self.jump_threshold_rad,
            "(0, ∞)",
            |v| v > 0.0,
        )?;
        OutOfRange::require(
            "cartesian.max_length_m",
            self.max_length_m,
            "(0, 100]",
            |v| v > 0.0 && v <= 100.0,
        )
    }
}

/// Why a Cartesian path ended.
#[derive(Clone, Debug, PartialEq)]
pub enum CartesianEnd {
    /// Inverse kinematics found no configuration at the next waypoint (within the joint
    /// limits) from the last one.
    Unreachable,
    /// The next waypoint's configuration breaks a constraint.
    Violation(Violation),
    /// The next waypoint's configuration lies more than the jump threshold from the last.
    Jump {
        /// The largest joint change (rad).
        rad: f64,
    },
    /// The path reached [`CartesianConfig::max_length_m`].
    MaxLength,
}

impl std::fmt::Display for CartesianEnd {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Self::Unreachable => f.write_str("no inverse-kinematics solution at the next waypoint"),
            Self::Violation(violation) => write!(f, "{violation}"),
            Self::Jump { rad } => write!(f, "a joint would jump {rad:.3} rad"),
            Self::MaxLength => f.write_str("reached the longest path tried"),
        }
    }
}

impl CartesianEnd {
    /// Short name for tables: `unreachable`, `violation`, `jump`, `max_length`.
    pub fn name(&self) -> &'static str {
        match self {
            Self::Unreachable => "unreachable",
            Self::Violation(_) => "violation",
            Self::Jump { .. } => "jump",
            Self::MaxLength => "max_length",
        }
    }
}

/// A Cartesian path: its configurations, one per waypoint reached (the start first), how far
/// along the line it got and why it ended.
#[derive(Clone, Debug, PartialEq)]
pub struct CartesianPath {
    /// The configuration at each waypoint reached; empty when not even the start pose was.
    pub waypoints: Vec<JointVector>,
    /// Distance along the line of the last waypoint reached (m).
    pub length_m: f64,
    /// Why the path ended.
    pub ended: CartesianEnd,
}

/// The Cartesian path of `task` from `start`: the start put on the exact pose `(p0, n)` with
/// the roll it has, then one waypoint every [`CartesianConfig::eef_step_m`] along `d`, each
/// solved from the previous solution with the whole pose held.
pub fn cartesian_path(
    robot: &Robot,
    task: &Task,
    constraints: &ConstraintConfig,
    start: &JointVector,
    config: &CartesianConfig,
) -> CartesianPath {
    let projection = ProjectionConfig::default();
    let rotation = *robot.forward(start).tcp_rotation();
    let x = rotation.column(0).into_owned();
    let roll = (x - task.n * x.dot(&task.n)).normalize();
    let target = |s: f64| PoseTarget {
        position: task.p0 + task.d * s,
        tool_axis: task.n,
        roll_axis: Some(roll),
    };
    let mut waypoints = Vec::new();
    let mut previous = *start;
    // The rounding margin keeps a length that is a whole number of steps whole.
    let steps = (config.max_length_m / config.eef_step_m + 1e-9).floor() as usize;
    for k in 0..=steps {
        let s = k as f64 * config.eef_step_m;
        let end = match project_to_pose(robot, &previous, &target(s), &projection) {
            Err(_) => Some(CartesianEnd::Unreachable),
            Ok((q, _)) => {
                let jump = (q - previous).amax();
                if k > 0 && jump > config.jump_threshold_rad {
                    Some(CartesianEnd::Jump { rad: jump })
                } else if let Some(violation) =
                    first_violation(robot, task, &robot.forward(&q), constraints)
                {
                    Some(CartesianEnd::Violation(violation))
                } else {
                    waypoints.push(q);
                    previous = q;
                    None
                }
            }
        };
        if let Some(ended) = end {
            return CartesianPath {
                length_m: waypoints.len().saturating_sub(1) as f64 * config.eef_step_m,
                waypoints,
                ended,
            };
        }
    }
    CartesianPath {
        length_m: steps as f64 * config.eef_step_m,
        waypoints,
        ended: CartesianEnd::MaxLength,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::test_support::{demo, fr3};

    #[test]
    fn the_demo_line_is_followed_with_the_pose_held_and_every_waypoint_valid() {
        let robot = fr3();
        let (task, start) = demo(&robot);
        let constraints = ConstraintConfig::default();
        let config = CartesianConfig::default();
        let line = cartesian_path(&robot, &task, &constraints, &start, &config);
        assert!(line.length_m > 0.05, "{}: {}", line.length_m, line.ended);
        let first = robot.forward(&line.waypoints[0]);
        for (k, q) in line.waypoints.iter().enumerate() {
            let kinematics = robot.forward(q);
            let expected = task.p0 + task.d * (k as f64 * config.eef_step_m);
            assert!((kinematics.tcp() - expected).norm() < 1e-8, "waypoint {k}");
            assert!((kinematics.tcp_rotation() - first.tcp_rotation()).norm() < 1e-8);
            assert!((kinematics.tool_axis() - task.n).norm() < 1e-8);
            assert_eq!(
                first_violation(&robot, &task, &kinematics, &constraints),
                None
            );
        }
        for pair in line.waypoints.windows(2) {
            assert!((pair[1] - pair[0]).amax() <= config.jump_threshold_rad);
        }
        assert_ne!(
            line.ended,
            CartesianEnd::MaxLength,
            "the FR3 cannot draw 3 m"
        );
        // A shorter longest path ends there.
        let short = CartesianConfig {
            max_length_m: 0.03,
            ..config.clone()
        };
        let capped = cartesian_path(&robot, &task, &constraints, &start, &short);
        assert_eq!(capped.ended, CartesianEnd::MaxLength);
        assert_eq!(capped.waypoints[..], line.waypoints[..4]);
        assert!(
            CartesianConfig {
                eef_step_m: 0.0,
                ..config
            }
            .validate()
            .is_err()
        );
    }
}
