//! PPO in Burn (SPEC §5): rollouts by the plain-Rust policy over a [`VecEnv`], GAE, the clipped
//! surrogate, the clipped value loss, an entropy bonus, minibatch epochs with a target-KL early
//! stop, return normalisation, linear learning-rate annealing and gradient-norm clipping;
//! checkpoints with exact resume.
//!
//! Every random choice of iteration `k` comes from its own ChaCha stream of the configured seed,
//! and the in-flight episodes are stored as replayable records, so a run resumed from a
//! checkpoint continues the very same learning curve.

use std::path::Path;
use std::time::Instant;

use burn::grad_clipping::GradientClippingConfig;
use burn::optim::{AdamConfig, GradientsParams};
use burn::tensor::{Device, Tensor, TensorData};
use emg_learning::checkpoint;
use rand::SeedableRng;
use rand::seq::SliceRandom;
use rand_chacha::ChaCha8Rng;
use serde::{Deserialize, Serialize};

use crate::advantage::{ReturnScaler, generalised_advantages};
use crate::config::{Backend, NetworkConfig, PpoConfig};
use crate::error::PolicyError;
use crate::inference::PlainPolicy;
use crate::network::ActorCritic;

use crate::vec_env::{Environment, HALF_LN_TWO_PI, MAX_ENVS, Rollout, VecEnv, VecEnvSnapshot};
use crate::weights::PolicyWeights;

/// One row of the learning curve (identical for a resumed run).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct IterationLog {
    /// Iterations done (1-based).
    pub iteration: u64,
    /// Environment steps done.
    pub env_steps: u64,
    /// Episodes that ended during this iteration's rollout.
    pub episodes: usize,
    /// Their mean undiscounted return (`None` when none ended).
    pub mean_return: Option<f64>,
    /// Their mean score (path length, m, for the arm).
    pub mean_score: Option<f64>,
    /// Mean clipped-surrogate loss of the last epoch run.
    pub policy_loss: f64,
    /// Mean clipped value loss of the last epoch run.
    pub value_loss: f64,
    /// Mean Gaussian entropy of the last epoch run.
    pub entropy: f64,
    /// Approximate KL of the last minibatch.
    pub approx_kl: f64,
    /// Epochs run before the target-KL stop (or all).
    pub epochs: usize,
    /// Learning rate of the iteration.
    pub learning_rate: f64,
}

/// Wall time of one iteration (not part of the reproducible curve).
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct IterationTiming {
    /// Seconds collecting the rollout.
    pub collect_s: f64,
    /// Seconds in the PPO update.
    pub update_s: f64,
}

/// What a checkpoint's `state.json` holds besides the tensors.
#[derive(Clone, Debug, Serialize, Deserialize)]
struct CheckpointState {
    network: NetworkConfig,
    ppo: PpoConfig,
    iteration: u64,
    scaler: ReturnScaler,
    log: Vec<IterationLog>,
    timing: Vec<IterationTiming>,
    envs: VecEnvSnapshot,
}

/// The training state: Burn actor-critic and Adam on an autodiff device, return statistics and
/// the learning curve.
pub struct Trainer {
    network: NetworkConfig,
    ppo: PpoConfig,
    device: Device,
    model: ActorCritic,
    optimizer: burn::optim::ModuleOptimizer,
    iteration: u64,
    scaler: ReturnScaler,
    log: Vec<IterationLog>,
    timing: Vec<IterationTiming>,
    rollout: Rollout,
}

/// Serialises seeded weight initialisation across the process.
static INITIALISATION: std::sync::Mutex<()> = std::sync::Mutex::new(());

fn optimizer(ppo: &PpoConfig) -> burn::optim::ModuleOptimizer {
    AdamConfig::new()
        .with_epsilon(ppo.adam_epsilon as f32)
        .with_grad_clipping(Some(GradientClippingConfig::Norm(
            ppo.grad_clip_norm as f32,
        )))
        .init()
}

