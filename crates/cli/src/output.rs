//! Writing the result files of one planned task (layouts in `emg-io`).

use std::path::Path;

use anyhow::{Context, Result};
use emg_io::{JointTrajectory, PlanPaths, TrajectoryFile, trajectory_csv, write_atomically};

/// Writes `file` as JSON and its steps as CSV to the paths of `paths`, and `joint` as the joint
/// trajectory, each atomically, creating parent directories.
pub fn write_result(
    file: &TrajectoryFile<'_>,
    joint: &JointTrajectory,
    paths: &PlanPaths,
) -> Result<()> {
    write_text(&paths.json, &file.to_json())?;
    write_text(&paths.csv, &trajectory_csv(file.steps))?;
    let mut json = joint.to_json();
    json.push('\n');
    write_text(&paths.joint_trajectory, &json)
}

/// Writes `text` to `path` atomically, creating parent directories.
pub fn write_text(path: &Path, text: &str) -> Result<()> {
    write_atomically(path, text.as_bytes())
        .with_context(|| format!("cannot write {}", path.display()))
}
