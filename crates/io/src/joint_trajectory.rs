//! The `emg-joint-trajectory/1` JSON layout, modelled on ROS `trajectory_msgs/JointTrajectory`:
//! joint names, points with positions, velocities (by [`point_velocities`]) and a
//! `time_from_start` in whole nanoseconds, carrying the task and the constraints so that the
//! file alone can be verified. The layout is documented in `docs/joint-trajectory-format.md`.

use emg_control::{ConstraintConfig, Task, Trajectory};
use emg_kinematics::{DOF, JointVector};
use emg_verify::{JointSamples, point_velocities};
use serde::{Deserialize, Serialize};
use serde_json::{Map, Value};

use crate::error::{FormatError, field_error};

/// Value of the `format` field of every joint-trajectory file.
pub const JOINT_TRAJECTORY_FORMAT: &str = "emg-joint-trajectory/1";

/// A gap between consecutive times that lies this little (ns) above a whole number of
/// nanoseconds is float noise of the accumulated times and is rounded down to it; any larger
/// excess is rounded up (see [`times_from_start`]).
pub const GAP_ROUNDING_NOISE_NS: f64 = 1e-3;

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

    fn from_nanoseconds(total: u64) -> Option<Self> {
        Some(Self {
            sec: i32::try_from(total / 1_000_000_000).ok()?,
            nanosec: u32::try_from(total % 1_000_000_000).ok()?,
        })
    }

    fn nanoseconds(&self) -> u64 {
        u64::try_from(self.sec).expect("sec ≥ 0") * 1_000_000_000 + u64::from(self.nanosec)
    }
}

/// The `time_from_start` of points planned at `time_s` (s): the first time rounded to the
/// nearest nanosecond, then each gap `t_k − t_{k−1}` rounded **up** to whole nanoseconds (at
/// least 1 ns; a gap within [`GAP_ROUNDING_NOISE_NS`] above a whole number of nanoseconds is
/// rounded down to it) and summed. No gap is shorter than planned (beyond that noise), so joint
/// speeds computed from the file's positions and times never exceed the planned ones; point
/// `k` lies between `k · 0.001` ns before and `k` ns after its planned time.
///
/// Fails, naming the point, on a time that is not finite, a negative first time, times that do
/// not increase, or a time past 2³¹ s.
pub fn times_from_start(time_s: &[f64]) -> Result<Vec<TimeFromStart>, FormatError> {
    let mut out: Vec<TimeFromStart> = Vec::with_capacity(time_s.len());
    for (k, t) in time_s.iter().enumerate() {
        let total = match out.last() {
            None if t.is_finite() && *t >= 0.0 && *t < 1e18 => Some((t * 1e9).round() as u64),
            None => None,
            Some(previous) => {
                let gap = t - time_s[k - 1];
                if gap.is_nan() || gap <= 0.0 {
                    return Err(field_error(
                        format!("points[{k}].time_from_start"),
                        format!(
                            "cannot be made from time {t} s: it does not come after the previous \
                             point's {} s",
                            time_s[k - 1]
                        ),
                    ));
                }
                let gap_ns = (gap * 1e9 - GAP_ROUNDING_NOISE_NS).ceil().max(1.0);
                (gap_ns < 1e18).then(|| previous.nanoseconds() + gap_ns as u64)
            }
        };
        let time = total
            .and_then(TimeFromStart::from_nanoseconds)
            .ok_or_else(|| {
                field_error(
                    format!("points[{k}].time_from_start"),
                    format!("cannot be made from time {t} s (it must be finite, ≥ 0, < 2^31 s)"),
                )
            })?;
        out.push(time);
    }
    Ok(out)
}

/// One point of a [`JointTrajectory`], as ROS `trajectory_msgs/JointTrajectoryPoint` (without
/// accelerations and efforts).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct JointTrajectoryPoint {
    /// Joint positions (rad), in `joint_names` order.
    pub positions: Vec<f64>,
    /// Joint velocities (rad/s) by [`point_velocities`], in `joint_names` order.
    pub velocities: Vec<f64>,
    /// Time since the first point.
    pub time_from_start: TimeFromStart,
}