impl Trainer {
    /// A fresh run on `backend` (weights initialised from `ppo.seed`).
    pub fn new(
        network: NetworkConfig,
        ppo: PpoConfig,
        backend: Backend,
    ) -> Result<Self, PolicyError> {
        ppo.validate()?;
        if ppo.envs > MAX_ENVS {
            return Err(PolicyError::BadConfig {
                field: "envs",
                problem: format!("must be at most {MAX_ENVS}"),
            });
        }
        if let Some(i) = network.hidden.iter().position(|&w| w == 0) {
            return Err(PolicyError::BadConfig {
                field: "hidden",
                problem: format!("layer {i} has width 0"),
            });
        }
        let device = backend.device().autodiff();
        let model = {
            // The device's generator is shared by the process: seed, initialise and materialise
            // the lazily initialised parameters without another trainer drawing in between.
            let _guard = INITIALISATION.lock().unwrap_or_else(|e| e.into_inner());
            device.seed(ppo.seed);
            let model = ActorCritic::new(&network, ppo.log_std_bias, &device);
            PolicyWeights::from_model(&model, &network, (ppo.log_std_min, ppo.log_std_max), 0);
            model
        };
        Ok(Self {
            optimizer: optimizer(&ppo),
            network,
            ppo,
            device,
            model,
            iteration: 0,
            scaler: ReturnScaler::default(),
            log: Vec::new(),
            timing: Vec::new(),
            rollout: Rollout::default(),
        })
    }

    /// The environments of a fresh run, their first episodes drawn from `ppo.seed`.
    pub fn start_envs<E: Environment>(&self, envs: Vec<E>) -> Result<VecEnv<E>, PolicyError> {
        self.check_env_count(envs.len())?;
        Ok(VecEnv::new(envs, self.ppo.seed))
    }

    /// Resumes the run saved in `dir`, rebuilding its in-flight episodes in `envs`; fails with a
    /// clear error when the checkpoint was made with other settings.
    pub fn resume<E: Environment>(
        dir: &Path,
        network: NetworkConfig,
        ppo: PpoConfig,
        backend: Backend,
        envs: Vec<E>,
    ) -> Result<(Self, VecEnv<E>), PolicyError> {
        let state: CheckpointState = checkpoint::read_state(dir)?;
        if state.network != network {
            return Err(PolicyError::ConfigMismatch {
                what: "network config",
            });
        }
        let comparable = PpoConfig {
            total_env_steps: state.ppo.total_env_steps,
            ..ppo.clone()
        };
        if comparable != state.ppo {
            return Err(PolicyError::ConfigMismatch { what: "PPO config" });
        }
        let mut trainer = Self::new(network, state.ppo.clone(), backend)?;
        trainer.check_env_count(envs.len())?;
        (trainer.model, trainer.optimizer) =
            checkpoint::read_training(dir, trainer.model, optimizer(&trainer.ppo))?;
        trainer.iteration = state.iteration;
        trainer.scaler = state.scaler;
        trainer.log = state.log;
        trainer.timing = state.timing;
        let envs = VecEnv::restore(envs, &state.envs)?;
        Ok((trainer, envs))
    }

    /// Writes a checkpoint into `dir` (built beside it and swapped in, so a stop mid-write keeps
    /// the previous checkpoint).
    pub fn save_checkpoint<E: Environment>(
        &self,
        dir: &Path,
        envs: &VecEnv<E>,
    ) -> Result<(), PolicyError> {
        let staging = checkpoint::stage(dir)?;
        checkpoint::write_training(&staging, &self.model, &self.optimizer)?;
        let state = CheckpointState {
            network: self.network.clone(),
            ppo: self.ppo.clone(),
            iteration: self.iteration,
            scaler: self.scaler.clone(),
            log: self.log.clone(),
            timing: self.timing.clone(),
            envs: envs.snapshot(),
        };
        checkpoint::write_state(&staging, &state)?;
        Ok(checkpoint::publish(dir)?)
    }

    /// Iterations done.
    pub fn iteration(&self) -> u64 {
        self.iteration
    }

    /// Whether the configured step budget is spent.
    pub fn is_done(&self) -> bool {
        self.iteration >= self.ppo.iterations()
    }

    /// The PPO settings.
    pub fn ppo(&self) -> &PpoConfig {
        &self.ppo
    }

    /// The learning curve so far.
    pub fn log(&self) -> &[IterationLog] {
        &self.log
    }

    /// Wall time of every iteration so far.
    pub fn timing(&self) -> &[IterationTiming] {
        &self.timing
    }

