//! Why a configuration, a training pool or a checkpoint is unusable.

#[cfg(feature = "train")]
use emg_learning::checkpoint::CheckpointError;

use crate::format::WeightsError;

/// Why a configuration, a training pool or a checkpoint is unusable.
#[derive(Debug, thiserror::Error)]
pub enum PolicyError {
    /// A configuration field with an unusable value.
    #[error("field '{field}' {problem}")]
    BadConfig {
        /// Field.
        field: &'static str,
        /// What is wrong.
        problem: String,
    },
    /// A checkpoint file could not be read or written.
    #[cfg(feature = "train")]
    #[error(transparent)]
    Checkpoint(#[from] CheckpointError),
    /// A checkpoint made with other settings.
    #[error("checkpoint was made with a different {what}; start a new run or restore the settings")]
    ConfigMismatch {
        /// `network config` or `PPO config`.
        what: &'static str,
    },
    /// Unusable weights.
    #[error(transparent)]
    Weights(#[from] WeightsError),
}
