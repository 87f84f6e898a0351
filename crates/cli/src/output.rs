//! Writing the `--html` page (the result files are written by `emg_planner::PlanFiles`), and the
//! progress bars of long commands.

use std::path::Path;

use anyhow::{Context, Result};
use emg_io::write_atomically;

/// Writes `text` to `path` atomically, creating parent directories.
pub fn write_text(path: &Path, text: &str) -> Result<()> {
    write_atomically(path, text).with_context(|| format!("cannot write {}", path.display()))
}

/// A progress bar of `length` `things` (strokes, places), its stage as its message.
pub fn progress_bar(length: u64, things: &str) -> indicatif::ProgressBar {
    indicatif::ProgressBar::new(length).with_style(
        indicatif::ProgressStyle::with_template(&format!(
            "{{msg:>8}} [{{bar:40}}] {{pos}}/{{len}} {things}, {{elapsed}}"
        ))
        .expect("a valid template")
        .progress_chars("=> "),
    )
}