    /// The current weights.
    pub fn weights(&self) -> PolicyWeights {
        PolicyWeights::from_model(
            &self.model,
            &self.network,
            (self.ppo.log_std_min, self.ppo.log_std_max),
            self.iteration * self.ppo.batch_size() as u64,
        )
    }

    /// One iteration: a rollout of `envs` by the current policy, then the PPO update.
    pub fn iterate<E: Environment>(
        &mut self,
        envs: &mut VecEnv<E>,
    ) -> Result<&IterationLog, PolicyError> {
        self.check_env_count(envs.len())?;
        let started = Instant::now();
        let policy = PlainPolicy::new(&self.weights());
        let mut rollout = std::mem::take(&mut self.rollout);
        envs.collect(
            &policy,
            self.ppo.seed,
            self.iteration,
            self.ppo.rollout_steps,
            &mut rollout,
        );
        let collect_s = started.elapsed().as_secs_f64();

        let started = Instant::now();
        let ppo = self.ppo.clone();
        let scale = self.scaler.update(&rollout, ppo.gamma);
        let targets = generalised_advantages(&rollout, scale, ppo.gamma, ppo.gae_lambda);
        let learning_rate =
            ppo.learning_rate * (1.0 - self.iteration as f64 / ppo.iterations() as f64);
        let batch = rollout.len();
        let minibatch = batch / ppo.minibatches;
        let mut order: Vec<usize> = (0..batch).collect();
        let mut rng = ChaCha8Rng::seed_from_u64(ppo.seed);
        rng.set_stream(self.iteration + 1);
        let mut stats = UpdateStats::default();
        let mut epochs = 0;
        'epochs: for _ in 0..ppo.epochs {
            epochs += 1;
            order.shuffle(&mut rng);
            stats = UpdateStats::default();
            for indices in order.chunks_exact(minibatch) {
                let inputs = self.minibatch(&rollout, &targets, indices);
                let (loss, step) = self.loss(inputs);
                let gradients = GradientsParams::from_grads(loss.backward(), &self.model);
                self.model = self
                    .optimizer
                    .step(learning_rate, self.model.clone(), gradients);
                stats.add(&step);
                if step.approx_kl > ppo.target_kl {
                    break 'epochs;
                }
            }
        }
        self.iteration += 1;
        let (returns, scores): (Vec<f64>, Vec<f64>) = rollout.finished.iter().copied().unzip();
        let mean = |v: &[f64]| (!v.is_empty()).then(|| v.iter().sum::<f64>() / v.len() as f64);
        let count = stats.minibatches.max(1) as f64;
        self.log.push(IterationLog {
            iteration: self.iteration,
            env_steps: self.iteration * ppo.batch_size() as u64,
            episodes: returns.len(),
            mean_return: mean(&returns),
            mean_score: mean(&scores),
            policy_loss: stats.policy_loss / count,
            value_loss: stats.value_loss / count,
            entropy: stats.entropy / count,
            approx_kl: stats.last_kl,
            epochs,
            learning_rate,
        });
        self.timing.push(IterationTiming {
            collect_s,
            update_s: started.elapsed().as_secs_f64(),
        });
        self.rollout = rollout;
        Ok(self.log.last().expect("just pushed"))
    }

    fn check_env_count(&self, count: usize) -> Result<(), PolicyError> {
        if count != self.ppo.envs {
            return Err(PolicyError::BadConfig {
                field: "envs",
                problem: format!(
                    "the PPO config asks for {} environments, {count} were given",
                    self.ppo.envs
                ),
            });
        }
        Ok(())
    }

    /// Gathers the rows `indices` onto the device (advantages normalised within the minibatch).
    fn minibatch(
        &self,
        rollout: &Rollout,
        targets: &crate::advantage::Targets,
        indices: &[usize],
    ) -> Minibatch {
        let b = indices.len();
        let rows = |values: &[f32], width: usize| {
            let mut out = Vec::with_capacity(b * width);
            for &i in indices {
                out.extend_from_slice(&values[i * width..(i + 1) * width]);
            }
            out
        };
        let mut advantages = rows(&targets.advantages, 1);
        let mean = advantages.iter().map(|&a| f64::from(a)).sum::<f64>() / b as f64;
        let var = advantages
            .iter()
            .map(|&a| (f64::from(a) - mean).powi(2))
            .sum::<f64>()
            / b as f64;
        let inv_std = 1.0 / (var.sqrt() + 1e-8);
        for a in &mut advantages {
            *a = ((f64::from(*a) - mean) * inv_std) as f32;
        }
        let matrix = |values: Vec<f32>, width| {
            Tensor::from_data(TensorData::new(values, [b, width]), &self.device)
        };
        let vector =
            |values: Vec<f32>| Tensor::from_data(TensorData::new(values, [b]), &self.device);
        let dims = rollout.dims.expect("a collected rollout");
        Minibatch {
            observations: matrix(
                rows(&rollout.observations, dims.observation),
                dims.observation,
            ),
            samples: matrix(rows(&rollout.samples, dims.action), dims.action),
            old_log_probs: vector(rows(&rollout.log_probs, 1)),
            old_values: vector(rows(&rollout.values, 1)),
            advantages: vector(advantages),
            returns: vector(rows(&targets.returns, 1)),
        }
    }

    /// The PPO loss `−L_clip + c_v L_V − c_e H` of one minibatch and its statistics.
    fn loss(&self, batch: Minibatch) -> (Tensor<1>, StepStats) {
        let ppo = &self.ppo;
        let [b, _] = batch.observations.dims();
        let output = self.model.policy(
            batch.observations.clone(),
            (ppo.log_std_min, ppo.log_std_max),
        );
        let z = (batch.samples - output.mean) / output.log_std.clone().exp();
        let log_probs = (z.square().mul_scalar(-0.5) - output.log_std.clone())
            .sub_scalar(HALF_LN_TWO_PI)
            .sum_dim(1)
            .reshape([b]);
        let log_ratio = log_probs - batch.old_log_probs;
        let ratio = log_ratio.clone().exp();
        let unclipped = ratio.clone() * batch.advantages.clone();
        let clipped = ratio.clone().clamp(1.0 - ppo.clip, 1.0 + ppo.clip) * batch.advantages;
        let policy_loss = unclipped.min_pair(clipped).mean().neg();

        let values = self.model.value(batch.observations);
        let values_clipped = batch.old_values.clone()
            + (values.clone() - batch.old_values).clamp(-ppo.clip, ppo.clip);
        let value_loss = (values - batch.returns.clone())
            .square()
            .max_pair((values_clipped - batch.returns).square())
            .mean()
            .mul_scalar(0.5);
        let entropy = output
            .log_std
            .add_scalar(0.5 + HALF_LN_TWO_PI)
            .sum_dim(1)
            .mean();
        let approx_kl = (ratio.sub_scalar(1.0) - log_ratio).mean();

        let loss = policy_loss.clone() + value_loss.clone().mul_scalar(ppo.value_coefficient)
            - entropy.clone().mul_scalar(ppo.entropy_coefficient);
        let scalar = |t: Tensor<1>| f64::from(t.into_scalar::<f32>());
        let stats = StepStats {
            policy_loss: scalar(policy_loss.detach()),
            value_loss: scalar(value_loss.detach()),
            entropy: scalar(entropy.detach()),
            approx_kl: scalar(approx_kl.detach()),
        };
        (loss, stats)
    }
}

/// One minibatch on the training device.
struct Minibatch {
    observations: Tensor<2>,
    samples: Tensor<2>,
    old_log_probs: Tensor<1>,
    old_values: Tensor<1>,
    advantages: Tensor<1>,
    returns: Tensor<1>,
}

/// Statistics of one minibatch step.
struct StepStats {
    policy_loss: f64,
    value_loss: f64,
    entropy: f64,
    approx_kl: f64,
}

/// Sums over the minibatches of one epoch.
#[derive(Default)]
struct UpdateStats {
    minibatches: usize,
    policy_loss: f64,
    value_loss: f64,
    entropy: f64,
    last_kl: f64,
}

impl UpdateStats {
    fn add(&mut self, step: &StepStats) {
        self.minibatches += 1;
        self.policy_loss += step.policy_loss;
        self.value_loss += step.value_loss;
        self.entropy += step.entropy;
        self.last_kl = step.approx_kl;
    }
}
