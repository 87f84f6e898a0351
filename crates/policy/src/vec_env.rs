//! Many environments stepped in parallel with rayon by the sampling policy, filling one PPO
//! rollout; each environment's randomness comes from its own ChaCha stream, so a rollout does not
//! depend on the number of threads, and each in-flight episode is recorded as (reset seed,
//! actions) so a checkpoint can rebuild it exactly by replay.

use emg_learning::StandardNormal;
use rand::{RngExt, SeedableRng};
use rand_chacha::ChaCha8Rng;
use rayon::prelude::*;
use serde::{Deserialize, Serialize};

use crate::error::PolicyError;
use crate::inference::PlainPolicy;
use crate::observation::{ACTION_DIM, OBSERVATION_DIM, PolicyDims};

/// How an episode ended at a step.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum EpisodeEnd {
    /// A constraint broke (no bootstrap: the episode's value is what it earned).
    Terminated,
    /// The step cap was reached; the value of the final state is bootstrapped, and
    /// [`Environment::observe`] still shows that final state.
    Truncated,
}

/// What one step returned.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Transition {
    /// Reward of the step.
    pub reward: f64,
    /// `Some` when the episode ended with this step.
    pub end: Option<EpisodeEnd>,
}

/// One episodic environment with the policy's observation and action sizes.
pub trait Environment: Send {
    /// Starts a new episode; every random choice comes from `rng`.
    fn reset(&mut self, rng: &mut ChaCha8Rng);

    /// The current observation (after a truncation: the final state's).
    fn observe(&self, out: &mut [f32; OBSERVATION_DIM]);

    /// Applies `action ∈ (−1, 1)ⁿ⁻³` (the entries past the action's length are zero).
    fn step(&mut self, action: &[f32; ACTION_DIM]) -> Transition;

    /// The environment's measure of the current episode so far (for the arm: path length, m).
    fn score(&self) -> f64;
}

/// `ln √(2π)`, the per-dimension constant of a Gaussian log-density.
pub(crate) const HALF_LN_TWO_PI: f32 = 0.918_938_5;

/// Samples of one rollout, stored environment-major (`[env][step]`).
#[derive(Clone, Debug, Default)]
pub struct Rollout {
    /// Steps per environment.
    pub steps: usize,
    /// The policy's observation and action lengths (the rows below).
    pub dims: Option<PolicyDims>,
    /// Observations, `[N·T, observation length]`.
    pub observations: Vec<f32>,
    /// Pre-squash Gaussian samples `u` (the action is `tanh(u)`), `[N·T, action length]`.
    pub samples: Vec<f32>,
    /// Gaussian log-density of `u` under the sampling policy, `[N·T]`.
    pub log_probs: Vec<f32>,
    /// Critic values of the observations, `[N·T]`.
    pub values: Vec<f32>,
    /// Raw rewards, `[N·T]`.
    pub rewards: Vec<f32>,
    /// How each step ended its episode, `[N·T]`.
    pub ends: Vec<Option<EpisodeEnd>>,
    /// Critic value of the final state after a truncation (0 elsewhere), `[N·T]`.
    pub truncation_values: Vec<f32>,
    /// Critic value of each environment's state after the rollout, `[N]`.
    pub last_values: Vec<f32>,
    /// `(return, score)` of every episode that ended, in environment then step order.
    pub finished: Vec<(f64, f64)>,
}

impl Rollout {
    fn resize(&mut self, envs: usize, steps: usize, dims: PolicyDims) {
        let n = envs * steps;
        self.steps = steps;
        self.dims = Some(dims);
        self.observations.resize(n * dims.observation, 0.0);
        self.samples.resize(n * dims.action, 0.0);
        self.log_probs.resize(n, 0.0);
        self.values.resize(n, 0.0);
        self.rewards.resize(n, 0.0);
        self.ends.resize(n, None);
        self.truncation_values.resize(n, 0.0);
        self.last_values.resize(envs, 0.0);
        self.finished.clear();
    }

