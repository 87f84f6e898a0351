//! Checkpoint directories replaced atomically: files are written into a staging sibling that is
//! swapped in only when complete, so a stop at any moment leaves a whole checkpoint behind.

use std::path::{Path, PathBuf};

/// `dir` with `.suffix` appended to its last component.
fn sibling(dir: &Path, suffix: &str) -> PathBuf {
    let mut name = dir.file_name().unwrap_or_default().to_os_string();
    name.push(format!(".{suffix}"));
    dir.with_file_name(name)
}

/// Creates an empty staging directory (`<dir>.partial`) for the next checkpoint of `dir` and
/// returns its path.
pub fn stage(dir: &Path) -> std::io::Result<PathBuf> {
    let staging = sibling(dir, "partial");
    let _ = std::fs::remove_dir_all(&staging);
    std::fs::create_dir_all(&staging)?;
    Ok(staging)
}

/// Replaces `dir` by its complete staging directory (the old checkpoint is kept as
/// `<dir>.previous` until the new one is in place).
pub fn publish(dir: &Path) -> std::io::Result<()> {
    let (staging, previous) = (sibling(dir, "partial"), sibling(dir, "previous"));
    let _ = std::fs::remove_dir_all(&previous);
    if dir.exists() {
        std::fs::rename(dir, &previous)?;
    }
    std::fs::rename(&staging, dir)?;
    let _ = std::fs::remove_dir_all(&previous);
    Ok(())
}
