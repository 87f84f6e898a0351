//! Reward scaling by the running standard deviation of the discounted return, and generalised
//! advantage estimation with bootstrapping at truncations (SPEC §5).

use serde::{Deserialize, Serialize};

use crate::vec_env::{EpisodeEnd, Rollout};

/// Running mean and variance (Chan et al.'s parallel update), floats kept as bits so that a
/// checkpoint restores them exactly.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
pub struct RunningMoments {
    count: u64,
    mean_bits: u64,
    m2_bits: u64,
}

impl RunningMoments {
    /// Adds a batch of values.
    pub fn update(&mut self, values: &[f64]) {
        if values.is_empty() {
            return;
        }
        let n = values.len() as f64;
        let batch_mean = values.iter().sum::<f64>() / n;
        let batch_m2: f64 = values.iter().map(|v| (v - batch_mean).powi(2)).sum();
        let count = self.count as f64;
        let mean = f64::from_bits(self.mean_bits);
        let total = count + n;
        let delta = batch_mean - mean;
        let m2 = f64::from_bits(self.m2_bits) + batch_m2 + delta * delta * count * n / total;
        self.count += values.len() as u64;
        self.mean_bits = (mean + delta * n / total).to_bits();
        self.m2_bits = m2.to_bits();
    }

    /// The (population) standard deviation so far; 1 before any value.
    pub fn std(&self) -> f64 {
        if self.count == 0 {
            return 1.0;
        }
        (f64::from_bits(self.m2_bits) / self.count as f64).sqrt()
    }
}

/// Per-environment discounted returns `R ← γR + r` (reset at episode ends), whose running
/// standard deviation scales the rewards.
#[derive(Clone, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
pub struct ReturnScaler {
    /// Per environment: the discounted return so far (`f64::to_bits`).
    returns: Vec<u64>,
    moments: RunningMoments,
}

impl ReturnScaler {
    /// Folds the rollout's rewards into the statistics and returns the scale `1/σ` to apply
    /// to them (σ floored at 1e-4).
    pub fn update(&mut self, rollout: &Rollout, gamma: f64) -> f64 {
        let envs = rollout.last_values.len();
        self.returns.resize(envs, 0f64.to_bits());
        let mut seen = Vec::with_capacity(rollout.len());
        for (env, bits) in self.returns.iter_mut().enumerate() {
            let mut ret = f64::from_bits(*bits);
            for t in 0..rollout.steps {
                let i = env * rollout.steps + t;
                ret = gamma * ret + f64::from(rollout.rewards[i]);
                seen.push(ret);
                if rollout.ends[i].is_some() {
                    ret = 0.0;
                }
            }
            *bits = ret.to_bits();
        }
        self.moments.update(&seen);
        1.0 / self.moments.std().max(1e-4)
    }
}

/// Advantages and value targets of a rollout.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Targets {
    /// GAE advantages `Â_t`.
    pub advantages: Vec<f32>,
    /// Value targets `Â_t + V(o_t)`.
    pub returns: Vec<f32>,
}

/// GAE(γ, λ) over a rollout with rewards multiplied by `reward_scale`; a truncated step adds
/// `γ V(final state)` to its reward and, like a termination, cuts the recursion.
pub fn generalised_advantages(
    rollout: &Rollout,
    reward_scale: f64,
    gamma: f64,
    lambda: f64,
) -> Targets {
    let n = rollout.len();
    let steps = rollout.steps;
    let mut advantages = vec![0.0f32; n];
    for env in 0..rollout.last_values.len() {
        let mut next_value = f64::from(rollout.last_values[env]);
        let mut next_advantage = 0.0f64;
        for t in (0..steps).rev() {
            let i = env * steps + t;
            let mut reward = f64::from(rollout.rewards[i]) * reward_scale;
            let continues = match rollout.ends[i] {
                None => 1.0,
                Some(EpisodeEnd::Terminated) => 0.0,
                Some(EpisodeEnd::Truncated) => {
                    reward += gamma * f64::from(rollout.truncation_values[i]);
                    0.0
                }
            };
            let value = f64::from(rollout.values[i]);
            let delta = reward + gamma * next_value * continues - value;
            next_advantage = delta + gamma * lambda * continues * next_advantage;
            advantages[i] = next_advantage as f32;
            next_value = value;
        }
    }
    let returns = advantages
        .iter()
        .zip(&rollout.values)
        .map(|(a, v)| a + v)
        .collect();
    Targets {
        advantages,
        returns,
    }
}
