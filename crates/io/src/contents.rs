//! Any trajectory file, told apart by its content: JSON starts with `{` and its `format` field
//! names the layout; anything else is read as the CSV.

use std::path::{Path, PathBuf};

use emg_control::{ConstraintConfig, Task};
use emg_verify::{
    JointDynamics, JointSamples, Recording, ReferenceModel, ReplayError, ReplayReport,
    check_joint_names, check_replay,
};
use serde_json::Value;

use crate::csv::{read_csv, samples_from_steps};
use crate::error::{FormatError, field_error};
use crate::joint_trajectory::{JOINT_TRAJECTORY_FORMAT, JointTrajectory};
use crate::rollout_file::{RolloutRecord, TRAJECTORY_FORMAT};

/// What a trajectory file holds, by layout.
#[derive(Clone, Debug, PartialEq)]
pub enum TrajectoryContents {
    /// `emg-trajectory/1`: the rollout as recorded.
    Rollout(RolloutRecord),
    /// `emg-joint-trajectory/2`.
    Joint(JointTrajectory),
    /// The CSV: times, positions and declared velocities only.
    Csv(JointSamples),
}

/// Why a trajectory file cannot be read.
#[derive(Debug, thiserror::Error)]
pub enum ReadError {
    /// The file cannot be read.
    #[error("cannot read {path}")]
    Io {
        /// The file.
        path: String,
        /// The cause.
        #[source]
        source: std::io::Error,
    },
    /// The file is not in any trajectory layout.
    #[error("{path} is not a readable trajectory file")]
    Format {
        /// The file.
        path: String,
        /// What is wrong, naming the field or cell.
        #[source]
        source: FormatError,
    },
}

/// Task, constraints and robot a JSON file carries.
#[derive(Clone, Debug, PartialEq)]
pub struct Carried {
    /// The robot the file names.
    pub robot: String,
    /// The task.
    pub task: Task,
    /// The constraints.
    pub constraints: ConstraintConfig,
}

/// The file carrying the task of the CSV at `csv`, which carries none: the `emg-trajectory/1`
/// JSON of the same stem beside it (`emg plan` and Python's `Plan.save` write them together),
/// when it exists.
pub fn task_file_beside(csv: &Path) -> Option<PathBuf> {
    Some(csv.with_extension("json")).filter(|path| path.is_file())
}

impl TrajectoryContents {
    /// Reads `path`, whatever its layout.
    pub fn read(path: &Path) -> Result<Self, ReadError> {
        let text = std::fs::read_to_string(path).map_err(|source| ReadError::Io {
            path: path.display().to_string(),
            source,
        })?;
        Self::parse(&text).map_err(|source| ReadError::Format {
            path: path.display().to_string(),
            source,
        })
    }

    /// Reads a file's text, whatever its layout, told apart by its content (the file name
    /// does not matter): JSON opens with `{` (or `[`, which no layout uses, so its parse error
    /// is reported), the CSV with its `time_s` header.
    pub fn parse(text: &str) -> Result<Self, FormatError> {
        let start = text.trim_start();
        if start.starts_with('{') || start.starts_with('[') {
            Self::parse_json(text)
        } else if start.starts_with("time_s") {
            read_csv(text).map(Self::Csv)
        } else {
            let opening: String = start.chars().take(20).collect();
            Err(FormatError::Unrecognised(format!(
                "it opens with {opening:?}: JSON opens with '{{', the CSV with its header \
                 'time_s,q1,...'"
            )))
        }
    }

    /// Reads a JSON trajectory file of either layout, by its `format` field.
    pub fn parse_json(text: &str) -> Result<Self, FormatError> {
        let doc: Value =
            serde_json::from_str(text).map_err(|e| FormatError::Json(e.to_string()))?;
        let format = doc
            .get("format")
            .ok_or_else(|| field_error("format", "is missing"))?;
        match format.as_str() {
            Some(TRAJECTORY_FORMAT) => RolloutRecord::from_value(&doc).map(Self::Rollout),
            Some(JOINT_TRAJECTORY_FORMAT) => JointTrajectory::from_json(text).map(Self::Joint),
            _ => Err(field_error(
                "format",
                format!(
                    "is {format}, expected {TRAJECTORY_FORMAT:?} or {JOINT_TRAJECTORY_FORMAT:?}"
                ),
            )),
        }
    }

