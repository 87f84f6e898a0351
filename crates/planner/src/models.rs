//! The trained models a plan can use: the diffusion seeder and the PPO policy, loaded from their
//! weights files.

use std::path::{Path, PathBuf};

use emg_diffusion::{DenoiserWeights, DpSeedConfig, DpSeedError, DpSeeder, WeightsError};
use emg_kinematics::Robot;
use emg_learning::{RobotStamp, StampError, check_stamp};
use emg_policy::{PolicyWeights, RlController};

use crate::controller::ControllerKind;

/// File name of a robot's shipped diffusion-seeder weights, in its `models/` directory.
pub const DIFFUSION_WEIGHTS_FILE: &str = "diffusion-v1.weights";

/// File name of a robot's shipped policy weights, in its `models/` directory.
pub const POLICY_WEIGHTS_FILE: &str = "ppo-v1.weights";

/// The loaded models; either may be absent (then the `dp` seed, or the `rl` and `hybrid`
/// controllers, are unavailable).
#[derive(Clone, Default)]
pub struct Models {
    /// The diffusion seeder (DP seeds).
    pub seeder: Option<DpSeeder>,
    /// The learned null-space controller.
    pub policy: Option<RlController>,
}

/// Why a model cannot be loaded.
#[derive(Debug, thiserror::Error)]
pub enum ModelsError {
    /// The weights were trained for another robot, or record none.
    #[error(transparent)]
    Robot(#[from] StampError),
    /// The diffusion weights cannot be read.
    #[error("cannot load diffusion weights {path}")]
    Diffusion {
        /// The file.
        path: PathBuf,
        /// The cause.
        #[source]
        source: WeightsError,
    },
    /// The diffusion weights cannot make a seeder.
    #[error("unusable diffusion weights {path}")]
    Seeder {
        /// The file.
        path: PathBuf,
        /// The cause.
        #[source]
        source: DpSeedError,
    },
    /// The policy weights cannot be read.
    #[error("cannot load policy weights {path}")]
    Policy {
        /// The file.
        path: PathBuf,
        /// The cause.
        #[source]
        source: emg_policy::WeightsError,
    },
}

impl Models {
    /// The strongest controller these models allow: the hybrid with a policy, else the
    /// classical controller (what `emg plan` and Python run unless told otherwise).
    pub fn best_controller(&self) -> ControllerKind {
        if self.policy.is_some() {
            ControllerKind::Hybrid
        } else {
            ControllerKind::Classical
        }
    }

    /// Loads the models of `robot` whose files are given (with the default DP seed settings);
    /// each file must have been trained for `robot`.
    pub fn load(
        robot: &Robot,
        diffusion: Option<&Path>,
        policy: Option<&Path>,
    ) -> Result<Self, ModelsError> {
        Ok(Self {
            seeder: diffusion.map(|p| load_seeder(robot, p)).transpose()?,
            policy: policy.map(|p| load_policy(robot, p)).transpose()?,
        })
    }

    /// Loads both models shipped for `robot` in its data directory (`<dir>/models/`).
    pub fn shipped(robot: &Robot, data_dir: &Path) -> Result<Self, ModelsError> {
        let models = data_dir.join("models");
        Self::load(
            robot,
            Some(&models.join(DIFFUSION_WEIGHTS_FILE)),
            Some(&models.join(POLICY_WEIGHTS_FILE)),
        )
    }
}

/// The stamp weights trained for `robot` record: its name and its chain's fingerprint.
pub fn robot_stamp(robot: &Robot) -> RobotStamp {
    RobotStamp {
        name: robot.name().to_string(),
        fingerprint: robot.fingerprint(),
    }
}

/// Fails unless the weights file at `path`, whose header records `trained_for`, was trained for
/// `robot`.
fn check_trained_for(
    robot: &Robot,
    trained_for: Option<&RobotStamp>,
    path: &Path,
) -> Result<(), StampError> {
    check_stamp(
        trained_for,
        &robot_stamp(robot),
        &path.display().to_string(),
    )
}

/// The diffusion seeder of a weights file trained for `robot`, with the default DP seed
/// settings.
pub fn load_seeder(robot: &Robot, path: &Path) -> Result<DpSeeder, ModelsError> {
    let weights = DenoiserWeights::read(path).map_err(|source| ModelsError::Diffusion {
        path: path.to_path_buf(),
        source,
    })?;
    check_trained_for(robot, weights.header().robot.as_ref(), path)?;
    DpSeeder::new(robot, &weights, DpSeedConfig::default()).map_err(|source| ModelsError::Seeder {
        path: path.to_path_buf(),
        source,
    })
}

/// The learned controller of a policy weights file trained for `robot`.
pub fn load_policy(robot: &Robot, path: &Path) -> Result<RlController, ModelsError> {
    let weights = PolicyWeights::read(path).map_err(|source| ModelsError::Policy {
        path: path.to_path_buf(),
        source,
    })?;
    check_trained_for(robot, weights.header().robot.as_ref(), path)?;
    Ok(RlController::new(&weights))
}
