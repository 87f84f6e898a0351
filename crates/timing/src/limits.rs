//! Joint limits a URDF cannot hold: acceleration and jerk (and tighter velocities), read from a
//! MoveIt `joint_limits.yaml`, and the velocity/acceleration scaling a user asks for.

use std::collections::BTreeMap;
use std::path::Path;

use emg_kinematics::{JointVector, MAX_DOF, Robot};
use serde::Deserialize;

/// Acceleration limit (rad/s²) assumed for every joint of a robot whose vendor publishes none:
/// conservative, half the 10 rad/s² a MoveIt configuration of the KUKA LBR iiwa uses
/// (lbr_fri_ros2_stack), and half the FR3's published 10 rad/s².
pub const ASSUMED_ACCELERATION_RAD_S2: f64 = 5.0;

/// Jerk limit (rad/s³) assumed for every joint of a robot whose vendor publishes none: the jerk
/// limit of the iiwa's MoveIt configuration in ICube-Robotics/iiwa_ros2, far below the FR3's
/// published 5,000 rad/s³.
pub const ASSUMED_JERK_RAD_S3: f64 = 300.0;

/// Per-joint velocity (rad/s), acceleration (rad/s²) and jerk (rad/s³) limits, base to tip.
#[derive(Clone, Debug, PartialEq)]
pub struct DynamicLimits {
    /// Largest joint speed (rad/s).
    pub velocity: JointVector,
    /// Largest joint acceleration (rad/s²).
    pub acceleration: JointVector,
    /// Largest joint jerk (rad/s³).
    pub jerk: JointVector,
}

/// Velocity and acceleration scaling factors in (0, 1], as MoveIt and Pilz take them: velocity
/// limits are multiplied by `velocity`, acceleration and jerk limits by `acceleration`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Scaling {
    /// Factor on the velocity limits.
    pub velocity: f64,
    /// Factor on the acceleration and jerk limits.
    pub acceleration: f64,
}

impl Default for Scaling {
    fn default() -> Self {
        Self {
            velocity: 1.0,
            acceleration: 1.0,
        }
    }
}

/// Why limits could not be read or used; names the file or field and what is wrong.
#[derive(Debug, thiserror::Error)]
pub enum LimitsError {
    /// The file could not be read.
    #[error("cannot read joint limits {path}: {source}")]
    Read {
        /// The file.
        path: String,
        /// The operating system's error.
        source: std::io::Error,
    },
    /// The text is not YAML of the MoveIt layout.
    #[error("joint limits {path}: not a MoveIt joint_limits.yaml: {message}")]
    Syntax {
        /// The file.
        path: String,
        /// The parser's message (with its line and column).
        message: String,
    },
    /// A field is missing or holds an unusable value.
    #[error("joint limits {path}: field '{field}' {problem}")]
    Field {
        /// The file.
        path: String,
        /// The field, e.g. `joint_limits.fr3_joint4.max_jerk`.
        field: String,
        /// What is wrong with it.
        problem: String,
    },
    /// A scaling factor is outside (0, 1].
    #[error("{field} must be in (0, 1], got {value}")]
    Scaling {
        /// `velocity_scaling` or `acceleration_scaling`.
        field: &'static str,
        /// The value given.
        value: f64,
    },
}

/// The MoveIt layout: `joint_limits: {<joint>: {has_velocity_limits, max_velocity, ...}}`.
/// Other keys (positions, efforts, default scaling factors) are allowed and not used.
#[derive(Deserialize)]
struct LimitsFile {
    joint_limits: BTreeMap<String, JointEntry>,
}

#[derive(Deserialize)]
struct JointEntry {
    #[serde(default)]
    has_velocity_limits: bool,
    max_velocity: Option<f64>,
    #[serde(default)]
    has_acceleration_limits: bool,
    max_acceleration: Option<f64>,
    #[serde(default)]
    has_jerk_limits: bool,
    max_jerk: Option<f64>,
}

impl Scaling {
    /// Both factors checked to lie in (0, 1].
    pub fn new(velocity: f64, acceleration: f64) -> Result<Self, LimitsError> {
        for (field, value) in [
            ("velocity_scaling", velocity),
            ("acceleration_scaling", acceleration),
        ] {
            if !(value > 0.0 && value <= 1.0) {
                return Err(LimitsError::Scaling { field, value });
            }
        }
        Ok(Self {
            velocity,
            acceleration,
        })
    }
}

impl DynamicLimits {
    /// Limits for a robot whose vendor gives no acceleration or jerk limits: the robot file's
    /// velocity limits, [`ASSUMED_ACCELERATION_RAD_S2`] and [`ASSUMED_JERK_RAD_S3`].
    pub fn assumed(robot: &Robot) -> Self {
        Self {
            velocity: robot.limits().velocity,
            acceleration: JointVector::repeat(ASSUMED_ACCELERATION_RAD_S2),
            jerk: JointVector::repeat(ASSUMED_JERK_RAD_S3),
        }
    }

