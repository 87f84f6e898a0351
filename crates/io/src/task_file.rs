//! Task-set files: a compact versioned binary for generated sets, JSON for hand-written tasks.
//!
//! Binary layout (little endian): the 8-byte magic `EMGTASKS`, `u32` format version (1), `u32`
//! values per task (16), `u64` task count, then per task `p0` (3), `d` (3), `n` (3), `q0_seed` (7)
//! as `f64` (`q0_seed` all NaN when unknown; an arm of six joints has a zero seventh value).
//!
//! JSON layout: an array of objects `{"p0": [x, y, z], "d": [..], "n": [..], "q0_seed": [n values]}`
//! (`q0_seed` optional, one value per joint of the arm), or one such object.

use std::path::Path;

use emg_control::{Task, TaskError};
use emg_kinematics::{JointVector, MAX_DOF, Robot, Vec3};
use serde::{Deserialize, Serialize};

use crate::atomic::write_atomically;

const MAGIC: &[u8; 8] = b"EMGTASKS";
/// Version of the binary task-set layout written by [`write_task_set`].
pub const TASK_FORMAT_VERSION: u32 = 1;
const VALUES_PER_TASK: usize = 16;
const HEADER_BYTES: usize = 8 + 4 + 4 + 8;

/// Why a task file could not be read.
#[derive(Debug, thiserror::Error)]
pub enum TaskFileError {
    /// The file could not be read or written.
    #[error("{path}: {source}")]
    Io {
        /// File path.
        path: String,
        /// Underlying error.
        source: std::io::Error,
    },
    /// The file is not in either task layout.
    #[error("{path}: {problem}")]
    Format {
        /// File path.
        path: String,
        /// What is wrong.
        problem: String,
    },
    /// One task of the file is invalid.
    #[error("{path}: task {index}: {source}")]
    Task {
        /// File path.
        path: String,
        /// 0-based index of the task in the file.
        index: usize,
        /// Why it is invalid.
        source: TaskError,
    },
}

/// A task as written by hand in JSON (validated into a [`Task`] on reading).
#[derive(Clone, Debug, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct TaskSpec {
    /// Start position (m).
    pub p0: [f64; 3],
    /// Motion direction (normalised on reading).
    pub d: [f64; 3],
    /// Task-plane normal (normalised on reading).
    pub n: [f64; 3],
    /// Generating configuration, if known (rad): one value per joint of the arm.
    #[serde(default)]
    pub q0_seed: Option<Vec<f64>>,
}

impl TaskSpec {
    /// Validates the spec into a task for `robot`.
    pub fn to_task(&self, robot: &Robot) -> Result<Task, TaskError> {
        let seed = match &self.q0_seed {
            Some(values) if values.len() != robot.dof() => {
                return Err(TaskError::BadSeed {
                    problem: format!(
                        "has {} values; the robot has {} joints",
                        values.len(),
                        robot.dof()
                    ),
                });
            }
            Some(values) => Some(robot.joint_vector(values)),
            None => None,
        };
        Task::new(
            robot,
            Vec3::from(self.p0),
            Vec3::from(self.d),
            Vec3::from(self.n),
            seed,
        )
    }

    /// The spec of `task` on `robot` (its seed's `n` joint values).
    pub fn of(task: &Task, robot: &Robot) -> Self {
        Self {
            p0: task.p0.into(),
            d: task.d.into(),
            n: task.n.into(),
            q0_seed: task.q0_seed.map(|q| robot.joints_of(&q).to_vec()),
        }
    }
}

/// Writes `tasks` in the binary layout (bit-exact values), atomically.
pub fn write_task_set(path: &Path, tasks: &[Task]) -> Result<(), TaskFileError> {
    let io = |source| TaskFileError::Io {
        path: path.display().to_string(),
        source,
    };
    let mut bytes = Vec::with_capacity(HEADER_BYTES + tasks.len() * VALUES_PER_TASK * 8);
    bytes.extend_from_slice(MAGIC);
    bytes.extend_from_slice(&TASK_FORMAT_VERSION.to_le_bytes());
    bytes.extend_from_slice(&(VALUES_PER_TASK as u32).to_le_bytes());
    bytes.extend_from_slice(&(tasks.len() as u64).to_le_bytes());
    for task in tasks {
        let seed = task
            .q0_seed
            .unwrap_or_else(|| JointVector::repeat(f64::NAN));
        for value in task.p0.iter().chain(&task.d).chain(&task.n).chain(&seed) {
            bytes.extend_from_slice(&value.to_le_bytes());
        }
    }
    write_atomically(path, &bytes).map_err(io)
}

/// Reads tasks from a binary task set or a JSON file, told apart by their content (the
/// `EMGTASKS` magic bytes, or JSON's opening `{` or `[`; the file name does not matter),
/// validating every task against `robot`.
pub fn read_tasks(path: &Path, robot: &Robot) -> Result<Vec<Task>, TaskFileError> {
    read_each_task(path, robot)?.into_iter().collect()
}

/// Reads a task file as [`read_tasks`] does, but validates each task on its own: the file's
/// own faults (unreadable, malformed) are the error, and each task is there or says why it is
/// invalid, so the valid ones can be planned.
pub fn read_each_task(
    path: &Path,
    robot: &Robot,
) -> Result<Vec<Result<Task, TaskFileError>>, TaskFileError> {
    let bytes = std::fs::read(path).map_err(|source| TaskFileError::Io {
        path: path.display().to_string(),
        source,
    })?;
    parse_each_task(&path.display().to_string(), &bytes, robot)
}

