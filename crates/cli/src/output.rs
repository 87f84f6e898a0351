//! Writing the `--html` page (the result files are written by `emg_planner::PlanFiles`).

use std::path::Path;

use anyhow::{Context, Result};
use emg_io::write_atomically;

/// Writes `text` to `path` atomically, creating parent directories.
pub fn write_text(path: &Path, text: &str) -> Result<()> {
    write_atomically(path, text).with_context(|| format!("cannot write {}", path.display()))
}
