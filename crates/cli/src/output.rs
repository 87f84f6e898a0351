//! The result files: `<stem>.json` (format `emg-trajectory/1`), `<stem>.csv` and
//! `<stem>.joint_trajectory.json` (format `emg-joint-trajectory/1`). The layouts are documented
//! in `docs/trajectory-format.md` and `docs/joint-trajectory-format.md`.

use std::ffi::OsString;
use std::path::{Path, PathBuf};

use anyhow::{Context, Result};
use emg_control::{
    ClassicalGains, JointTrajectory, RolloutConfig, StepRecord, Task, Termination, Trajectory,
    trajectory_csv,
};
use serde::Serialize;

/// Value of the `format` field of every trajectory file this build writes.
pub const TRAJECTORY_FORMAT: &str = "emg-trajectory/1";

/// One planned task as written to `<stem>.json`.
#[derive(Debug, Serialize)]
pub struct TrajectoryFile<'a> {
    /// Always [`TRAJECTORY_FORMAT`].
    pub format: &'static str,
    /// Robot file path as given on the command line.
    pub robot: String,
    /// Names of the seven joints, base to tip (the order of every `q`).
    pub joint_names: &'a [String],
    /// The validated task.
    pub task: &'a Task,
    /// `generating`, `home` or `given`.
    pub seed_source: &'a str,
    /// Controller requested on the command line.
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
}

impl<'a> TrajectoryFile<'a> {
    /// Borrows the parts of a result; `trajectory` supplies steps, termination and length.
    #[allow(clippy::too_many_arguments)]
    pub fn new(
        robot: &Path,
        joint_names: &'a [String],
        task: &'a Task,
        seed_source: &'a str,
        controller: &'a str,
        config: &'a RolloutConfig,
        gains: &'a ClassicalGains,
        trajectory: &'a Trajectory,
    ) -> Self {
        Self {
            format: TRAJECTORY_FORMAT,
            robot: robot.display().to_string(),
            joint_names,
            task,
            seed_source,
            controller,
            config,
            gains,
            steps: &trajectory.steps,
            termination: &trajectory.termination,
            path_length_m: trajectory.path_length_m,
        }
    }
}

/// The `.json` and `.csv` paths for `stem`: `<stem>.json`, or `<stem>-00007.json` for task 7
/// of a multi-task run (`index = Some(7)`).
pub fn result_paths(stem: &Path, index: Option<usize>) -> (PathBuf, PathBuf) {
    (
        suffixed(stem, index, ".json"),
        suffixed(stem, index, ".csv"),
    )
}

/// The joint-trajectory path for `stem` by the same rule: `<stem>.joint_trajectory.json`, or
/// `<stem>-00007.joint_trajectory.json` for task 7 of a multi-task run.
pub fn joint_trajectory_path(stem: &Path, index: Option<usize>) -> PathBuf {
    suffixed(stem, index, ".joint_trajectory.json")
}

/// `stem`, then `-iiiii` for task `index`, then `ext`, appended as text.
fn suffixed(stem: &Path, index: Option<usize>, ext: &str) -> PathBuf {
    let mut name = OsString::from(stem.as_os_str());
    if let Some(i) = index {
        name.push(format!("-{i:05}"));
    }
    name.push(ext);
    PathBuf::from(name)
}

/// Writes `file` as JSON to `json_path` and its steps as CSV to `csv_path`, creating parent
/// directories. Each file is written to a temporary name and renamed into place.
pub fn write_result(file: &TrajectoryFile<'_>, json_path: &Path, csv_path: &Path) -> Result<()> {
    let mut json = serde_json::to_string(file).context("cannot serialise the trajectory")?;
    json.push('\n');
    write_atomic(json_path, &json)?;
    write_atomic(csv_path, &trajectory_csv(file.steps))
}

/// Writes `file` as JSON to `path` (temporary name, then renamed into place).
pub fn write_joint_trajectory(file: &JointTrajectory, path: &Path) -> Result<()> {
    let mut json = file.to_json();
    json.push('\n');
    write_atomic(path, &json)
}

/// The viewer page path for `--html <path>`: `path` itself, or for task 7 of a multi-task run
/// `path` without its extension, then `-00007`, then the extension (`.html` when it has none).
pub fn html_path(path: &Path, index: Option<usize>) -> PathBuf {
    let Some(i) = index else {
        return path.to_path_buf();
    };
    let mut name = OsString::from(path.with_extension("").as_os_str());
    name.push(format!("-{i:05}."));
    name.push(path.extension().unwrap_or("html".as_ref()));
    PathBuf::from(name)
}

/// Writes the viewer page `html` to `path`, creating parent directories, via a temporary name.
pub fn write_html(path: &Path, html: &str) -> Result<()> {
    write_atomic(path, html)
}

fn write_atomic(path: &Path, contents: &str) -> Result<()> {
    if let Some(parent) = path.parent().filter(|p| !p.as_os_str().is_empty()) {
        std::fs::create_dir_all(parent)
            .with_context(|| format!("cannot create directory {}", parent.display()))?;
    }
    let mut partial = OsString::from(path.as_os_str());
    partial.push(".partial");
    let partial = PathBuf::from(partial);
    std::fs::write(&partial, contents)
        .with_context(|| format!("cannot write {}", partial.display()))?;
    std::fs::rename(&partial, path).with_context(|| format!("cannot write {}", path.display()))
}
