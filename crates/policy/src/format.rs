//! The weights file's layout version, and why a file is not a usable weights file of it.

use emg_learning::container::{ContainerError, FileAccessError};

/// Version of the weights file layout this build reads and writes.
pub const WEIGHTS_FORMAT_VERSION: u32 = 1;

/// Why a weights file is unusable; every variant says what is wrong.
#[derive(Debug, thiserror::Error)]
pub enum WeightsError {
    /// The file could not be read or written.
    #[error(transparent)]
    Io(#[from] FileAccessError),
    /// The bytes are not a well-formed policy weights file of this layout version (the cause
    /// says what is wrong: magic, version, truncation, header, value count, trailing bytes).
    #[error("not a valid policy weights file (EMGPPOWT, format version {WEIGHTS_FORMAT_VERSION})")]
    Format(#[from] ContainerError),
    /// A header field disagrees with what this build uses.
    #[error("weights field '{field}' is {found}, but {expected} is required")]
    ShapeMismatch {
        /// Header field.
        field: &'static str,
        /// Required value.
        expected: usize,
        /// Value in the file.
        found: usize,
    },
    /// A NaN or infinite value.
    #[error("weights value {0} is not finite")]
    NotFinite(usize),
}
