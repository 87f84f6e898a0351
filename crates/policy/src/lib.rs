//! The learned null-space controller (Sec. 4.2, Eqs. 6–7; SPEC §4–5): PPO in Burn on CPU over
//! vectorised rollouts of the shared [`emg_control::Episode`] step, exported weights, and an
//! allocation-free plain-Rust policy forward for rollouts.
//!
//! * [`observe`]: the 31-value observation of Eq. 6; the action is `a ∈ (−1, 1)⁴` in `B(q)`,
//!   scaled by `a_max` inside the shared step (Eq. 7).
//! * [`TrainingPool`] / [`ArmEnvironment`]: episodes on training tasks, starting from their
//!   labels or `q0_seed`; reward `clip(Δp·d / (v·Δt), 0, 1)`.
//! * [`VecEnv`]: many [`Environment`]s stepped in parallel (rayon), thread-count independent.
//! * [`Trainer`]: PPO with GAE, clipped objective and value loss, entropy bonus, target-KL stop,
//!   return normalisation, truncation bootstrap; checkpoints with exact resume; any Burn
//!   [`Backend`].
//! * [`PolicyWeights`] / [`PlainPolicy`]: exported weights and their batch-1 forward.
//! * [`RlController`]: the trained policy as an [`emg_control::NullSpaceController`].
//!
//! ```
//! use emg_control::{RolloutConfig, Task, rollout};
//! use emg_kinematics::{Robot, Vec3};
//! use emg_policy::{Backend, NetworkConfig, PpoConfig, RlController, Trainer};
//! let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../../data/robots/fr3_pen.urdf");
//! let robot = Robot::from_urdf_file(path, "link0", "pen_tip")?;
//! let network = NetworkConfig { hidden: vec![8], ..NetworkConfig::default() };
//! let trainer = Trainer::new(network, PpoConfig::default(), Backend::Flex)?;
//! let mut controller = RlController::new(&trainer.weights());
//! let seed = robot.mid_range();
//! let kin = robot.forward(&seed);
//! let task = Task::new(&robot, kin.tcp(), Vec3::y(), kin.tool_axis(), Some(seed))?;
//! let trajectory = rollout(&robot, &task, &seed, &mut controller, &RolloutConfig::default());
//! assert!(trajectory.path_length_m > 0.0);
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```

mod advantage;
mod config;
mod controller;
mod env;
mod error;
mod format;
mod inference;
#[cfg(feature = "train")]
mod network;
mod observation;
#[cfg(feature = "train")]
mod ppo;
mod vec_env;
mod weights;

pub use advantage::{ReturnScaler, RunningMoments, Targets, generalised_advantages};
pub use config::{Backend, EnvConfig, NetworkConfig, PpoConfig};
pub use controller::RlController;
#[cfg(feature = "train")]
pub use emg_learning::checkpoint::CheckpointError;
pub use emg_learning::container::ContainerError;
pub use env::{ArmEnvironment, TrainingPool};
pub use error::PolicyError;
pub use format::{WEIGHTS_FORMAT_VERSION, WeightsError};
pub use inference::{ActorOutput, PlainPolicy, PolicyScratch};
#[cfg(feature = "train")]
pub use network::{ActorCritic, PolicyOutput, Trunk};
pub use observation::{ACTION_DIM, OBSERVATION_DIM, PolicyDims, observe};
#[cfg(feature = "train")]
pub use ppo::{IterationLog, IterationTiming, Trainer};
pub use vec_env::{Environment, EpisodeEnd, MAX_ENVS, Rollout, Transition, VecEnv, VecEnvSnapshot};
pub use weights::{PolicyWeights, WeightsHeader, layer_shapes};