    /// The layout's name.
    pub fn layout(&self) -> &'static str {
        match self {
            Self::Rollout(_) => TRAJECTORY_FORMAT,
            Self::Joint(_) => JOINT_TRAJECTORY_FORMAT,
            Self::Csv(_) => "CSV",
        }
    }

    /// Task, constraints and robot the file carries (none for a CSV).
    pub fn carried(&self) -> Option<Carried> {
        match self {
            Self::Rollout(file) => Some(Carried {
                robot: file.robot.clone(),
                task: file.task.clone(),
                constraints: file.constraints.clone(),
            }),
            Self::Joint(file) => Some(Carried {
                robot: file.robot.clone(),
                task: file.task.clone(),
                constraints: file.constraints.clone(),
            }),
            Self::Csv(_) => None,
        }
    }

    /// The joint names the file declares (none for a CSV).
    pub fn joint_names(&self) -> Option<&[String]> {
        match self {
            Self::Rollout(file) => Some(&file.joint_names),
            Self::Joint(file) => Some(&file.joint_names),
            Self::Csv(_) => None,
        }
    }

    /// The timed points of the file (with the velocities it declares, if any).
    pub fn samples(&self) -> JointSamples {
        match self {
            Self::Rollout(file) => samples_from_steps(&file.trajectory.steps),
            Self::Joint(file) => file.samples(),
            Self::Csv(samples) => samples.clone(),
        }
    }

    /// Verifies the file with the independent checker `model` (whose robot's joints, base to
    /// tip, are `joint_names`) against `task` and `constraints`: the joint names the file
    /// declares must be the robot's, and every point must hold every constraint. With
    /// `own_task` (the task is the one the file was planned for), a rollout file's recorded TCP,
    /// tool angles, path length and end are verified too; its tool angles are measured from
    /// that task's normal, so against any other task they are not. A joint-trajectory file is
    /// verified against joint dynamics limits too: `limits` when given, else the file's own.
    pub fn verify(
        &self,
        model: &ReferenceModel,
        joint_names: &[String],
        task: &Task,
        constraints: &ConstraintConfig,
        own_task: bool,
        limits: Option<&JointDynamics>,
    ) -> Result<ReplayReport, VerifyFailure> {
        let samples = self.samples();
        let failure = |error| VerifyFailure {
            time_s: match &error {
                ReplayError::Point { point, .. } => samples.time_s.get(*point).copied(),
                _ => None,
            },
            points: samples.len(),
            error,
        };
        if let Some(names) = self.joint_names() {
            check_joint_names(names, joint_names).map_err(failure)?;
        }
        let recording = match self {
            Self::Rollout(file) if own_task => Some(Recording::from(&file.trajectory)),
            _ => None,
        };
        let dynamics = match (limits, self) {
            (Some(limits), _) => Some(limits.clone()),
            (None, Self::Joint(file)) => Some(file.limits.dynamics()),
            (None, _) => None,
        };
        check_replay(
            model,
            &task.into(),
            &emg_control::task_bounds(task, constraints),
            &samples,
            recording.as_ref(),
            dynamics.as_ref(),
        )
        .map_err(failure)
    }
}

/// A trajectory file that does not hold up: the checker's finding, with the time of the point
/// it names.
#[derive(Debug)]
pub struct VerifyFailure {
    /// The checker's finding.
    pub error: ReplayError,
    /// Time of the failing point (s), when the finding names a point.
    pub time_s: Option<f64>,
    /// Number of points in the file.
    pub points: usize,
}

impl std::fmt::Display for VerifyFailure {
    /// `point k of N (t = … s): problem`, or the finding itself when it names no point.
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match &self.error {
            ReplayError::Point { point, problem, .. } => {
                write!(f, "point {point} of {}", self.points)?;
                if let Some(t) = self.time_s {
                    write!(f, " (t = {t} s)")?;
                }
                write!(f, ": {problem}")
            }
            error => write!(f, "{error}"),
        }
    }
}

impl std::error::Error for VerifyFailure {}
