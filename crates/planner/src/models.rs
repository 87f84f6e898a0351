//! The trained models a plan can use: the diffusion seeder and the PPO policy, loaded from their
//! weights files.

use std::path::{Path, PathBuf};

use emg_diffusion::{DenoiserWeights, DpSeedConfig, DpSeedError, DpSeeder, WeightsError};
use emg_policy::{PolicyWeights, RlController};

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
    /// Loads the models whose files are given (with the default DP seed settings).
    pub fn load(diffusion: Option<&Path>, policy: Option<&Path>) -> Result<Self, ModelsError> {
        Ok(Self {
            seeder: diffusion.map(load_seeder).transpose()?,
            policy: policy.map(load_policy).transpose()?,
        })
    }

    /// Loads both models shipped in a robot's data directory (`<dir>/models/`).
    pub fn shipped(data_dir: &Path) -> Result<Self, ModelsError> {
        let models = data_dir.join("models");
        Self::load(
            Some(&models.join(DIFFUSION_WEIGHTS_FILE)),
            Some(&models.join(POLICY_WEIGHTS_FILE)),
        )
    }
}

/// The diffusion seeder of a weights file, with the default DP seed settings.
pub fn load_seeder(path: &Path) -> Result<DpSeeder, ModelsError> {
    let weights = DenoiserWeights::read(path).map_err(|source| ModelsError::Diffusion {
        path: path.to_path_buf(),
        source,
    })?;
    DpSeeder::new(&weights, DpSeedConfig::default()).map_err(|source| ModelsError::Seeder {
        path: path.to_path_buf(),
        source,
    })
}

/// The learned controller of a policy weights file.
pub fn load_policy(path: &Path) -> Result<RlController, ModelsError> {
    let weights = PolicyWeights::read(path).map_err(|source| ModelsError::Policy {
        path: path.to_path_buf(),
        source,
    })?;
    Ok(RlController::new(&weights))
}
