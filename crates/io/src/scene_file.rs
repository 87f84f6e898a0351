//! Scene files: the obstacles of a cell as JSON ([`emg_kinematics::Scene`] describes the
//! layout).

use std::path::Path;

use emg_kinematics::Scene;

/// Why a scene file cannot be used.
#[derive(Debug, thiserror::Error)]
pub enum SceneFileError {
    /// The file cannot be read.
    #[error("cannot read scene file {path}")]
    Io {
        /// The file.
        path: String,
        /// The cause.
        #[source]
        source: std::io::Error,
    },
    /// The text is not a scene; the message names the obstacle and the field.
    #[error("invalid scene file {path}: {message}")]
    Parse {
        /// The file.
        path: String,
        /// The reader's message (obstacle, field, value, line and column).
        message: String,
    },
}

/// Reads and checks a scene file.
pub fn read_scene(path: &Path) -> Result<Scene, SceneFileError> {
    let text = std::fs::read_to_string(path).map_err(|source| SceneFileError::Io {
        path: path.display().to_string(),
        source,
    })?;
    serde_json::from_str(&text).map_err(|e| SceneFileError::Parse {
        path: path.display().to_string(),
        message: e.to_string(),
    })
}
