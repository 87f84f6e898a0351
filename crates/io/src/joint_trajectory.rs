//! The `emg-joint-trajectory/2` JSON layout, modelled on ROS `trajectory_msgs/JointTrajectory`:
//! joint names and a rest-to-rest motion sampled at a fixed rate (positions, velocities,
//! accelerations, `time_from_start` in whole nanoseconds), carrying the task, the constraints
//! and the joint limits it was timed for, so that the file alone can be verified. The layout is
//! documented in `docs/joint-trajectory-format.md`.

use emg_control::{ConstraintConfig, Task};
use emg_kinematics::{JointVector, MAX_DOF, MIN_DOF};
use emg_timing::{TimedMotion, TimingReport};
use emg_verify::{JointDynamics, JointSamples};
use serde::{Deserialize, Serialize};
use serde_json::{Map, Value};

use crate::error::{FormatError, field_error};

/// Value of the `format` field of every joint-trajectory file.
pub const JOINT_TRAJECTORY_FORMAT: &str = "emg-joint-trajectory/2";

/// A time since the start in whole nanoseconds, as ROS `builtin_interfaces/Duration`
/// (`sec` + `nanosec`, `0 ≤ nanosec < 10⁹`).
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord, Serialize, Deserialize)]
pub struct TimeFromStart {
    /// Whole seconds.
    pub sec: i32,
    /// Nanoseconds past `sec`, below 10⁹.
    pub nanosec: u32,
}

impl TimeFromStart {
    /// The time in seconds, `sec + nanosec / 10⁹`.
    pub fn seconds(&self) -> f64 {
        f64::from(self.sec) + f64::from(self.nanosec) / 1e9
    }

    /// The time `total` ns after the start; `None` past 2³¹ s.
    pub fn from_nanoseconds(total: u64) -> Option<Self> {
        Some(Self {
            sec: i32::try_from(total / 1_000_000_000).ok()?,
            nanosec: u32::try_from(total % 1_000_000_000).ok()?,
        })
    }
}

/// The joint limits a motion was timed for, as its file records them.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct TimingLimits {
    /// The MoveIt `joint_limits.yaml` the limits were read from, relative to the robot file's
    /// directory.
    pub joint_limits_file: String,
    /// Factor on the file's velocity limits.
    pub velocity_scaling: f64,
    /// Factor on the file's acceleration and jerk limits.
    pub acceleration_scaling: f64,
    /// Largest tool speed asked for (m/s).
    pub tool_speed_m_per_s: f64,
    /// The velocity limits every point holds (rad/s): the file's, scaled, and at most the robot
    /// file's times the constraints' `velocity_limit_fraction`.
    pub max_velocity: Vec<f64>,
    /// The acceleration limits every point holds (rad/s²), scaled.
    pub max_acceleration: Vec<f64>,
    /// The jerk limits every point holds (rad/s³), scaled.
    pub max_jerk: Vec<f64>,
}

impl TimingLimits {
    /// The limits as the checker takes them.
    pub fn dynamics(&self) -> JointDynamics {
        JointDynamics {
            velocity: self.max_velocity.clone(),
            acceleration: self.max_acceleration.clone(),
            jerk: self.max_jerk.clone(),
        }
    }
}

/// How a motion was timed, as its file records it (a report: the checker does not rely on it).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct TimingSummary {
    /// Samples per second.
    pub rate_hz: f64,
    /// Time from rest to rest (s).
    pub duration_s: f64,
    /// Time of the fastest motion along the same path under the velocity, acceleration and
    /// tool-speed limits alone, without jerk limits (s).
    pub time_optimal_s: f64,
    /// Share of the duration with the tool at ≥ 99 % of the requested speed.
    pub tool_speed_share: f64,
    /// TCP travel along the smooth path (m).
    pub path_travel_m: f64,
    /// Knots the smooth path gained to hold the task constraints.
    pub refined_knots: usize,
    /// When the smooth path ends before the last planned point: the planned point it ends at.
    pub cut_at_point: Option<usize>,
    /// And the constraint the spline broke beyond it.
    pub cut_reason: Option<String>,
    /// Rounds of local slow-down the limits needed.
    pub slowdowns: usize,
    /// Times (s) at which the motion rests inside its path (a path task's unblended corners);
    /// absent on a line.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub rests_s: Vec<f64>,
}

