//! The seed-label dataset: per task of a task set, the best initial configurations found across
//! self-motion branches (Sec. 4.1, SPEC §7), in a compact versioned binary file.
//!
//! Layout (little endian), documented for other readers in `docs/labels-format.md`:
//! the 8-byte magic `EMGLABEL`, `u32` format version (1), `u32` most labels per task (`K'`),
//! the 32-byte SHA-256 of the labelled task-set file, `u64` task count of that task set, `u64`
//! number of task records; then per record (task indices strictly increasing) `u32` task index,
//! `u8` label count, and per label `q` (7 × `f64`, rad), `length_m` (`f32`), `stability_m`
//! (`f32`) and `branch` (`u32`).

use std::path::Path;

use emg_kinematics::{JointVector, MAX_DOF};
use sha2::{Digest, Sha256};

const MAGIC: &[u8; 8] = b"EMGLABEL";
/// Version of the binary label layout written by [`LabelSet::write`].
pub const LABEL_FORMAT_VERSION: u32 = 1;
const HEADER_BYTES: usize = 8 + 4 + 4 + 32 + 8 + 8;
const RECORD_HEADER_BYTES: usize = 4 + 1;
const LABEL_BYTES: usize = MAX_DOF * 8 + 4 + 4 + 4;

/// One labelled initial configuration of a task.
#[derive(Clone, Debug, PartialEq)]
pub struct Label {
    /// Configuration on the exact pose `(p0, tool axis = n)` within every constraint (rad).
    pub q: JointVector,
    /// Path length `L` of the classical rollout from `q` (m; stored to `f32` precision).
    pub length_m: f64,
    /// Self-motion branch the configuration lies on; ids are per task, 0 = the branch found first.
    pub branch: u32,
    /// Largest change of `L` under the labeller's small task perturbations (m; `f32` precision).
    pub stability_m: f64,
}

impl Label {
    /// A label whose lengths are rounded to the stored `f32` precision, so that writing and
    /// reading it back yields the same value.
    pub fn stored(q: JointVector, length_m: f64, branch: u32, stability_m: f64) -> Self {
        Self {
            q,
            length_m: f64::from(length_m as f32),
            branch,
            stability_m: f64::from(stability_m as f32),
        }
    }
}

/// The labels of one task, best (longest) first.
#[derive(Clone, Debug, PartialEq)]
pub struct TaskLabels {
    /// Index of the task in the labelled task-set file (0-based).
    pub task_index: u32,
    /// At most `K'` labels, longest first; empty when no candidate qualified.
    pub labels: Vec<Label>,
}

/// A label file: which task set it labels, and the labels of some or all of its tasks.
#[derive(Clone, Debug, PartialEq)]
pub struct LabelSet {
    task_set_sha256: [u8; 32],
    task_set_len: u64,
    max_labels: u32,
    tasks: Vec<TaskLabels>,
}

/// Why a label file could not be read or written; names the file and what is wrong.
#[derive(Debug, thiserror::Error)]
pub enum LabelError {
    /// The file could not be read or written.
    #[error("{path}: {source}")]
    Io {
        /// File path.
        path: String,
        /// Underlying error.
        source: std::io::Error,
    },
    /// The file is not a label file of this version, or is truncated.
    #[error("{path}: {problem}")]
    Format {
        /// File path.
        path: String,
        /// What is wrong.
        problem: String,
    },
    /// One task record is invalid.
    #[error("{path}: task {task_index}: {problem}")]
    Record {
        /// File path (empty when building a set in memory).
        path: String,
        /// Task index of the record.
        task_index: u32,
        /// What is wrong.
        problem: String,
    },
}

impl LabelSet {
    /// A label set for the task set with SHA-256 `task_set_sha256` and `task_set_len` tasks,
    /// holding `tasks` (strictly increasing indices below `task_set_len`, at most `max_labels`
    /// finite labels each, longest first).
    pub fn new(
        task_set_sha256: [u8; 32],
        task_set_len: u64,
        max_labels: u32,
        tasks: Vec<TaskLabels>,
    ) -> Result<Self, LabelError> {
        let set = Self {
            task_set_sha256,
            task_set_len,
            max_labels,
            tasks,
        };
        set.validate("")?;
        Ok(set)
    }

    /// Task records, in increasing task index.
    pub fn tasks(&self) -> &[TaskLabels] {
        &self.tasks
    }

    /// The labels of task `task_index`, if this set holds its record.
    pub fn get(&self, task_index: u32) -> Option<&TaskLabels> {
        self.tasks
            .binary_search_by_key(&task_index, |t| t.task_index)
            .ok()
            .map(|i| &self.tasks[i])
    }

