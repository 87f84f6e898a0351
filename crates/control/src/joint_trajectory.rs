//! Trajectory files a robot stack can replay, and reading every trajectory file back for the
//! independent checker.
//!
//! * [`JointTrajectory`]: the `emg-joint-trajectory/1` JSON layout, modelled on ROS
//!   `trajectory_msgs/JointTrajectory` (joint names, points with positions, velocities and a
//!   `time_from_start` in whole nanoseconds), carrying the task and the constraints so that the
//!   file alone can be verified.
//! * [`trajectory_csv`] / [`read_csv`]: the CSV table of a rollout (`time_s`, `q1..q7`,
//!   `qd1..qd7`, TCP, tool angle, `ρ`, controller) and its reader.
//! * [`point_velocities`]: the velocity rule shared by both: the central difference at interior
//!   points, the one-sided segment velocity at the ends.
//! * [`JointSamples`]: timed joint positions (and declared velocities) from any of the files;
//!   [`JointSamples::to_trajectory`] rebuilds a [`Trajectory`] with the checker's own forward
//!   kinematics, and [`check_replay`] verifies it with [`ReferenceModel`], joint speeds and the
//!   declared velocities included.
//!
//! The layouts are documented in `docs/joint-trajectory-format.md` and
//! `docs/trajectory-format.md`.
//!
//! ```
//! use emg_control::{
//!     ClassicalController, JointTrajectory, ReferenceModel, RolloutConfig, Task, check_replay,
//!     rollout,
//! };
//! use emg_kinematics::{Robot, Vec3};
//! let path = emg_kinematics::default_robot_path();
//! let robot = Robot::from_urdf_file(&path, "link0", "pen_tip")?;
//! let seed = robot.mid_range();
//! let kin = robot.forward(&seed);
//! let task = Task::new(&robot, kin.tcp(), Vec3::y(), kin.tool_axis(), Some(seed))?;
//! let config = RolloutConfig { max_steps: 20, ..RolloutConfig::default() };
//! let trajectory = rollout(&robot, &task, &seed, &mut ClassicalController::default(), &config);
//!
//! let file = JointTrajectory::new("fr3_pen.urdf", robot.joint_names(), &task,
//!                                 &config.constraints, &trajectory)?;
//! let back = JointTrajectory::from_json(&file.to_json())?;
//! assert_eq!(back, file);
//!
//! let checker = ReferenceModel::from_urdf_file(&path, "link0", "pen_tip")?;
//! let samples = back.samples();
//! let report = check_replay(&checker, &back.task, &back.constraints, &samples, None)?;
//! assert_eq!(report.points, 21);
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```

use emg_kinematics::{DOF, JointVector};
use serde::{Deserialize, Serialize};
use serde_json::{Map, Value};

use crate::checker::ReferenceModel;
use crate::config::ConstraintConfig;
use crate::constraints::tool_angle_deg;
use crate::rollout::{StepRecord, Termination, Trajectory};
use crate::task::Task;

/// Value of the `format` field of every joint-trajectory file.
pub const JOINT_TRAJECTORY_FORMAT: &str = "emg-joint-trajectory/1";

/// A gap between consecutive times that lies this little (ns) above a whole number of
/// nanoseconds is float noise of the accumulated times and is rounded down to it; any larger
/// excess is rounded up (see [`times_from_start`]).
pub const GAP_ROUNDING_NOISE_NS: f64 = 1e-3;

/// Relative slack when comparing a declared velocity with its limit (float rounding).
pub const VELOCITY_LIMIT_SLACK: f64 = 1e-9;

/// Tolerance of declared velocities: a declared `q̇_i` may differ from the one
/// [`point_velocities`] gives from the file's own positions and times by
/// `1e-9 · (1 + |q̇_i|)` rad/s (the writers use that very rule, so their files agree to the
/// last bit; the tolerance admits a reader that computes it in another order).
pub const DECLARED_VELOCITY_TOLERANCE: f64 = 1e-9;

/// The CSV header written by [`trajectory_csv`]; [`read_csv`] needs its first 15 columns.
pub const CSV_HEADER: &str = "time_s,q1,q2,q3,q4,q5,q6,q7,qd1,qd2,qd3,qd4,qd5,qd6,qd7,\
                              tcp_x,tcp_y,tcp_z,tool_angle_deg,rho,controller";

/// Columns [`read_csv`] reads: the time, the positions and the declared velocities.
const CSV_READ_COLUMNS: usize = 1 + 2 * DOF;

/// A file that cannot be read; names the field (or CSV cell) and what is wrong with it.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum JointTrajectoryError {
    /// The text is not JSON at all.
    #[error("not valid JSON: {0}")]
    Json(String),
    /// A field is missing, of the wrong type or holds a wrong value.
    #[error("field '{field}' {problem}")]
    Field {
        /// Path of the field, e.g. `points[3].positions`.
        field: String,
        /// What is wrong with it.
        problem: String,
    },
    /// The CSV header does not hold the expected columns.
    #[error("CSV header: {0}")]
    CsvHeader(String),
    /// A CSV cell (1-based line and column; the header is line 1) cannot be read.
    #[error("CSV line {line}, column {column} ('{name}'): {problem}")]
    CsvCell {
        /// 1-based line number (the header is line 1).
        line: usize,
        /// 1-based column number.
        column: usize,
        /// Column name from the header.
        name: String,
        /// What is wrong with the cell.
        problem: String,
    },
}

fn field_error(field: impl Into<String>, problem: impl Into<String>) -> JointTrajectoryError {
    JointTrajectoryError::Field {
        field: field.into(),
        problem: problem.into(),
    }
}

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
pub fn times_from_start(time_s: &[f64]) -> Result<Vec<TimeFromStart>, String> {
    let mut out: Vec<TimeFromStart> = Vec::with_capacity(time_s.len());
    for (k, t) in time_s.iter().enumerate() {
        let total = match out.last() {
            None if t.is_finite() && *t >= 0.0 && *t < 1e18 => Some((t * 1e9).round() as u64),
            None => None,
            Some(previous) => {
                let gap = t - time_s[k - 1];
                if gap.is_nan() || gap <= 0.0 {
                    return Err(format!(
                        "point {k}: time {t} s does not come after the previous point's {} s",
                        time_s[k - 1]
                    ));
                }
                let gap_ns = (gap * 1e9 - GAP_ROUNDING_NOISE_NS).ceil().max(1.0);
                (gap_ns < 1e18).then(|| previous.nanoseconds() + gap_ns as u64)
            }
        };
        let time = total
            .and_then(TimeFromStart::from_nanoseconds)
            .ok_or_else(|| {
                format!("point {k}: time {t} s cannot be a time_from_start (finite, ≥ 0, < 2^31 s)")
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
    ) -> Result<Self, JointTrajectoryError> {
        if joint_names.len() != DOF {
            return Err(field_error(
                "joint_names",
                format!("has {} entries, expected {DOF}", joint_names.len()),
            ));
        }
        let planned: Vec<f64> = trajectory.steps.iter().map(|s| s.time_s).collect();
        let times = times_from_start(&planned)
            .map_err(|problem| field_error("points[].time_from_start", problem))?;
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
    pub fn from_json(text: &str) -> Result<Self, JointTrajectoryError> {
        let value: Value =
            serde_json::from_str(text).map_err(|e| JointTrajectoryError::Json(e.to_string()))?;
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
) -> Result<&'a Value, JointTrajectoryError> {
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

fn string(value: &Value, path: &str) -> Result<String, JointTrajectoryError> {
    value
        .as_str()
        .map(str::to_string)
        .ok_or_else(|| field_error(path, format!("is {}, expected a string", describe(value))))
}

fn array<'a>(value: &'a Value, path: &str) -> Result<&'a Vec<Value>, JointTrajectoryError> {
    value
        .as_array()
        .ok_or_else(|| field_error(path, format!("is {}, expected an array", describe(value))))
}

/// Exactly [`DOF`] finite numbers.
fn joint_values(value: &Value, path: &str) -> Result<Vec<f64>, JointTrajectoryError> {
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

fn read_point(value: &Value, path: &str) -> Result<JointTrajectoryPoint, JointTrajectoryError> {
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

/// Joint velocities at timed points: interior points take the central difference
/// `(q_{k+1} − q_{k−1}) / (t_{k+1} − t_{k−1})` (a convex combination of the two segment
/// velocities, so within any bound both segments hold), the first and last points the velocity
/// of their one segment; a single point has zero velocity.
///
/// `time_s` and `q` have the same length and the times increase strictly.
pub fn point_velocities(time_s: &[f64], q: &[JointVector]) -> Vec<JointVector> {
    assert_eq!(time_s.len(), q.len(), "one time per configuration");
    let n = q.len();
    let slope = |a: usize, b: usize| (q[b] - q[a]) / (time_s[b] - time_s[a]);
    (0..n)
        .map(|k| match (k, n) {
            (_, 1) => JointVector::zeros(),
            (0, _) => slope(0, 1),
            (k, n) if k == n - 1 => slope(k - 1, k),
            (k, _) => slope(k - 1, k + 1),
        })
        .collect()
}

/// Per joint, `max_k |q̇_{k+1,i} − q̇_{k,i}| / (t_{k+1} − t_k)` over consecutive timed points
/// (zeros for a single point).
fn peak_accelerations(time_s: &[f64], velocities: &[JointVector]) -> Vec<f64> {
    let mut peak = vec![0.0_f64; DOF];
    for k in 1..velocities.len() {
        let gap = time_s[k] - time_s[k - 1];
        for (i, peak) in peak.iter_mut().enumerate() {
            *peak = peak.max((velocities[k][i] - velocities[k - 1][i]).abs() / gap);
        }
    }
    peak
}

/// The CSV table of a rollout's steps: [`CSV_HEADER`], then one row per step: time (s),
/// positions (rad), velocities by [`point_velocities`] (rad/s), TCP (m), tool angle (degrees),
/// `ρ`, and the acting controller (`classical`, `learned` or empty). Numbers are Rust's
/// shortest round-trip form, so [`read_csv`] gives back the very same values.
pub fn trajectory_csv(steps: &[StepRecord]) -> String {
    let samples = JointSamples::from_steps(steps);
    let velocities = point_velocities(&samples.time_s, &samples.q);
    let mut out = String::from(CSV_HEADER);
    out.push('\n');
    for (step, qd) in steps.iter().zip(&velocities) {
        let mut row = vec![step.time_s];
        row.extend(step.q.iter());
        row.extend(qd.iter());
        row.extend(step.tcp.iter());
        row.extend([step.tool_angle_deg, step.rho]);
        for value in row {
            out.push_str(&format!("{value:?},"));
        }
        out.push_str(step.controller.map_or("", |c| c.name()));
        out.push('\n');
    }
    out
}

/// Reads a CSV table: the header must start with `time_s,q1..q7,qd1..qd7` (the columns after
/// those are not read); every row must have as many cells as the header, and the cells read
/// must be finite numbers. The error names the line, the column and what is wrong.
pub fn read_csv(text: &str) -> Result<JointSamples, JointTrajectoryError> {
    let mut lines = text.lines();
    let header: Vec<&str> = lines
        .next()
        .ok_or_else(|| JointTrajectoryError::CsvHeader("the file is empty".into()))?
        .split(',')
        .map(str::trim)
        .collect();
    let expected: Vec<&str> = CSV_HEADER.split(',').take(CSV_READ_COLUMNS).collect();
    for (column, want) in expected.iter().enumerate() {
        match header.get(column) {
            Some(name) if name == want => {}
            Some(name) => {
                return Err(JointTrajectoryError::CsvHeader(format!(
                    "column {} is '{name}', expected '{want}' (the header must start with \
                     time_s,q1..q7,qd1..qd7)",
                    column + 1
                )));
            }
            None => {
                return Err(JointTrajectoryError::CsvHeader(format!(
                    "has {} columns; column {} must be '{want}' (the header must start with \
                     time_s,q1..q7,qd1..qd7)",
                    header.len(),
                    column + 1
                )));
            }
        }
    }
    let (mut time_s, mut q, mut qd) = (Vec::new(), Vec::new(), Vec::new());
    for (index, row) in lines.enumerate() {
        let line = index + 2;
        let cells: Vec<&str> = row.split(',').collect();
        if cells.len() != header.len() {
            return Err(JointTrajectoryError::CsvCell {
                line,
                column: cells.len().min(header.len()),
                name: header[cells.len().min(header.len()) - 1].to_string(),
                problem: format!(
                    "the row has {} cells, the header {} columns",
                    cells.len(),
                    header.len()
                ),
            });
        }
        let mut values = [0.0; CSV_READ_COLUMNS];
        for (column, value) in values.iter_mut().enumerate() {
            let cell = cells[column].trim();
            *value = match cell.parse::<f64>() {
                Ok(x) if x.is_finite() => x,
                _ => {
                    return Err(JointTrajectoryError::CsvCell {
                        line,
                        column: column + 1,
                        name: header[column].to_string(),
                        problem: format!("'{cell}' is not a finite number"),
                    });
                }
            };
        }
        time_s.push(values[0]);
        q.push(JointVector::from_column_slice(&values[1..=DOF]));
        qd.push(JointVector::from_column_slice(&values[DOF + 1..]));
    }
    let samples = JointSamples {
        time_s,
        q,
        qd: Some(qd),
    };
    Ok(samples)
}

/// Timed joint positions read from a trajectory file, with the velocities it declares.
#[derive(Clone, Debug, PartialEq)]
pub struct JointSamples {
    /// Time of each point since the start (s).
    pub time_s: Vec<f64>,
    /// Joint positions of each point (rad).
    pub q: Vec<JointVector>,
    /// Velocities the file declares at each point (rad/s), if it declares any.
    pub qd: Option<Vec<JointVector>>,
}

impl JointSamples {
    /// Times and positions of recorded steps (exact times, no declared velocities).
    pub fn from_steps(steps: &[StepRecord]) -> Self {
        Self {
            time_s: steps.iter().map(|s| s.time_s).collect(),
            q: steps.iter().map(|s| s.q).collect(),
            qd: None,
        }
    }

    /// Number of points.
    pub fn len(&self) -> usize {
        self.q.len()
    }

    /// Whether there is no point at all.
    pub fn is_empty(&self) -> bool {
        self.q.is_empty()
    }

    /// The points as a [`Trajectory`] of `task` for [`ReferenceModel::check`]: TCP and tool
    /// angle from the checker's own forward kinematics ([`ReferenceModel::tcp_pose`]), `ρ` from
    /// its joint limits, no acting controller, the path length `(p_last − p0)·d` from the last
    /// point's TCP, and [`Termination::StepCap`].
    ///
    /// A file of points says nothing about why the motion ended, so the check of such a
    /// trajectory verifies every point but no reason for the end: `StepCap` makes the checker
    /// blame no constraint on a step that is not in the file. Since the TCP and tool angles are
    /// recomputed here, the check compares them with themselves; what it verifies are the
    /// constraints at each point.
    pub fn to_trajectory(&self, model: &ReferenceModel, task: &Task) -> Trajectory {
        let limits = model.limits();
        let steps: Vec<StepRecord> = self
            .time_s
            .iter()
            .zip(&self.q)
            .map(|(time_s, q)| {
                let (tcp, axis) = model.tcp_pose(q.as_slice());
                let rho = limits
                    .iter()
                    .zip(q.iter())
                    .map(|((lo, hi), v)| ((2.0 * v - lo - hi) / (hi - lo)).abs())
                    .fold(0.0, f64::max);
                StepRecord {
                    time_s: *time_s,
                    q: *q,
                    tcp,
                    tool_angle_deg: tool_angle_deg(&axis, &task.n),
                    rho,
                    controller: None,
                }
            })
            .collect();
        let path_length_m = steps
            .last()
            .map_or(0.0, |last| (last.tcp - task.p0).dot(&task.d));
        Trajectory {
            steps,
            termination: Termination::StepCap,
            path_length_m,
        }
    }
}

/// What a verified trajectory does, for the report of a check.
#[derive(Clone, Debug, PartialEq)]
pub struct ReplayReport {
    /// Number of points.
    pub points: usize,
    /// Time of the last point (s).
    pub duration_s: f64,
    /// `(p_last − p0)·d` (m), from the checker's forward kinematics.
    pub path_length_m: f64,
    /// Per joint, the fastest segment speed `|Δq_i| / Δt` as a fraction of the robot file's
    /// velocity limit of that joint (0 for a single point).
    pub peak_speed_fraction: Vec<f64>,
    /// Per joint, the largest change of point velocity between consecutive points over their
    /// time gap (rad/s²), from the declared velocities or else [`point_velocities`]: what a
    /// controller interpolating the points meets between them (0 for a single point). The
    /// planner does not bound it.
    pub peak_acceleration_rad_s2: Vec<f64>,
    /// The fastest joint at the first and at the last point, as a fraction of its velocity
    /// limit: a motion that starts or ends moving needs the arm brought up to (down from) that
    /// speed outside the file.
    pub boundary_speed_fraction: [f64; 2],
    /// Largest lateral distance of the TCP from the task line (m).
    pub max_line_deviation_m: f64,
    /// Largest angle between the tool axis and `n` (degrees).
    pub max_tool_angle_deg: f64,
    /// Smallest clearance between checked capsule pairs (m), with the pair's links.
    pub min_clearance: (f64, String, String),
    /// Largest difference between a declared velocity and the velocity rule (rad/s); `None`
    /// when the file declares no velocities.
    pub max_declared_velocity_error: Option<f64>,
}

/// Why a trajectory file does not hold up: the joint names, or a point and the constraint it
/// breaks.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum ReplayError {
    /// The file's joint names are not the robot's, in the robot's order.
    #[error("joint_names {file:?} are not the robot's joints {robot:?} (same names, same order)")]
    JointNames {
        /// Names in the file.
        file: Vec<String>,
        /// The robot's revolute joints, base to tip.
        robot: Vec<String>,
    },
    /// A point breaks a constraint or disagrees with the file's own records.
    #[error("point {point}: {problem}")]
    Point {
        /// Index of the point (0 = the first).
        point: usize,
        /// The constraint and by how much.
        problem: String,
    },
}

/// `value <= bound`; false when either is NaN, so that every check fails closed.
fn within(value: f64, bound: f64) -> bool {
    value <= bound
}

/// Checks that a file's joint names are the robot's, in the same order.
pub fn check_joint_names(file: &[String], robot: &[String]) -> Result<(), ReplayError> {
    if file == robot {
        Ok(())
    } else {
        Err(ReplayError::JointNames {
            file: file.to_vec(),
            robot: robot.to_vec(),
        })
    }
}

/// Verifies timed points against `task` and `constraints` with the independent checker:
///
/// 1. times finite and strictly increasing;
/// 2. [`ReferenceModel::check`] of `recorded` (a file's own [`Trajectory`] holding these very
///    points) or else of [`JointSamples::to_trajectory`]: joint position limits, line tolerance,
///    tool cone, self-collision, joint speeds from positions and times within
///    `velocity_limit_fraction · v_max` (when the constraints enforce it), and the records a
///    recorded trajectory carries (TCP, tool angle, path length, why it ended);
/// 3. declared velocities, if any: `|q̇_i| ≤ fraction · v_max,i · (1 + VELOCITY_LIMIT_SLACK)`
///    (when enforced) and within [`DECLARED_VELOCITY_TOLERANCE`] of [`point_velocities`] of the
///    file's own positions and times.
///
/// # Panics
///
/// If `recorded` does not hold exactly the samples' times and positions.
pub fn check_replay(
    model: &ReferenceModel,
    task: &Task,
    constraints: &ConstraintConfig,
    samples: &JointSamples,
    recorded: Option<&Trajectory>,
) -> Result<ReplayReport, ReplayError> {
    let fail = |point: usize, problem: String| Err(ReplayError::Point { point, problem });
    if samples.is_empty() {
        return fail(0, "the file holds no point".into());
    }
    for (k, t) in samples.time_s.iter().enumerate() {
        if !t.is_finite() {
            return fail(k, format!("time {t} s is not finite"));
        }
        if k > 0 && *t <= samples.time_s[k - 1] {
            return fail(
                k,
                format!(
                    "timestamps must increase strictly: {t} s after {} s",
                    samples.time_s[k - 1]
                ),
            );
        }
    }
    let rebuilt;
    let trajectory = match recorded {
        Some(trajectory) => {
            assert!(
                trajectory.steps.len() == samples.len()
                    && trajectory
                        .steps
                        .iter()
                        .zip(samples.time_s.iter().zip(&samples.q))
                        .all(|(step, (t, q))| step.time_s == *t && step.q == *q),
                "the recorded trajectory holds the samples' points"
            );
            trajectory
        }
        None => {
            rebuilt = samples.to_trajectory(model, task);
            &rebuilt
        }
    };
    model
        .check(task, trajectory, constraints)
        .map_err(|failure| ReplayError::Point {
            point: failure.step,
            problem: failure.problem,
        })?;

    let v_max = model.velocity_limits();
    let fraction = constraints.velocity_limit_fraction.map(|f| f.get());
    let mut max_declared_velocity_error = None;
    if let Some(declared) = &samples.qd {
        let rule = point_velocities(&samples.time_s, &samples.q);
        let mut worst = 0.0_f64;
        for (k, (qd, expected)) in declared.iter().zip(&rule).enumerate() {
            for i in 0..DOF {
                if let Some(f) = fraction
                    && !within(qd[i].abs(), f * v_max[i] * (1.0 + VELOCITY_LIMIT_SLACK))
                {
                    return fail(
                        k,
                        format!(
                            "declared velocity of joint {} is {} rad/s, {:.4} × its limit {} \
                             rad/s (allowed: {f} ×)",
                            i + 1,
                            qd[i],
                            qd[i].abs() / v_max[i],
                            v_max[i],
                        ),
                    );
                }
                let error = (qd[i] - expected[i]).abs();
                if !within(
                    error,
                    DECLARED_VELOCITY_TOLERANCE * (1.0 + expected[i].abs()),
                ) {
                    return fail(
                        k,
                        format!(
                            "declared velocity of joint {} is {} rad/s but the positions and \
                             times give {} rad/s (tolerance {DECLARED_VELOCITY_TOLERANCE:e} × \
                             (1 + |q̇|))",
                            i + 1,
                            qd[i],
                            expected[i]
                        ),
                    );
                }
                worst = worst.max(error);
            }
        }
        max_declared_velocity_error = Some(worst);
    }

    let mut peak_speed_fraction = vec![0.0_f64; DOF];
    for k in 1..samples.len() {
        let gap = samples.time_s[k] - samples.time_s[k - 1];
        for (i, peak) in peak_speed_fraction.iter_mut().enumerate() {
            let speed = (samples.q[k][i] - samples.q[k - 1][i]).abs() / gap;
            *peak = peak.max(speed / v_max[i]);
        }
    }
    let velocities = match &samples.qd {
        Some(declared) => declared.clone(),
        None => point_velocities(&samples.time_s, &samples.q),
    };
    let peak_acceleration_rad_s2 = peak_accelerations(&samples.time_s, &velocities);
    let fastest_joint =
        |qd: &JointVector| (0..DOF).map(|i| qd[i].abs() / v_max[i]).fold(0.0, f64::max);
    let boundary_speed_fraction = [
        fastest_joint(&velocities[0]),
        fastest_joint(&velocities[velocities.len() - 1]),
    ];
    let mut max_line_deviation_m = 0.0_f64;
    let mut max_tool_angle_deg = 0.0_f64;
    let mut min_clearance = (f64::INFINITY, String::new(), String::new());
    for q in &samples.q {
        let (tcp, axis) = model.tcp_pose(q.as_slice());
        let offset = tcp - task.p0;
        max_line_deviation_m =
            max_line_deviation_m.max((offset - task.d * offset.dot(&task.d)).norm());
        max_tool_angle_deg = max_tool_angle_deg.max(tool_angle_deg(&axis, &task.n));
        let clearance = model.min_clearance(q.as_slice());
        if clearance.0 < min_clearance.0 {
            min_clearance = clearance;
        }
    }
    let last = samples.len() - 1;
    let (tcp, _) = model.tcp_pose(samples.q[last].as_slice());
    Ok(ReplayReport {
        points: samples.len(),
        duration_s: samples.time_s[last],
        path_length_m: (tcp - task.p0).dot(&task.d),
        peak_speed_fraction,
        peak_acceleration_rad_s2,
        boundary_speed_fraction,
        max_line_deviation_m,
        max_tool_angle_deg,
        min_clearance,
        max_declared_velocity_error,
    })
}

#[cfg(test)]
mod tests {
    use emg_kinematics::{Robot, Vec3, default_robot_path};

    use super::*;
    use crate::classical::ClassicalController;
    use crate::config::{RolloutConfig, VelocityLimitFraction};
    use crate::rollout::rollout;

    /// Velocity-limit fraction of [`planned`]: low enough to slow most steps.
    const FRACTION: f64 = 0.03;

    /// A short classical rollout of the demo-style task with a small fraction of the velocity
    /// limits, so that most steps are slowed and the times are not uniform.
    fn planned() -> (Robot, Task, RolloutConfig, Trajectory) {
        let robot = Robot::from_urdf_file(default_robot_path(), "link0", "pen_tip").unwrap();
        let seed = robot.mid_range();
        let kin = robot.forward(&seed);
        let n = kin.tool_axis();
        let d = (Vec3::y() - n * n.y).normalize();
        let task = Task::new(&robot, kin.tcp(), d, n, Some(seed)).unwrap();
        let mut config = RolloutConfig {
            max_steps: 30,
            ..RolloutConfig::default()
        };
        config.constraints.velocity_limit_fraction =
            Some(VelocityLimitFraction::new(FRACTION).unwrap());
        let trajectory = rollout(
            &robot,
            &task,
            &seed,
            &mut ClassicalController::default(),
            &config,
        );
        (robot, task, config, trajectory)
    }

    fn checker() -> ReferenceModel {
        ReferenceModel::from_urdf_file(&default_robot_path(), "link0", "pen_tip").unwrap()
    }

    fn export() -> (JointTrajectory, Trajectory) {
        let (robot, task, config, trajectory) = planned();
        let file = JointTrajectory::new(
            "fr3_pen.urdf",
            robot.joint_names(),
            &task,
            &config.constraints,
            &trajectory,
        )
        .unwrap();
        (file, trajectory)
    }

    #[test]
    fn json_round_trip_keeps_every_position_bit_for_bit() {
        let (file, trajectory) = export();
        let gaps: Vec<f64> = trajectory
            .steps
            .windows(2)
            .map(|w| w[1].time_s - w[0].time_s)
            .collect();
        assert!(
            gaps.iter().any(|g| (g - 0.05).abs() > 1e-6),
            "the slowed steps make the times non-uniform: {gaps:?}"
        );
        let text = file.to_json();
        assert!(!text.contains('\n'));
        let back = JointTrajectory::from_json(&text).unwrap();
        assert_eq!(back, file);
        assert_eq!(back.points.len(), trajectory.steps.len());
        for (point, step) in back.points.iter().zip(&trajectory.steps) {
            let bits = |v: &[f64]| v.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
            assert_eq!(bits(&point.positions), bits(step.q.as_slice()));
            // Never shorter than planned, at most 1 ns per point later.
            let drift = point.time_from_start.seconds() - step.time_s;
            assert!(drift > -1e-12 && drift < 1e-9 * trajectory.steps.len() as f64);
        }
        let report = check_replay(
            &checker(),
            &back.task,
            &back.constraints,
            &back.samples(),
            None,
        )
        .unwrap();
        assert_eq!(report.points, trajectory.steps.len());
        assert_eq!(report.max_declared_velocity_error, Some(0.0));
        assert!((report.path_length_m - trajectory.path_length_m).abs() < 1e-12);
        let peak = report
            .peak_speed_fraction
            .iter()
            .copied()
            .fold(0.0, f64::max);
        assert!(
            peak > 0.99 * FRACTION && peak <= FRACTION * (1.0 + 1e-9),
            "{peak}"
        );
        // The first and last points move at their segment's speed, within the peak.
        let [first, last] = report.boundary_speed_fraction;
        assert!(first > 0.0 && first <= peak && last > 0.0 && last <= peak);
        assert!(report.peak_acceleration_rad_s2.iter().all(|a| *a > 0.0));
    }

    #[test]
    fn peak_accelerations_compare_consecutive_point_velocities() {
        let velocity = |v: f64| JointVector::from_element(v);
        // Joint velocities 1, 2/3, 1/2 rad/s at 0, 1 and 3 s: changes of 1/3 over 1 s and
        // 1/6 over 2 s.
        let peaks = peak_accelerations(
            &[0.0, 1.0, 3.0],
            &[velocity(1.0), velocity(2.0 / 3.0), velocity(0.5)],
        );
        for peak in peaks {
            assert!((peak - 1.0 / 3.0).abs() < 1e-15, "{peak}");
        }
        assert_eq!(peak_accelerations(&[0.0], &[velocity(1.0)]), vec![0.0; DOF]);
    }

    #[test]
    fn csv_round_trip_keeps_times_and_positions_bit_for_bit() {
        let (_, _, _, trajectory) = planned();
        let text = trajectory_csv(&trajectory.steps);
        assert!(text.starts_with(CSV_HEADER));
        let samples = read_csv(&text).unwrap();
        assert_eq!(samples.len(), trajectory.steps.len());
        for (k, step) in trajectory.steps.iter().enumerate() {
            assert_eq!(samples.time_s[k].to_bits(), step.time_s.to_bits());
            for i in 0..DOF {
                assert_eq!(samples.q[k][i].to_bits(), step.q[i].to_bits());
            }
        }
        let rule = point_velocities(&samples.time_s, &samples.q);
        assert_eq!(samples.qd.as_ref().unwrap(), &rule);
        let row = text.lines().nth(1).unwrap();
        assert_eq!(row.split(',').count(), CSV_HEADER.split(',').count());
        assert!(row.ends_with(",classical"));
    }

    #[test]
    fn velocity_rule_on_non_uniform_times() {
        let time_s = [0.0, 0.1, 0.3, 0.35];
        let joint = [0.0, 0.2, 0.3, 0.5];
        let q: Vec<JointVector> = joint
            .iter()
            .map(|&v| JointVector::from_element(v))
            .collect();
        let qd = point_velocities(&time_s, &q);
        let expected = [
            (0.2 - 0.0) / 0.1,
            (0.3 - 0.0) / 0.3,
            (0.5 - 0.2) / (0.35 - 0.1),
            (0.5 - 0.3) / (0.35 - 0.3),
        ];
        for (v, e) in qd.iter().zip(expected) {
            assert!(v.iter().all(|x| *x == e), "{v} vs {e}");
        }
        // Interior points lie between their two segment velocities (2.0 / 0.5 and 0.5 / 4.0).
        assert!(qd[1][0] > 0.5 && qd[1][0] < 2.0);
        assert!(qd[2][0] > 0.5 && qd[2][0] < 4.0);
        assert_eq!(
            point_velocities(&[0.0], &q[..1]),
            vec![JointVector::zeros()]
        );
    }

    #[test]
    fn times_are_rounded_up_per_gap_to_whole_nanoseconds() {
        // Accumulated 0.05 s steps land exactly on the grid despite float noise.
        let mut t = vec![0.0];
        for _ in 0..10 {
            t.push(t.last().unwrap() + 0.05);
        }
        t.push(t.last().unwrap() + 1.0 / 30.0);
        let times = times_from_start(&t).unwrap();
        assert_eq!(
            times[10],
            TimeFromStart {
                sec: 0,
                nanosec: 500_000_000
            }
        );
        assert_eq!(
            times[11],
            TimeFromStart {
                sec: 0,
                nanosec: 533_333_334
            }
        );
        for k in 1..t.len() {
            assert!(times[k].seconds() - times[k - 1].seconds() >= (t[k] - t[k - 1]) - 1e-12);
        }
        let error = times_from_start(&[0.0, 0.1, 0.1]).unwrap_err();
        assert!(
            error.contains("point 2") && error.contains("does not come after"),
            "{error}"
        );
        assert!(times_from_start(&[-0.1]).unwrap_err().contains("point 0"));
    }

    #[test]
    fn malformed_json_names_the_field() {
        let (file, _) = export();
        let good: Value = serde_json::from_str(&file.to_json()).unwrap();
        let error = |edit: &dyn Fn(&mut Value)| {
            let mut doc = good.clone();
            edit(&mut doc);
            JointTrajectory::from_json(&doc.to_string())
                .unwrap_err()
                .to_string()
        };
        let e = error(&|d| d["format"] = "emg-trajectory/1".into());
        assert!(
            e.contains("'format'") && e.contains("emg-joint-trajectory/1"),
            "{e}"
        );
        let e = error(&|d| {
            d["joint_names"].as_array_mut().unwrap().pop();
        });
        assert!(e.contains("'joint_names' has 6 entries, expected 7"), "{e}");
        let e = error(&|d| {
            d["points"][1]["positions"].as_array_mut().unwrap().pop();
        });
        assert!(e.contains("'points[1].positions' has 6 values"), "{e}");
        let e = error(&|d| d["points"][0]["velocities"][2] = "fast".into());
        assert!(
            e.contains("'points[0].velocities[2]'") && e.contains("\"fast\""),
            "{e}"
        );
        let e = error(&|d| d["points"][3]["time_from_start"]["nanosec"] = 1_000_000_000.into());
        assert!(e.contains("'points[3].time_from_start.nanosec'"), "{e}");
        let e = error(&|d| {
            d.as_object_mut().unwrap().remove("constraints");
        });
        assert!(e.contains("'constraints' is missing"), "{e}");
        let e = error(&|d| d["constraints"]["velocity_limit_fraction"] = 2.0.into());
        assert!(
            e.contains("'constraints'") && e.contains("velocity_limit_fraction"),
            "{e}"
        );
        assert!(matches!(
            JointTrajectory::from_json("{\"format\": "),
            Err(JointTrajectoryError::Json(_))
        ));
    }

    #[test]
    fn malformed_csv_names_line_and_column() {
        let (_, _, _, trajectory) = planned();
        let text = trajectory_csv(&trajectory.steps);
        let bad = text.replacen("0.0,", "zero,", 1);
        let e = read_csv(&bad).unwrap_err().to_string();
        assert_eq!(
            e,
            "CSV line 2, column 1 ('time_s'): 'zero' is not a finite number"
        );
        let mut lines: Vec<String> = text.lines().map(str::to_string).collect();
        let mut cells: Vec<String> = lines[3].split(',').map(str::to_string).collect();
        cells[9] = "NaN".into();
        lines[3] = cells.join(",");
        let e = read_csv(&lines.join("\n")).unwrap_err().to_string();
        assert!(e.starts_with("CSV line 4, column 10 ('qd2')"), "{e}");
        let old_header = text.replacen("qd1,qd2,qd3,qd4,qd5,qd6,qd7,", "", 1);
        let e = read_csv(&old_header).unwrap_err().to_string();
        assert!(e.contains("column 9 is 'tcp_x', expected 'qd1'"), "{e}");
    }

    #[test]
    fn check_replay_blames_the_point_and_the_constraint() {
        let (file, _) = export();
        let model = checker();
        let run = |samples: &JointSamples| {
            check_replay(&model, &file.task, &file.constraints, samples, None)
                .unwrap_err()
                .to_string()
        };
        let mut samples = file.samples();
        samples.qd.as_mut().unwrap()[5][3] += 0.01;
        let e = run(&samples);
        assert!(
            e.starts_with("point 5: declared velocity of joint 4"),
            "{e}"
        );

        let mut samples = file.samples();
        samples.time_s[7] = samples.time_s[6] + 0.5 * (samples.time_s[7] - samples.time_s[6]);
        let e = run(&samples);
        assert!(
            e.starts_with("point 7: joint") && e.contains("rad/s, above"),
            "{e}"
        );

        let mut samples = file.samples();
        samples.time_s[4] = samples.time_s[3];
        assert!(run(&samples).starts_with("point 4: timestamps must increase"));

        let mut names = file.joint_names.clone();
        names.swap(0, 1);
        let e = check_joint_names(&names, &file.joint_names)
            .unwrap_err()
            .to_string();
        assert!(e.contains("same order"), "{e}");
        assert!(check_joint_names(&file.joint_names, &file.joint_names).is_ok());
    }
}