    /// These limits as a MoveIt `joint_limits.yaml` for `robot`'s joints, after the comment
    /// lines of `header` (each prefixed with `# `); [`DynamicLimits::parse`] reads it back
    /// exactly.
    pub fn to_yaml(&self, robot: &Robot, header: &str) -> String {
        let mut text: String = header.lines().map(|line| format!("# {line}\n")).collect();
        text.push_str(
            "default_velocity_scaling_factor: 1.0\ndefault_acceleration_scaling_factor: 1.0\n\
             joint_limits:\n",
        );
        for (i, name) in robot.joint_names().iter().enumerate().take(MAX_DOF) {
            text.push_str(&format!(
                "  {name}:\n    has_velocity_limits: true\n    max_velocity: {:?}\n    \
                 has_acceleration_limits: true\n    max_acceleration: {:?}\n    \
                 has_jerk_limits: true\n    max_jerk: {:?}\n",
                self.velocity[i], self.acceleration[i], self.jerk[i]
            ));
        }
        text
    }

    /// The limits of `robot`'s joints from a MoveIt `joint_limits.yaml` file.
    pub fn read(path: impl AsRef<Path>, robot: &Robot) -> Result<Self, LimitsError> {
        let path = path.as_ref();
        let text = std::fs::read_to_string(path).map_err(|source| LimitsError::Read {
            path: path.display().to_string(),
            source,
        })?;
        Self::parse(&text, &path.display().to_string(), robot)
    }

    /// The limits of `robot`'s joints from the text of a MoveIt `joint_limits.yaml` (`origin`
    /// names it in errors). Every joint of the robot needs an entry with a positive, finite
    /// `max_acceleration` and `max_jerk` (and `has_acceleration_limits`, `has_jerk_limits`
    /// true); `max_velocity` is used when `has_velocity_limits` is true, else the robot file's
    /// velocity limit.
    pub fn parse(text: &str, origin: &str, robot: &Robot) -> Result<Self, LimitsError> {
        let file: LimitsFile = serde_saphyr::from_str(text).map_err(|e| LimitsError::Syntax {
            path: origin.to_string(),
            message: e.to_string(),
        })?;
        let field_error = |field: String, problem: String| LimitsError::Field {
            path: origin.to_string(),
            field,
            problem,
        };
        // Every joint of the robot is read below; the assumed values stay only in the slots
        // past an arm's joints, which never move.
        let mut limits = Self::assumed(robot);
        for (i, name) in robot.joint_names().iter().enumerate().take(MAX_DOF) {
            let entry = file.joint_limits.get(name).ok_or_else(|| {
                field_error(
                    format!("joint_limits.{name}"),
                    format!(
                        "is missing: the file must list every joint of the robot ({})",
                        robot.joint_names().join(", ")
                    ),
                )
            })?;
            let value = |has: bool, max: Option<f64>, key: &str| {
                let field = format!("joint_limits.{name}.{key}");
                match (has, max) {
                    (false, _) => Err(field_error(
                        format!("joint_limits.{name}.has_{}_limits", &key[4..]),
                        "must be true: timing needs every joint's acceleration and jerk limit"
                            .to_string(),
                    )),
                    (true, None) => Err(field_error(field, "is missing".to_string())),
                    (true, Some(v)) if !(v.is_finite() && v > 0.0) => Err(field_error(
                        field,
                        format!("is {v}, expected a positive finite number"),
                    )),
                    (true, Some(v)) => Ok(v),
                }
            };
            if entry.has_velocity_limits {
                limits.velocity[i] =
                    value(true, entry.max_velocity, "max_velocity")?.min(limits.velocity[i]);
            }
            limits.acceleration[i] = value(
                entry.has_acceleration_limits,
                entry.max_acceleration,
                "max_acceleration",
            )?;
            limits.jerk[i] = value(entry.has_jerk_limits, entry.max_jerk, "max_jerk")?;
        }
        Ok(limits)
    }

    /// The limits with `scaling` applied: velocities × `scaling.velocity`, accelerations and
    /// jerks × `scaling.acceleration`.
    pub fn scaled(&self, scaling: Scaling) -> Self {
        Self {
            velocity: self.velocity * scaling.velocity,
            acceleration: self.acceleration * scaling.acceleration,
            jerk: self.jerk * scaling.acceleration,
        }
    }

    /// The limits with every velocity limit lowered to at most `ceiling` (per joint).
    pub fn with_velocity_ceiling(&self, ceiling: &JointVector) -> Self {
        Self {
            velocity: self.velocity.inf(ceiling),
            ..self.clone()
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn assumed_limits_written_as_yaml_read_back_exactly() {
        let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../data/robots/iiwa14_pen.urdf");
        let robot = Robot::from_chain_file(&path).unwrap();
        let limits = DynamicLimits::assumed(&robot);
        assert_eq!(limits.velocity, robot.limits().velocity);
        let text = limits.to_yaml(&robot, "assumed limits\nsecond line");
        assert!(
            text.starts_with("# assumed limits\n# second line\n"),
            "{text}"
        );
        assert_eq!(DynamicLimits::parse(&text, "t", &robot).unwrap(), limits);
    }
}