impl TimingSummary {
    /// The summary of a timing `report` at `rate_hz`.
    pub fn new(report: &TimingReport, rate_hz: f64) -> Self {
        Self {
            rate_hz,
            duration_s: report.duration_s,
            time_optimal_s: report.time_optimal_s,
            tool_speed_share: report.tool_speed_share,
            path_travel_m: report.path_travel_m,
            refined_knots: report.refined_knots,
            cut_at_point: report.cut.as_ref().map(|(point, _)| *point),
            cut_reason: report.cut.as_ref().map(|(_, reason)| reason.clone()),
            slowdowns: report.slowdowns,
            rests_s: report.rests_s.clone(),
        }
    }
}

/// One point of a [`JointTrajectory`], as ROS `trajectory_msgs/JointTrajectoryPoint` (without
/// efforts).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct JointTrajectoryPoint {
    /// Joint positions (rad), in `joint_names` order.
    pub positions: Vec<f64>,
    /// Joint velocities (rad/s), in `joint_names` order.
    pub velocities: Vec<f64>,
    /// Joint accelerations (rad/s²), in `joint_names` order.
    pub accelerations: Vec<f64>,
    /// Time since the first point.
    pub time_from_start: TimeFromStart,
}

/// A planned motion as a robot stack replays it (`emg-joint-trajectory/2`): rest to rest at a
/// fixed rate, with the task, constraints and joint limits it holds.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct JointTrajectory {
    /// Always [`JOINT_TRAJECTORY_FORMAT`].
    pub format: String,
    /// The robot file the motion was planned for (the path as given to the planner).
    pub robot: String,
    /// The arm's `n` revolute joints (6 or 7), base to tip (the order of every position and
    /// velocity).
    pub joint_names: Vec<String>,
    /// The task the motion follows.
    pub task: Task,
    /// The constraints every point holds.
    pub constraints: ConstraintConfig,
    /// The joint limits every point holds.
    pub limits: TimingLimits,
    /// How the motion was timed.
    pub timing: TimingSummary,
    /// The samples, from rest at the seed to rest at the end.
    pub points: Vec<JointTrajectoryPoint>,
}

impl JointTrajectory {
    /// The file of `motion` (timed for `limits`, at `rate_hz`).
    ///
    /// Fails when there are not 6 or 7 joint names or a sample lies past 2³¹ s.
    pub fn new(
        robot: &str,
        joint_names: &[String],
        task: &Task,
        constraints: &ConstraintConfig,
        limits: TimingLimits,
        motion: &TimedMotion,
        rate_hz: f64,
    ) -> Result<Self, FormatError> {
        let joints = joint_count(joint_names.len())?;
        let points = motion
            .samples
            .iter()
            .enumerate()
            .map(|(k, sample)| {
                let time_from_start =
                    TimeFromStart::from_nanoseconds(sample.time_ns).ok_or_else(|| {
                        field_error(format!("points[{k}].time_from_start"), "is past 2^31 s")
                    })?;
                Ok(JointTrajectoryPoint {
                    positions: sample.q.as_slice()[..joints].to_vec(),
                    velocities: sample.qd.as_slice()[..joints].to_vec(),
                    accelerations: sample.qdd.as_slice()[..joints].to_vec(),
                    time_from_start,
                })
            })
            .collect::<Result<_, FormatError>>()?;
        Ok(Self {
            format: JOINT_TRAJECTORY_FORMAT.to_string(),
            robot: robot.to_string(),
            joint_names: joint_names.to_vec(),
            task: task.clone(),
            constraints: constraints.clone(),
            limits,
            timing: TimingSummary::new(&motion.report, rate_hz),
            points,
        })
    }