    /// Samples held.
    pub fn len(&self) -> usize {
        self.log_probs.len()
    }

    /// Whether the rollout holds no samples.
    pub fn is_empty(&self) -> bool {
        self.log_probs.is_empty()
    }
}

/// One environment with the record that rebuilds its in-flight episode.
struct Slot<E> {
    env: E,
    reset_seed: u64,
    actions: Vec<[f32; ACTION_DIM]>,
    episode_return: f64,
}

/// The in-flight episodes of a [`VecEnv`], enough to rebuild them exactly (floats as bits).
#[derive(Clone, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub struct VecEnvSnapshot {
    /// Per environment: the reset seed of its episode.
    pub reset_seeds: Vec<u64>,
    /// Per environment: the actions applied since the reset (`f32::to_bits`).
    pub actions: Vec<Vec<[u32; ACTION_DIM]>>,
    /// Per environment: the return earned so far (`f64::to_bits`).
    pub episode_returns: Vec<u64>,
}

/// Environments stepped together.
pub struct VecEnv<E> {
    slots: Vec<Slot<E>>,
}

impl<E: Environment> VecEnv<E> {
    /// Starts every environment's first episode from streams of `seed`.
    pub fn new(envs: Vec<E>, seed: u64) -> Self {
        let mut slots: Vec<Slot<E>> = envs
            .into_iter()
            .map(|env| Slot {
                env,
                reset_seed: 0,
                actions: Vec::new(),
                episode_return: 0.0,
            })
            .collect();
        slots.par_iter_mut().enumerate().for_each(|(i, slot)| {
            let mut rng = stream(seed, 0, i);
            slot.reset_seed = rng.random();
            slot.env
                .reset(&mut ChaCha8Rng::seed_from_u64(slot.reset_seed));
        });
        Self { slots }
    }

    /// Rebuilds the in-flight episodes of `snapshot` by replaying their actions.
    pub fn restore(envs: Vec<E>, snapshot: &VecEnvSnapshot) -> Result<Self, PolicyError> {
        let n = envs.len();
        if [
            snapshot.reset_seeds.len(),
            snapshot.actions.len(),
            snapshot.episode_returns.len(),
        ]
        .iter()
        .any(|&len| len != n)
        {
            return Err(PolicyError::BadConfig {
                field: "envs",
                problem: format!(
                    "the checkpoint holds a different number of environments than the {n} given"
                ),
            });
        }
        let mut slots: Vec<Slot<E>> = envs
            .into_iter()
            .enumerate()
            .map(|(i, env)| Slot {
                env,
                reset_seed: snapshot.reset_seeds[i],
                actions: snapshot.actions[i]
                    .iter()
                    .map(|a| a.map(f32::from_bits))
                    .collect(),
                episode_return: f64::from_bits(snapshot.episode_returns[i]),
            })
            .collect();
        slots.par_iter_mut().for_each(|slot| {
            slot.env
                .reset(&mut ChaCha8Rng::seed_from_u64(slot.reset_seed));
            for action in &slot.actions {
                slot.env.step(action);
            }
        });
        Ok(Self { slots })
    }

    /// The record that [`VecEnv::restore`] rebuilds these episodes from.
    pub fn snapshot(&self) -> VecEnvSnapshot {
        VecEnvSnapshot {
            reset_seeds: self.slots.iter().map(|s| s.reset_seed).collect(),
            actions: self
                .slots
                .iter()
                .map(|s| s.actions.iter().map(|a| a.map(f32::to_bits)).collect())
                .collect(),
            episode_returns: self
                .slots
                .iter()
                .map(|s| s.episode_return.to_bits())
                .collect(),
        }
    }

    /// Number of environments.
    pub fn len(&self) -> usize {
        self.slots.len()
    }

    /// Whether there are no environments.
    pub fn is_empty(&self) -> bool {
        self.slots.is_empty()
    }