/// Parses the bytes of a task file (either layout, told apart by content as in
/// [`read_tasks`]); `origin` names the bytes in errors.
pub fn parse_tasks(origin: &str, bytes: &[u8], robot: &Robot) -> Result<Vec<Task>, TaskFileError> {
    parse_each_task(origin, bytes, robot)?.into_iter().collect()
}

/// Parses the bytes of a task file as [`parse_tasks`] does, each task validated on its own
/// ([`read_each_task`]).
fn parse_each_task(
    origin: &str,
    bytes: &[u8],
    robot: &Robot,
) -> Result<Vec<Result<Task, TaskFileError>>, TaskFileError> {
    let name = origin.to_string();
    let first = bytes.iter().find(|b| !b.is_ascii_whitespace());
    let specs = if bytes.starts_with(MAGIC) {
        parse_binary(&name, bytes, robot.dof())?
    } else if matches!(first, Some(b'{' | b'[')) {
        parse_json(&name, bytes)?
    } else if bytes.starts_with(&MAGIC[..bytes.len().min(MAGIC.len())]) && !bytes.is_empty() {
        return Err(TaskFileError::Format {
            path: name,
            problem: format!(
                "truncated header: {} of its {HEADER_BYTES} bytes",
                bytes.len()
            ),
        });
    } else {
        return Err(TaskFileError::Format {
            path: name,
            problem: "not a task set: it starts with neither the EMGTASKS header of the binary \
                      layout nor the '{' or '[' of JSON"
                .into(),
        });
    };
    Ok(specs
        .iter()
        .enumerate()
        .map(|(index, spec)| {
            spec.to_task(robot).map_err(|source| TaskFileError::Task {
                path: name.clone(),
                index,
                source,
            })
        })
        .collect())
}

fn parse_json(path: &str, bytes: &[u8]) -> Result<Vec<TaskSpec>, TaskFileError> {
    // Dispatch on the first token rather than trying both shapes, so that the error of the
    // shape actually written (unknown key, missing field, position) is the one reported.
    let format = |e: serde_json::Error| TaskFileError::Format {
        path: path.into(),
        problem: e.to_string(),
    };
    match bytes.iter().find(|b| !b.is_ascii_whitespace()) {
        Some(b'{') => serde_json::from_slice::<TaskSpec>(bytes)
            .map(|spec| vec![spec])
            .map_err(format),
        _ => serde_json::from_slice::<Vec<TaskSpec>>(bytes).map_err(format),
    }
}

/// The task specs of a binary task set read for an arm of `joints` joints.
fn parse_binary(path: &str, bytes: &[u8], joints: usize) -> Result<Vec<TaskSpec>, TaskFileError> {
    let format = |problem: String| TaskFileError::Format {
        path: path.into(),
        problem,
    };
    let magic_len = bytes.len().min(MAGIC.len());
    if bytes[..magic_len] != MAGIC[..magic_len] || bytes.is_empty() {
        return Err(format("not a task set: missing the EMGTASKS header".into()));
    }
    if bytes.len() < HEADER_BYTES {
        return Err(format(format!(
            "truncated header: {} of its {HEADER_BYTES} bytes",
            bytes.len()
        )));
    }
    let word = |at: usize| u32::from_le_bytes(bytes[at..at + 4].try_into().expect("4 bytes"));
    let version = word(8);
    if version != TASK_FORMAT_VERSION {
        return Err(format(format!(
            "task-set format version {version} is not supported (this build reads {TASK_FORMAT_VERSION})"
        )));
    }
    if word(12) as usize != VALUES_PER_TASK {
        return Err(format(format!(
            "{} values per task, expected {VALUES_PER_TASK}",
            word(12)
        )));
    }
    let count = u64::from_le_bytes(bytes[16..24].try_into().expect("8 bytes")) as usize;
    let expected = count
        .checked_mul(VALUES_PER_TASK * 8)
        .and_then(|b| b.checked_add(HEADER_BYTES))
        .ok_or_else(|| format(format!("task count {count} is implausible")))?;
    if bytes.len() != expected {
        return Err(format(format!(
            "truncated or padded: header announces {count} tasks ({expected} bytes), file has {} bytes",
            bytes.len()
        )));
    }
    Ok(bytes[HEADER_BYTES..]
        .chunks_exact(VALUES_PER_TASK * 8)
        .map(|record| {
            let v: Vec<f64> = record
                .chunks_exact(8)
                .map(|b| f64::from_le_bytes(b.try_into().expect("8 bytes")))
                .collect();
            let seed = &v[9..9 + MAX_DOF];
            // An arm of fewer joints pads its seed with zeros; the padding is dropped.
            let joints = if seed[joints..].iter().all(|x| *x == 0.0) {
                joints
            } else {
                MAX_DOF
            };
            TaskSpec {
                p0: [v[0], v[1], v[2]],
                d: [v[3], v[4], v[5]],
                n: [v[6], v[7], v[8]],
                q0_seed: (!seed.iter().all(|x| x.is_nan())).then(|| seed[..joints].to_vec()),
            }
        })
        .collect())
}