    /// SHA-256 of the labelled task-set file (see [`task_set_sha256`]).
    pub fn task_set_sha256(&self) -> &[u8; 32] {
        &self.task_set_sha256
    }

    /// Number of tasks in the labelled task set.
    pub fn task_set_len(&self) -> u64 {
        self.task_set_len
    }

    /// Most labels per task (`K'`).
    pub fn max_labels(&self) -> u32 {
        self.max_labels
    }

    /// Whether the set holds a record for every task of its task set.
    pub fn is_complete(&self) -> bool {
        self.tasks.len() as u64 == self.task_set_len
    }

    /// Reads and validates a label file.
    pub fn read(path: &Path) -> Result<Self, LabelError> {
        let name = path.display().to_string();
        let bytes = std::fs::read(path).map_err(|source| LabelError::Io {
            path: name.clone(),
            source,
        })?;
        Self::from_bytes(&name, &bytes)
    }

    /// Parses and validates the bytes of a label file; `origin` names them in errors.
    pub fn from_bytes(origin: &str, bytes: &[u8]) -> Result<Self, LabelError> {
        let name = origin.to_string();
        let format = |problem: String| LabelError::Format {
            path: name.clone(),
            problem,
        };
        let mut reader = Reader { bytes, at: 0 };
        let truncated = || "the file is truncated".to_string();
        if reader.take(8).ok_or_else(truncated).map_err(format)? != MAGIC {
            return Err(format("not a label file (magic bytes differ)".into()));
        }
        let version = reader.u32().ok_or_else(truncated).map_err(format)?;
        if version != LABEL_FORMAT_VERSION {
            return Err(format(format!(
                "format version {version}, this reader knows {LABEL_FORMAT_VERSION}"
            )));
        }
        let max_labels = reader.u32().ok_or_else(truncated).map_err(format)?;
        let mut task_set_sha256 = [0u8; 32];
        task_set_sha256.copy_from_slice(reader.take(32).ok_or_else(truncated).map_err(format)?);
        let task_set_len = reader.u64().ok_or_else(truncated).map_err(format)?;
        let records = reader.u64().ok_or_else(truncated).map_err(format)?;
        if records > task_set_len {
            return Err(format(format!(
                "{records} records for a task set of {task_set_len} tasks"
            )));
        }
        // The declared count sizes nothing: a record takes at least `RECORD_HEADER_BYTES`, so
        // the bytes present bound how many can follow.
        let room = (bytes.len() - reader.at) / RECORD_HEADER_BYTES;
        let mut tasks = Vec::with_capacity(usize::try_from(records).map_or(room, |r| r.min(room)));
        for _ in 0..records {
            tasks.push(reader.record().ok_or_else(truncated).map_err(format)?);
        }
        if reader.at != bytes.len() {
            return Err(format(format!(
                "{} trailing bytes after the last record",
                bytes.len() - reader.at
            )));
        }
        let set = Self {
            task_set_sha256,
            task_set_len,
            max_labels,
            tasks,
        };
        set.validate(&name)?;
        Ok(set)
    }

    /// Writes the set in the binary layout (atomically: a temporary file renamed into place).
    pub fn write(&self, path: &Path) -> Result<(), LabelError> {
        emg_io::write_atomically(path, self.to_bytes()).map_err(|source| LabelError::Io {
            path: path.display().to_string(),
            source,
        })
    }

    /// The set in the binary layout.
    pub fn to_bytes(&self) -> Vec<u8> {
        let labels: usize = self.tasks.iter().map(|t| t.labels.len()).sum();
        let mut bytes = Vec::with_capacity(
            HEADER_BYTES + self.tasks.len() * RECORD_HEADER_BYTES + labels * LABEL_BYTES,
        );
        bytes.extend_from_slice(MAGIC);
        bytes.extend_from_slice(&LABEL_FORMAT_VERSION.to_le_bytes());
        bytes.extend_from_slice(&self.max_labels.to_le_bytes());
        bytes.extend_from_slice(&self.task_set_sha256);
        bytes.extend_from_slice(&self.task_set_len.to_le_bytes());
        bytes.extend_from_slice(&(self.tasks.len() as u64).to_le_bytes());
        for task in &self.tasks {
            bytes.extend_from_slice(&task.task_index.to_le_bytes());
            bytes.push(task.labels.len() as u8);
            for label in &task.labels {
                for value in label.q.iter() {
                    bytes.extend_from_slice(&value.to_le_bytes());
                }
                bytes.extend_from_slice(&(label.length_m as f32).to_le_bytes());
                bytes.extend_from_slice(&(label.stability_m as f32).to_le_bytes());
                bytes.extend_from_slice(&label.branch.to_le_bytes());
            }
        }
        bytes
    }

