//! Where the shipped robots and models are read from.

use std::path::{Path, PathBuf};

use emg_planner::DataDir;
use pyo3::exceptions::PyOSError;
use pyo3::prelude::*;

/// The shipped data: `$EMG_DATA` when set, else the copy compiled into the module
/// ([`emg_planner::embedded::extracted`]), so an installed wheel needs no checkout.
pub(crate) fn data_dir() -> PyResult<DataDir> {
    match std::env::var_os(DataDir::ENV) {
        Some(dir) if !dir.is_empty() => Ok(DataDir::new(dir)),
        _ => emg_planner::embedded::extracted().map_err(|e| {
            PyOSError::new_err(format!(
                "cannot write the shipped robots and models to the cache directory: {e} (set \
                 XDG_CACHE_HOME to a writable directory, or EMG_DATA to a copy of data/)"
            ))
        }),
    }
}

/// The robot file a `robot` argument selects: a shipped robot's name or a path.
pub(crate) fn robot_file(robot: &Path) -> PyResult<PathBuf> {
    Ok(data_dir()?.robot_file(&robot.to_string_lossy()))
}
