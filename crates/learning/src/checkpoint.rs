//! Checkpoint directories replaced atomically: files are written into a staging sibling that is
//! swapped in only when complete, so a stop at any moment leaves a whole checkpoint behind.
//!
//! A checkpoint holds a Burn model's parameters, its optimizer's state and the run state (JSON).

use std::path::{Path, PathBuf};

use burn::module::Module;
use burn::optim::ModuleOptimizer;
use serde::Serialize;
use serde::de::DeserializeOwned;

/// Name of the JSON run state inside a checkpoint directory.
const STATE_FILE: &str = "state.json";
/// Name of the model's parameters inside a checkpoint directory.
const MODEL_FILE: &str = "model.bpk";
/// Name of the optimizer's state inside a checkpoint directory.
const OPTIMIZER_FILE: &str = "optimizer.bpk";

/// A checkpoint file that could not be read or written.
#[derive(Debug, thiserror::Error)]
#[error("checkpoint {path}: {problem}")]
pub struct CheckpointError {
    /// The file or directory concerned.
    pub path: String,
    /// What went wrong.
    pub problem: String,
}

fn error(path: &Path, problem: impl ToString) -> CheckpointError {
    CheckpointError {
        path: path.display().to_string(),
        problem: problem.to_string(),
    }
}

/// Writes the run state (everything but the tensors) into a staging directory as JSON.
pub fn write_state<T: Serialize>(staging: &Path, state: &T) -> Result<(), CheckpointError> {
    let path = staging.join(STATE_FILE);
    let json = serde_json::to_string(state).map_err(|e| error(&path, e))?;
    std::fs::write(&path, json).map_err(|e| error(&path, e))
}

/// Reads the run state of checkpoint `dir`.
pub fn read_state<T: DeserializeOwned>(dir: &Path) -> Result<T, CheckpointError> {
    let path = dir.join(STATE_FILE);
    let text = std::fs::read_to_string(&path).map_err(|e| error(&path, e))?;
    serde_json::from_str(&text).map_err(|e| error(&path, e))
}

/// Writes a model's parameters and its optimizer's state into a staging directory.
pub fn write_training<M: Module>(
    staging: &Path,
    model: &M,
    optimizer: &ModuleOptimizer,
) -> Result<(), CheckpointError> {
    let path = staging.join(MODEL_FILE);
    model
        .clone()
        .save_file(&path)
        .map_err(|e| error(&path, e))?;
    let path = staging.join(OPTIMIZER_FILE);
    optimizer.save(&path).map_err(|e| error(&path, e))
}

/// Loads what [`write_training`] wrote into checkpoint `dir` into `model` and `optimizer`
/// (fresh ones of the checkpoint's shape and settings) and returns them.
pub fn read_training<M: Module>(
    dir: &Path,
    model: M,
    optimizer: ModuleOptimizer,
) -> Result<(M, ModuleOptimizer), CheckpointError> {
    let path = dir.join(MODEL_FILE);
    let model = model.try_load_file(&path).map_err(|e| error(&path, e))?;
    let path = dir.join(OPTIMIZER_FILE);
    let optimizer = optimizer.load(&path).map_err(|e| error(&path, e))?;
    Ok((model, optimizer))
}

/// `dir` with `.suffix` appended to its last component.
fn sibling(dir: &Path, suffix: &str) -> PathBuf {
    let mut name = dir.file_name().unwrap_or_default().to_os_string();
    name.push(format!(".{suffix}"));
    dir.with_file_name(name)
}

/// Creates an empty staging directory (`<dir>.partial`) for the next checkpoint of `dir` and
/// returns its path.
pub fn stage(dir: &Path) -> Result<PathBuf, CheckpointError> {
    let staging = sibling(dir, "partial");
    let _ = std::fs::remove_dir_all(&staging);
    std::fs::create_dir_all(&staging).map_err(|e| error(&staging, e))?;
    Ok(staging)
}

/// Replaces `dir` by its complete staging directory (the old checkpoint is kept as
/// `<dir>.previous` until the new one is in place).
pub fn publish(dir: &Path) -> Result<(), CheckpointError> {
    let (staging, previous) = (sibling(dir, "partial"), sibling(dir, "previous"));
    let _ = std::fs::remove_dir_all(&previous);
    if dir.exists() {
        std::fs::rename(dir, &previous).map_err(|e| error(dir, e))?;
    }
    std::fs::rename(&staging, dir).map_err(|e| error(dir, e))?;
    let _ = std::fs::remove_dir_all(&previous);
    Ok(())
}