    /// The file's text: compact JSON on one line, numbers in their shortest round-trip form.
    pub fn to_json(&self) -> String {
        serde_json::to_string(self).expect("a joint trajectory serialises")
    }

    /// Reads a file's text. Checks the `format`, that there are `n` = 6 or 7 joint names, that
    /// the limits hold `n` positive numbers each, that every point has `n` finite positions,
    /// velocities and accelerations and a `time_from_start` with `nanosec < 10⁹`; the error
    /// names the field. Fields other than those of the layout are ignored.
    pub fn from_json(text: &str) -> Result<Self, FormatError> {
        let value: Value =
            serde_json::from_str(text).map_err(|e| FormatError::Json(e.to_string()))?;
        let top = value
            .as_object()
            .ok_or_else(|| field_error("(top level)", "is not a JSON object"))?;
        let format = string(member(top, "format", "format")?, "format")?;
        if format != JOINT_TRAJECTORY_FORMAT {
            return Err(field_error(
                "format",
                format!("is {format:?}, expected {JOINT_TRAJECTORY_FORMAT:?}"),
            ));
        }
        let robot = string(member(top, "robot", "robot")?, "robot")?;
        let names = array(member(top, "joint_names", "joint_names")?, "joint_names")?;
        let joints = joint_count(names.len())?;
        let joint_names = names
            .iter()
            .enumerate()
            .map(|(i, name)| string(name, &format!("joint_names[{i}]")))
            .collect::<Result<Vec<_>, _>>()?;
        let task = serde_json::from_value(member(top, "task", "task")?.clone())
            .map_err(|e| field_error("task", format!("is not a task: {e}")))?;
        let constraints =
            serde_json::from_value(member(top, "constraints", "constraints")?.clone())
                .map_err(|e| field_error("constraints", format!("is not a constraint set: {e}")))?;
        let limits: TimingLimits = serde_json::from_value(member(top, "limits", "limits")?.clone())
            .map_err(|e| field_error("limits", format!("is not a set of limits: {e}")))?;
        for (name, values) in [
            ("max_velocity", &limits.max_velocity),
            ("max_acceleration", &limits.max_acceleration),
            ("max_jerk", &limits.max_jerk),
        ] {
            if values.len() != joints || !values.iter().all(|v| v.is_finite() && *v > 0.0) {
                return Err(field_error(
                    format!("limits.{name}"),
                    format!("is {values:?}, expected {joints} positive numbers (one per joint)"),
                ));
            }
        }
        let timing = serde_json::from_value(member(top, "timing", "timing")?.clone())
            .map_err(|e| field_error("timing", format!("is not a timing summary: {e}")))?;
        let points = array(member(top, "points", "points")?, "points")?
            .iter()
            .enumerate()
            .map(|(k, point)| read_point(point, joints, &format!("points[{k}]")))
            .collect::<Result<Vec<_>, _>>()?;
        Ok(Self {
            format,
            robot,
            joint_names,
            task,
            constraints,
            limits,
            timing,
            points,
        })
    }

    /// The points as [`JointSamples`]: times from `time_from_start`, positions, and the declared
    /// velocities and accelerations.
    pub fn samples(&self) -> JointSamples {
        let vector = padded;
        JointSamples {
            time_s: self
                .points
                .iter()
                .map(|p| p.time_from_start.seconds())
                .collect(),
            q: self.points.iter().map(|p| vector(&p.positions)).collect(),
            qd: Some(self.points.iter().map(|p| vector(&p.velocities)).collect()),
            qdd: Some(
                self.points
                    .iter()
                    .map(|p| vector(&p.accelerations))
                    .collect(),
            ),
        }
    }
}

fn member<'a>(
    object: &'a Map<String, Value>,
    name: &str,
    path: &str,
) -> Result<&'a Value, FormatError> {
    object
        .get(name)
        .ok_or_else(|| field_error(path, "is missing"))
}

