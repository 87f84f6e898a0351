//! The `emg-trajectory/1` JSON layout: one planned task as recorded (task, settings, every step,
//! why it ended, the path length), written by the planner and read back by `emg check`. The
//! layout is documented in `docs/trajectory-format.md`.

use emg_control::{
    ClassicalGains, ConstraintConfig, RolloutConfig, StepRecord, Task, Termination, Trajectory,
};
use serde::Serialize;
use serde_json::Value;

use crate::error::{FormatError, field_error};
use crate::joint_trajectory::{joint_count, joint_values, padded};

/// Value of the `format` field of every `emg-trajectory/1` file.
pub const TRAJECTORY_FORMAT: &str = "emg-trajectory/1";

/// One planned task as written to `<stem>.json`.
#[derive(Debug, Serialize)]
pub struct TrajectoryFile<'a> {
    /// Always [`TRAJECTORY_FORMAT`].
    pub format: &'static str,
    /// Robot: a shipped robot's file or the path as given to the planner.
    pub robot: String,
    /// Names of the arm's `n` joints (6 or 7), base to tip (the order of every `q`; every joint
    /// vector of the file holds `n` entries).
    pub joint_names: &'a [String],
    /// The validated task.
    pub task: &'a Task,
    /// Where the seed came from (`dp`, `generating`, `home`, `given`, ...).
    pub seed_source: &'a str,
    /// Planner that was requested (`controller` or `search`).
    pub planner: &'a str,
    /// Controller that was requested.
    pub controller: &'a str,
    /// Rollout settings used.
    pub config: &'a RolloutConfig,
    /// Controller gains used.
    pub gains: &'a ClassicalGains,
    /// Accepted steps, the seed first.
    pub steps: &'a [StepRecord],
    /// Why the rollout ended.
    pub termination: &'a Termination,
    /// `(p_T − p0)·d` at the last accepted step (m).
    pub path_length_m: f64,
    /// The task's reachability bound (m), when it was computed.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub reachable_m: Option<f64>,
    /// Why the plan ends well below the bound, when it does (below 0.9 × `reachable_m`).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub below_bound: Option<String>,
}

impl TrajectoryFile<'_> {
    /// The file's text: compact JSON on one line, numbers in their shortest round-trip form,
    /// then a newline. Joint vectors hold the arm's `n` joints (the in-memory vectors' entries
    /// past `n` are the absent joint's zeros).
    pub fn to_json(&self) -> String {
        let mut doc = serde_json::to_value(self).expect("a trajectory file serialises");
        let joints = self.joint_names.len();
        for (_, vector) in joint_vector_fields(&mut doc) {
            if let Value::Array(values) = vector {
                values.truncate(joints);
            }
        }
        let mut json = doc.to_string();
        json.push('\n');
        json
    }
}

/// The parts of an `emg-trajectory/1` file that can be verified: the robot it names, the joint
/// order, the task, the constraints and the trajectory as recorded.
#[derive(Clone, Debug, PartialEq)]
pub struct RolloutRecord {
    /// The robot the file names.
    pub robot: String,
    /// Joint names, base to tip.
    pub joint_names: Vec<String>,
    /// The task as written (validate it against the robot before use).
    pub task: Task,
    /// The constraints of the rollout settings.
    pub constraints: ConstraintConfig,
    /// The trajectory as recorded.
    pub trajectory: Trajectory,
}

impl RolloutRecord {
    /// Reads an `emg-trajectory/1` document (already parsed); the error names the field.
    pub fn from_value(doc: &Value) -> Result<Self, FormatError> {
        let field = |name: &str| doc.get(name).ok_or_else(|| field_error(name, "is missing"));
        let format = field("format")?;
        if format.as_str() != Some(TRAJECTORY_FORMAT) {
            return Err(field_error(
                "format",
                format!("is {format}, expected {TRAJECTORY_FORMAT:?}"),
            ));
        }
        let robot = field("robot")?
            .as_str()
            .ok_or_else(|| field_error("robot", "is not a string"))?
            .to_string();
        let joint_names: Vec<String> = serde_json::from_value(field("joint_names")?.clone())
            .map_err(|e| field_error("joint_names", format!("is not an array of strings: {e}")))?;
        field("task")?;
        let config: RolloutConfig = serde_json::from_value(field("config")?.clone())
            .map_err(|e| field_error("config", format!("is not a rollout config: {e}")))?;
        for name in ["steps", "termination", "path_length_m"] {
            field(name)?;
        }
        let joints = joint_count(joint_names.len())?;
        let mut doc = doc.clone();
        for (name, vector) in joint_vector_fields(&mut doc) {
            pad_joint_vector(&name, vector, joints)?;
        }
        let task = serde_json::from_value(doc["task"].clone())
            .map_err(|e| field_error("task", format!("is not a task: {e}")))?;
        let trajectory = serde_json::from_value(doc).map_err(|e| {
            field_error(
                "steps/termination/path_length_m",
                format!("do not form a trajectory: {e}"),
            )
        })?;
        Ok(Self {
            robot,
            joint_names,
            task,
            constraints: config.constraints,
            trajectory,
        })
    }
}

/// The joint vectors of an `emg-trajectory/1` document, each with the field path an error
/// names: every step's `q`, the task's `q0_seed` and the termination's `rejected_q`, where present.
fn joint_vector_fields(doc: &mut Value) -> impl Iterator<Item = (String, &mut Value)> {
    let Value::Object(members) = doc else {
        return Vec::new().into_iter();
    };
    let mut vectors = Vec::new();
    for (name, member) in members.iter_mut() {
        match (name.as_str(), member) {
            ("steps", Value::Array(steps)) => {
                for (i, step) in steps.iter_mut().enumerate() {
                    if let Some(q) = step.get_mut("q") {
                        vectors.push((format!("steps[{i}].q"), q));
                    }
                }
            }
            ("task", task) => {
                if let Some(seed) = task.get_mut("q0_seed").filter(|seed| !seed.is_null()) {
                    vectors.push(("task.q0_seed".to_string(), seed));
                }
            }
            ("termination", termination) => {
                if let Some(rejected) = termination.get_mut("rejected_q") {
                    vectors.push(("termination.rejected_q".to_string(), rejected));
                }
            }
            _ => {}
        }
    }
    vectors.into_iter()
}

/// Pads the joint vector `field` of `joints` values to the in-memory `JointVector` with the
/// absent joint's zeros; refuses a vector of another length.
fn pad_joint_vector(field: &str, vector: &mut Value, joints: usize) -> Result<(), FormatError> {
    let values = joint_values(vector, joints, field)?;
    *vector = Value::from(padded(&values).as_slice().to_vec());
    Ok(())
}