/// A planned motion as a robot stack replays it (`emg-joint-trajectory/1`), with the task and
/// constraints it was planned for.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct JointTrajectory {
    /// Always [`JOINT_TRAJECTORY_FORMAT`].
    pub format: String,
    /// The robot file the motion was planned for (the path as given to the planner).
    pub robot: String,
    /// The seven revolute joints, base to tip (the order of every position and velocity).
    pub joint_names: Vec<String>,
    /// The task the motion follows.
    pub task: Task,
    /// The constraints every point holds.
    pub constraints: ConstraintConfig,
    /// The points, the seed first.
    pub points: Vec<JointTrajectoryPoint>,
}

impl JointTrajectory {
    /// The joint trajectory of `trajectory` (every recorded step, the seed first): positions as
    /// recorded, times by [`times_from_start`], and velocities by [`point_velocities`] from those
    /// positions and the file's own times.
    ///
    /// Fails when there are not seven joint names or the times cannot be written.
    pub fn new(
        robot: &str,
        joint_names: &[String],
        task: &Task,
        constraints: &ConstraintConfig,
        trajectory: &Trajectory,
    ) -> Result<Self, FormatError> {
        if joint_names.len() != DOF {
            return Err(field_error(
                "joint_names",
                format!("has {} entries, expected {DOF}", joint_names.len()),
            ));
        }
        let planned: Vec<f64> = trajectory.steps.iter().map(|s| s.time_s).collect();
        let times = times_from_start(&planned)?;
        let seconds: Vec<f64> = times.iter().map(TimeFromStart::seconds).collect();
        let q: Vec<JointVector> = trajectory.steps.iter().map(|s| s.q).collect();
        let velocities = point_velocities(&seconds, &q);
        let points = q
            .iter()
            .zip(&velocities)
            .zip(times)
            .map(|((q, qd), time_from_start)| JointTrajectoryPoint {
                positions: q.as_slice().to_vec(),
                velocities: qd.as_slice().to_vec(),
                time_from_start,
            })
            .collect();
        Ok(Self {
            format: JOINT_TRAJECTORY_FORMAT.to_string(),
            robot: robot.to_string(),
            joint_names: joint_names.to_vec(),
            task: task.clone(),
            constraints: constraints.clone(),
            points,
        })
    }

    /// The file's text: compact JSON on one line, numbers in their shortest round-trip form.
    pub fn to_json(&self) -> String {
        serde_json::to_string(self).expect("a joint trajectory serialises")
    }

    /// Reads a file's text. Checks the `format`, that there are seven joint names, that every
    /// point has seven finite positions and velocities and a `time_from_start` with
    /// `nanosec < 10⁹`; the error names the field. Fields other than those of the layout are
    /// ignored.
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
        if names.len() != DOF {
            return Err(field_error(
                "joint_names",
                format!("has {} entries, expected {DOF}", names.len()),
            ));
        }
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
        let points = array(member(top, "points", "points")?, "points")?
            .iter()
            .enumerate()
            .map(|(k, point)| read_point(point, &format!("points[{k}]")))
            .collect::<Result<Vec<_>, _>>()?;
        Ok(Self {
            format,
            robot,
            joint_names,
            task,
            constraints,
            points,
        })
    }

    /// The points as [`JointSamples`]: times from `time_from_start`, positions, and the declared
    /// velocities.
    pub fn samples(&self) -> JointSamples {
        let vector = |values: &[f64]| JointVector::from_column_slice(values);
        JointSamples {
            time_s: self
                .points
                .iter()
                .map(|p| p.time_from_start.seconds())
                .collect(),
            q: self.points.iter().map(|p| vector(&p.positions)).collect(),
            qd: Some(self.points.iter().map(|p| vector(&p.velocities)).collect()),
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

/// Exactly [`DOF`] finite numbers.
fn joint_values(value: &Value, path: &str) -> Result<Vec<f64>, FormatError> {
    let values = array(value, path)?;
    if values.len() != DOF {
        return Err(field_error(
            path,
            format!(
                "has {} values, expected {DOF} (one per joint)",
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

fn read_point(value: &Value, path: &str) -> Result<JointTrajectoryPoint, FormatError> {
    let object = value
        .as_object()
        .ok_or_else(|| field_error(path, format!("is {}, expected an object", describe(value))))?;
    let at = |name: &str| format!("{path}.{name}");
    let positions = joint_values(
        member(object, "positions", &at("positions"))?,
        &at("positions"),
    )?;
    let velocities = joint_values(
        member(object, "velocities", &at("velocities"))?,
        &at("velocities"),
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
        time_from_start: TimeFromStart { sec, nanosec },
    })
}