fn describe(value: &Value) -> String {
    let text = value.to_string();
    if text.chars().count() > 40 {
        format!("{}…", text.chars().take(40).collect::<String>())
    } else {
        text
    }
}

fn string(value: &Value, path: &str) -> Result<String, FormatError> {
    value
        .as_str()
        .map(str::to_string)
        .ok_or_else(|| field_error(path, format!("is {}, expected a string", describe(value))))
}

fn array<'a>(value: &'a Value, path: &str) -> Result<&'a Vec<Value>, FormatError> {
    value
        .as_array()
        .ok_or_else(|| field_error(path, format!("is {}, expected an array", describe(value))))
}

/// The number of joints `count` names, checked to be an arm's (6 or 7).
pub(crate) fn joint_count(count: usize) -> Result<usize, FormatError> {
    if (MIN_DOF..=MAX_DOF).contains(&count) {
        Ok(count)
    } else {
        Err(field_error(
            "joint_names",
            format!("has {count} entries, expected {MIN_DOF} or {MAX_DOF} (one per joint)"),
        ))
    }
}

/// The joint vector of an arm's joint values (zero past them).
pub(crate) fn padded(values: &[f64]) -> JointVector {
    JointVector::from_fn(|i, _| values.get(i).copied().unwrap_or(0.0))
}

/// Exactly `joints` finite numbers.
pub(crate) fn joint_values(
    value: &Value,
    joints: usize,
    path: &str,
) -> Result<Vec<f64>, FormatError> {
    let values = array(value, path)?;
    if values.len() != joints {
        return Err(field_error(
            path,
            format!(
                "has {} values, expected {joints} (one per joint)",
                values.len()
            ),
        ));
    }
    values
        .iter()
        .enumerate()
        .map(|(i, v)| match v.as_f64() {
            Some(x) if x.is_finite() => Ok(x),
            _ => Err(field_error(
                format!("{path}[{i}]"),
                format!("is {}, expected a finite number", describe(v)),
            )),
        })
        .collect()
}

fn read_point(
    value: &Value,
    joints: usize,
    path: &str,
) -> Result<JointTrajectoryPoint, FormatError> {
    let object = value
        .as_object()
        .ok_or_else(|| field_error(path, format!("is {}, expected an object", describe(value))))?;
    let at = |name: &str| format!("{path}.{name}");
    let positions = joint_values(
        member(object, "positions", &at("positions"))?,
        joints,
        &at("positions"),
    )?;
    let velocities = joint_values(
        member(object, "velocities", &at("velocities"))?,
        joints,
        &at("velocities"),
    )?;
    let accelerations = joint_values(
        member(object, "accelerations", &at("accelerations"))?,
        joints,
        &at("accelerations"),
    )?;
    let time_path = at("time_from_start");
    let time = member(object, "time_from_start", &time_path)?
        .as_object()
        .ok_or_else(|| field_error(&time_path, "is not an object {\"sec\", \"nanosec\"}"))?;
    let integer = |name: &str| {
        let path = format!("{time_path}.{name}");
        let value = member(time, name, &path)?;
        value.as_i64().ok_or_else(|| {
            field_error(
                &path,
                format!("is {}, expected an integer", describe(value)),
            )
        })
    };
    let sec = integer("sec")?;
    let sec = i32::try_from(sec).ok().filter(|s| *s >= 0).ok_or_else(|| {
        field_error(
            format!("{time_path}.sec"),
            format!("is {sec}, expected 0 ≤ sec < 2^31"),
        )
    })?;
    let nanosec = integer("nanosec")?;
    let nanosec = u32::try_from(nanosec)
        .ok()
        .filter(|n| *n < 1_000_000_000)
        .ok_or_else(|| {
            field_error(
                format!("{time_path}.nanosec"),
                format!("is {nanosec}, expected 0 ≤ nanosec < 1000000000"),
            )
        })?;
    Ok(JointTrajectoryPoint {
        positions,
        velocities,
        accelerations,
        time_from_start: TimeFromStart { sec, nanosec },
    })
}
