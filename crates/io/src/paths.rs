//! Where the files of a planned task go: `<stem>.json`, `<stem>.csv`,
//! `<stem>.joint_trajectory.json`, and `-00007` before the extension for task 7 of a multi-task
//! run.

use std::ffi::OsString;
use std::path::{Path, PathBuf};

/// The paths of one planned task's files.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct PlanPaths {
    /// `emg-trajectory/1` JSON.
    pub json: PathBuf,
    /// The CSV table.
    pub csv: PathBuf,
    /// `emg-joint-trajectory/2` JSON.
    pub joint_trajectory: PathBuf,
}

impl PlanPaths {
    /// The files for `stem`: `<stem>.json`, or `<stem>-00007.json` for task 7 of a multi-task
    /// run (`index = Some(7)`), and likewise `.csv` and `.joint_trajectory.json`.
    pub fn new(stem: &Path, index: Option<usize>) -> Self {
        Self {
            json: suffixed(stem, index, ".json"),
            csv: suffixed(stem, index, ".csv"),
            joint_trajectory: suffixed(stem, index, ".joint_trajectory.json"),
        }
    }
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