    /// Steps every environment `steps` times with actions `tanh(u)`, `u ~ N(μ, σ²)` sampled from
    /// `policy` (stream `(seed, iteration, env)`), writing into `rollout`; finished episodes are
    /// restarted at once.
    pub fn collect(
        &mut self,
        policy: &PlainPolicy,
        seed: u64,
        iteration: u64,
        steps: usize,
        rollout: &mut Rollout,
    ) {
        let dims = policy.dims();
        rollout.resize(self.slots.len(), steps, dims);
        let finished: Vec<Vec<(f64, f64)>> = self
            .slots
            .par_iter_mut()
            .zip(
                rollout
                    .observations
                    .par_chunks_mut(steps * dims.observation),
            )
            .zip(rollout.samples.par_chunks_mut(steps * dims.action))
            .zip(rollout.log_probs.par_chunks_mut(steps))
            .zip(rollout.values.par_chunks_mut(steps))
            .zip(rollout.rewards.par_chunks_mut(steps))
            .zip(rollout.ends.par_chunks_mut(steps))
            .zip(rollout.truncation_values.par_chunks_mut(steps))
            .zip(rollout.last_values.par_iter_mut())
            .enumerate()
            .map_init(
                || policy.scratch(),
                |scratch,
                 (
                    i,
                    (
                        (
                            ((((((slot, obs), samples), log_probs), values), rewards), ends),
                            truncation,
                        ),
                        last,
                    ),
                )| {
                    let mut rng = stream(seed, iteration + 1, i);
                    let mut finished = Vec::new();
                    for t in 0..steps {
                        let mut observation = [0.0; OBSERVATION_DIM];
                        slot.env.observe(&mut observation);
                        obs[t * dims.observation..(t + 1) * dims.observation]
                            .copy_from_slice(&observation[..dims.observation]);
                        let output = policy.actor(&observation, scratch);
                        values[t] = policy.value(&observation, scratch);
                        let mut action = [0.0f32; ACTION_DIM];
                        let mut log_prob = 0.0;
                        for k in 0..dims.action {
                            let noise: f32 = rng.sample(StandardNormal);
                            let u = output.mean[k] + libm::expf(output.log_std[k]) * noise;
                            samples[t * dims.action + k] = u;
                            action[k] = libm::tanhf(u);
                            log_prob += -0.5 * noise * noise - output.log_std[k] - HALF_LN_TWO_PI;
                        }
                        log_probs[t] = log_prob;
                        let transition = slot.env.step(&action);
                        slot.actions.push(action);
                        slot.episode_return += transition.reward;
                        rewards[t] = transition.reward as f32;
                        ends[t] = transition.end;
                        truncation[t] = 0.0;
                        if let Some(end) = transition.end {
                            if end == EpisodeEnd::Truncated {
                                let mut final_observation = [0.0; OBSERVATION_DIM];
                                slot.env.observe(&mut final_observation);
                                truncation[t] = policy.value(&final_observation, scratch);
                            }
                            finished.push((slot.episode_return, slot.env.score()));
                            slot.reset_seed = rng.random();
                            slot.env
                                .reset(&mut ChaCha8Rng::seed_from_u64(slot.reset_seed));
                            slot.actions.clear();
                            slot.episode_return = 0.0;
                        }
                    }
                    let mut observation = [0.0; OBSERVATION_DIM];
                    slot.env.observe(&mut observation);
                    *last = policy.value(&observation, scratch);
                    finished
                },
            )
            .collect();
        rollout.finished = finished.into_iter().flatten().collect();
    }
}

/// Most environments one [`VecEnv`] steps (their index fills the low bits of a stream id).
pub const MAX_ENVS: usize = 1 << 20;

/// The ChaCha stream of environment `env` in phase `phase` (0: the first resets, `k + 1`: the
/// rollout of iteration `k`).
fn stream(seed: u64, phase: u64, env: usize) -> ChaCha8Rng {
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    rng.set_stream((phase << 20) | env as u64);
    rng
}
