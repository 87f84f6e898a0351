//! Serde configurations of the policy network, the training environments and PPO (SPEC §5
//! defaults adapted to a 2-core CPU budget).

use serde::{Deserialize, Serialize};

/// Shape of the separate actor and critic MLPs (ReLU hidden layers; SPEC §5).
#[derive(Clone, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct NetworkConfig {
    /// Width of each hidden layer, input side first (the authors: three of 512; here two of 128,
    /// sized for two CPU cores).
    pub hidden: Vec<usize>,
    /// Joints `n` of the arm (6 or 7), which size the observation and the action
    /// ([`crate::PolicyDims`]); `cargo xtask train-ppo` sets it from the robot.
    pub joints: usize,
}

impl Default for NetworkConfig {
    fn default() -> Self {
        Self {
            hidden: vec![128, 128],
            joints: emg_kinematics::MAX_DOF,
        }
    }
}

/// How the training environments draw their episodes (Sec. 4.2).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct EnvConfig {
    /// Probability that an episode of a labelled task starts from the task's `q0_seed` rather
    /// than from one of its labels (evaluation starts from `q0_seed`, so training sees both).
    pub q0_seed_probability: f64,
}

impl Default for EnvConfig {
    fn default() -> Self {
        Self {
            q0_seed_probability: 0.5,
        }
    }
}

/// PPO hyper-parameters (SPEC §5).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct PpoConfig {
    /// Seed of every random choice (initial weights, episodes, action noise, minibatches).
    pub seed: u64,
    /// Environments stepped in parallel (the authors: 128).
    pub envs: usize,
    /// Steps per environment in one rollout (the authors: 32; here 64, halving the number of
    /// updates per sample on CPU).
    pub rollout_steps: usize,
    /// Minibatches per epoch (the authors: 32; here 8 of 1024 samples).
    pub minibatches: usize,
    /// Passes over one rollout (the authors: 10).
    pub epochs: usize,
    /// Environment steps of a full run; the Adam learning rate anneals linearly to 0 over it.
    pub total_env_steps: u64,
    /// Initial Adam learning rate (3e-4).
    pub learning_rate: f64,
    /// Adam ε (1e-5).
    pub adam_epsilon: f64,
    /// Discount γ (0.99).
    pub gamma: f64,
    /// GAE λ (0.95).
    pub gae_lambda: f64,
    /// Ratio clip ε of the surrogate objective and of the value loss (0.2).
    pub clip: f64,
    /// Weight of the value loss (0.5).
    pub value_coefficient: f64,
    /// Weight of the entropy bonus (0.01).
    pub entropy_coefficient: f64,
    /// Norm bound of each parameter tensor's gradient (0.5).
    pub grad_clip_norm: f64,
    /// Epochs stop early once a minibatch's approximate KL exceeds this (0.02).
    pub target_kl: f64,
    /// Lower bound of the log standard deviation of the Gaussian (−5).
    pub log_std_min: f64,
    /// Upper bound of the log standard deviation of the Gaussian (0).
    pub log_std_max: f64,
    /// Initial bias of the log-std head (−1).
    pub log_std_bias: f64,
}

impl Default for PpoConfig {
    fn default() -> Self {
        Self {
            seed: 0,
            envs: 128,
            rollout_steps: 64,
            minibatches: 8,
            epochs: 10,
            total_env_steps: 32_000_000,
            learning_rate: 3e-4,
            adam_epsilon: 1e-5,
            gamma: 0.99,
            gae_lambda: 0.95,
            clip: 0.2,
            value_coefficient: 0.5,
            entropy_coefficient: 0.01,
            grad_clip_norm: 0.5,
            target_kl: 0.02,
            log_std_min: -5.0,
            log_std_max: 0.0,
            log_std_bias: -1.0,
        }
    }
}

impl PpoConfig {
    /// Samples in one rollout (`envs × rollout_steps`).
    pub fn batch_size(&self) -> usize {
        self.envs * self.rollout_steps
    }

    /// Rollout–update iterations of a full run.
    pub fn iterations(&self) -> u64 {
        self.total_env_steps
            .div_ceil(self.batch_size().max(1) as u64)
    }

    /// A clear error naming the first unusable field.
    pub fn validate(&self) -> Result<(), crate::error::PolicyError> {
        let bad = |field: &'static str, problem: &str| {
            Err(crate::error::PolicyError::BadConfig {
                field,
                problem: problem.to_string(),
            })
        };
        if self.envs == 0 {
            return bad("envs", "must be positive");
        }
        if self.rollout_steps == 0 {
            return bad("rollout_steps", "must be positive");
        }
        if self.minibatches == 0 || self.minibatches > self.batch_size() {
            return bad("minibatches", "must be between 1 and envs × rollout_steps");
        }
        if self.epochs == 0 {
            return bad("epochs", "must be positive");
        }
        if self.learning_rate.partial_cmp(&0.0) != Some(std::cmp::Ordering::Greater) {
            return bad("learning_rate", "must be positive");
        }
        if !(0.0..=1.0).contains(&self.gamma) {
            return bad("gamma", "must lie in [0, 1]");
        }
        if !(0.0..=1.0).contains(&self.gae_lambda) {
            return bad("gae_lambda", "must lie in [0, 1]");
        }
        if self.clip.partial_cmp(&0.0) != Some(std::cmp::Ordering::Greater) {
            return bad("clip", "must be positive");
        }
        if self.log_std_min.partial_cmp(&self.log_std_max) != Some(std::cmp::Ordering::Less) {
            return bad("log_std_min", "must be below log_std_max");
        }
        Ok(())
    }
}

/// The Burn CPU backend training runs on (shared with the other learned crates).
pub use emg_learning::Backend;
