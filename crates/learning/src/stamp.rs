//! Which robot a weights file was trained for: its name and the fingerprint of its chain, so that
//! a model is never used on another arm by accident.

use serde::{Deserialize, Serialize};

/// The robot a weights file was trained for.
#[derive(Clone, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub struct RobotStamp {
    /// The robot's name (the URDF `<robot name>`).
    pub name: String,
    /// The fingerprint of its chain (joint frames, axes, limits, TCP).
    pub fingerprint: String,
}

impl std::fmt::Display for RobotStamp {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let short: String = self.fingerprint.chars().take(12).collect();
        write!(f, "'{}' (chain {short}…)", self.name)
    }
}

/// Why a weights file does not belong to the robot it is loaded for.
#[derive(Clone, Debug, PartialEq, Eq, thiserror::Error)]
pub enum StampError {
    /// The file records no robot.
    #[error(
        "weights file {file} records no robot it was trained for; stamp it with `cargo xtask \
         stamp-weights --robot <robot> {file}` if it really was trained for {robot}"
    )]
    Missing {
        /// The weights file.
        file: String,
        /// The robot it is loaded for.
        robot: RobotStamp,
    },
    /// The file was trained for another robot.
    #[error("weights file {file} was trained for robot {trained_for}, not for robot {robot}")]
    Mismatch {
        /// The weights file.
        file: String,
        /// The robot the file records.
        trained_for: RobotStamp,
        /// The robot it is loaded for.
        robot: RobotStamp,
    },
}

/// Checks that the stamp a weights file records (`recorded`) is `robot`'s; `file` names it in
/// the error.
pub fn check_stamp(
    recorded: Option<&RobotStamp>,
    robot: &RobotStamp,
    file: &str,
) -> Result<(), StampError> {
    match recorded {
        None => Err(StampError::Missing {
            file: file.to_string(),
            robot: robot.clone(),
        }),
        Some(stamp) if stamp.fingerprint != robot.fingerprint => Err(StampError::Mismatch {
            file: file.to_string(),
            trained_for: stamp.clone(),
            robot: robot.clone(),
        }),
        Some(_) => Ok(()),
    }
}