    /// Joins label sets of the same task set holding disjoint tasks into one, in task order.
    pub fn merge(parts: Vec<LabelSet>) -> Result<Self, LabelError> {
        let mut parts = parts.into_iter();
        let Some(first) = parts.next() else {
            return Err(LabelError::Format {
                path: String::new(),
                problem: "no label sets to merge".into(),
            });
        };
        let mut merged = first;
        for part in parts {
            if part.task_set_sha256 != merged.task_set_sha256
                || part.task_set_len != merged.task_set_len
                || part.max_labels != merged.max_labels
            {
                return Err(LabelError::Format {
                    path: String::new(),
                    problem: "the label sets label different task sets or use different K'".into(),
                });
            }
            merged.tasks.extend(part.tasks);
        }
        merged.tasks.sort_by_key(|t| t.task_index);
        merged.validate("")?;
        Ok(merged)
    }

    fn validate(&self, path: &str) -> Result<(), LabelError> {
        let mut previous: Option<u32> = None;
        for task in &self.tasks {
            let problem = |problem: String| LabelError::Record {
                path: path.to_string(),
                task_index: task.task_index,
                problem,
            };
            if previous.is_some_and(|p| p >= task.task_index) {
                return Err(problem(
                    "task indices are not strictly increasing (duplicate or out of order)".into(),
                ));
            }
            previous = Some(task.task_index);
            if u64::from(task.task_index) >= self.task_set_len {
                return Err(problem(format!(
                    "index beyond the task set of {} tasks",
                    self.task_set_len
                )));
            }
            if task.labels.len() > self.max_labels as usize || task.labels.len() > 255 {
                return Err(problem(format!(
                    "{} labels, at most {} allowed",
                    task.labels.len(),
                    self.max_labels
                )));
            }
            for (k, label) in task.labels.iter().enumerate() {
                if !label.q.iter().all(|v| v.is_finite()) {
                    return Err(problem(format!("label {k}: field 'q' is not finite")));
                }
                if !label.length_m.is_finite() || !label.stability_m.is_finite() {
                    return Err(problem(format!(
                        "label {k}: field 'length_m' or 'stability_m' is not finite"
                    )));
                }
            }
            if task
                .labels
                .windows(2)
                .any(|pair| pair[0].length_m < pair[1].length_m)
            {
                return Err(problem("labels are not sorted longest first".into()));
            }
        }
        Ok(())
    }
}

/// SHA-256 of a file's bytes: the identity of a labelled task set, of weights, of any input.
pub fn file_sha256(path: &Path) -> Result<[u8; 32], LabelError> {
    let bytes = std::fs::read(path).map_err(|source| LabelError::Io {
        path: path.display().to_string(),
        source,
    })?;
    Ok(Sha256::digest(&bytes).into())
}

/// Lower-case hexadecimal form of a digest (for manifests).
pub fn hex(digest: &[u8]) -> String {
    digest.iter().map(|b| format!("{b:02x}")).collect()
}

struct Reader<'a> {
    bytes: &'a [u8],
    at: usize,
}

impl<'a> Reader<'a> {
    fn take(&mut self, n: usize) -> Option<&'a [u8]> {
        let slice = self.bytes.get(self.at..self.at + n)?;
        self.at += n;
        Some(slice)
    }

    fn u32(&mut self) -> Option<u32> {
        Some(u32::from_le_bytes(self.take(4)?.try_into().ok()?))
    }

    fn u64(&mut self) -> Option<u64> {
        Some(u64::from_le_bytes(self.take(8)?.try_into().ok()?))
    }

    fn f32(&mut self) -> Option<f64> {
        Some(f64::from(f32::from_le_bytes(
            self.take(4)?.try_into().ok()?,
        )))
    }

    fn f64(&mut self) -> Option<f64> {
        Some(f64::from_le_bytes(self.take(8)?.try_into().ok()?))
    }

    fn record(&mut self) -> Option<TaskLabels> {
        let task_index = self.u32()?;
        let count = self.take(1)?[0];
        let mut labels = Vec::with_capacity(usize::from(count));
        for _ in 0..count {
            let mut q = JointVector::zeros();
            for value in q.iter_mut() {
                *value = self.f64()?;
            }
            let length_m = self.f32()?;
            let stability_m = self.f32()?;
            let branch = self.u32()?;
            labels.push(Label {
                q,
                length_m,
                branch,
                stability_m,
            });
        }
        Some(TaskLabels { task_index, labels })
    }
}
