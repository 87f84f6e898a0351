//! Path files: a path task's start, surface normal and segments as JSON
//! ([`emg_control::PathSpec`]; docs/paths.md describes the layout).

use std::path::Path;

/// Why a path file cannot be used.
#[derive(Debug, thiserror::Error)]
pub enum PathFileError {
    /// The file cannot be read.
    #[error("cannot read path file {path}")]
    Io {
        /// The file.
        path: String,
        /// The cause.
        #[source]
        source: std::io::Error,
    },
    /// The text is not a path; the message names the field and what is wrong.
    #[error("invalid path file {path}: {message}")]
    Parse {
        /// The file.
        path: String,
        /// The reader's message (field, value, line and column).
        message: String,
    },
}

/// Reads and validates a path file.
pub fn read_path(path: &Path) -> Result<emg_control::Path, PathFileError> {
    let text = std::fs::read_to_string(path).map_err(|source| PathFileError::Io {
        path: path.display().to_string(),
        source,
    })?;
    parse_path(&text).map_err(|message| PathFileError::Parse {
        path: path.display().to_string(),
        message,
    })
}

/// Parses and validates the text of a path file; the error names the field.
pub fn parse_path(text: &str) -> Result<emg_control::Path, String> {
    let spec: emg_control::PathSpec = serde_json::from_str(text).map_err(|e| e.to_string())?;
    emg_control::Path::new(spec).map_err(|e| e.to_string())
}
