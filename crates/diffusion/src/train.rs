//! Training of the denoiser in Burn: v-prediction MSE, classifier-free guidance dropout, mirror
//! augmentation, AdamW with gradient clipping, EMA weights, checkpoints and exact resume.
//!
//! Every random choice of step `k` comes from its own ChaCha stream of the configured seed, so
//! a run resumed from a checkpoint continues the very same loss curve.

use std::path::Path;

use burn::grad_clipping::GradientClippingConfig;
use burn::module::Module;
use burn::optim::{AdamWConfig, GradientsParams};
use burn::tensor::{Device, Tensor, TensorData};
use emg_learning::StandardNormal;
use emg_learning::checkpoint::{self, CheckpointError};
use rand::{RngExt, SeedableRng};
use rand_chacha::ChaCha8Rng;
use serde::{Deserialize, Serialize};

use crate::config::{Backend, DiffusionConfig, TrainConfig};
use crate::embedding::sinusoidal_embedding;
use crate::model::{Denoiser, DenoiserInput};
use crate::schedule::CosineSchedule;
use crate::weights::{DenoiserWeights, WeightsError};

/// Why training data, a checkpoint or a training configuration is unusable.
#[derive(Debug, thiserror::Error)]
pub enum TrainError {
    /// Training data of the wrong shape.
    #[error("training data field '{field}' {problem}")]
    BadData {
        /// Field.
        field: &'static str,
        /// What is wrong.
        problem: String,
    },
    /// A checkpoint file could not be read or written.
    #[error(transparent)]
    Checkpoint(#[from] CheckpointError),
    /// The EMA weights of a checkpoint are unusable.
    #[error(transparent)]
    Weights(#[from] WeightsError),
    /// A checkpoint made with other settings.
    #[error("checkpoint was made with different {what}; start a new run or restore the settings")]
    ConfigMismatch {
        /// `network config`, `training config` or `data set`.
        what: &'static str,
    },
}

/// A sign flip that maps a training pair onto an equally valid one (an arm's xz-plane symmetry,
/// SPEC §6): condition and sample are multiplied element-wise by these signs.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Mirror {
    /// Signs of the condition components.
    pub condition_signs: Vec<f32>,
    /// Signs of the sample components.
    pub sample_signs: Vec<f32>,
}

/// Pairs `(c, x0)` to train on.
#[derive(Clone, Debug)]
pub struct TrainingSet {
    conditions: Vec<f32>,
    samples: Vec<f32>,
    condition_dim: usize,
    data_dim: usize,
    mirror: Option<Mirror>,
    name: String,
}

impl TrainingSet {
    /// Pairs from row-major `conditions` (`n × condition_dim`) and `samples` (`n × data_dim`);
    /// `name` identifies the data set in checkpoints and weights files.
    pub fn new(
        conditions: Vec<f32>,
        samples: Vec<f32>,
        condition_dim: usize,
        data_dim: usize,
        name: &str,
    ) -> Result<Self, TrainError> {
        let bad = |field, problem: String| Err(TrainError::BadData { field, problem });
        if condition_dim == 0 || data_dim == 0 {
            return bad("dimensions", "must be positive".into());
        }
        if samples.is_empty() || !samples.len().is_multiple_of(data_dim) {
            return bad(
                "samples",
                format!(
                    "has {} values, not a positive multiple of {data_dim}",
                    samples.len()
                ),
            );
        }
        let n = samples.len() / data_dim;
        if conditions.len() != n * condition_dim {
            return bad(
                "conditions",
                format!(
                    "has {} values, expected {} for {n} samples",
                    conditions.len(),
                    n * condition_dim
                ),
            );
        }
        if let Some(i) = conditions
            .iter()
            .chain(&samples)
            .position(|v| !v.is_finite())
        {
            return bad("values", format!("value {i} is not finite"));
        }
        Ok(Self {
            conditions,
            samples,
            condition_dim,
            data_dim,
            mirror: None,
            name: name.to_string(),
        })
    }

    /// Whether the mirror augmentation is on.
    pub fn has_mirror(&self) -> bool {
        self.mirror.is_some()
    }

    /// Adds the mirror augmentation.
    pub fn with_mirror(mut self, mirror: Mirror) -> Result<Self, TrainError> {
        if mirror.condition_signs.len() != self.condition_dim
            || mirror.sample_signs.len() != self.data_dim
        {
            return Err(TrainError::BadData {
                field: "mirror",
                problem: "sign vectors must match the condition and sample dimensions".into(),
            });
        }
        self.mirror = Some(mirror);
        Ok(self)
    }

    /// Number of pairs.
    pub fn len(&self) -> usize {
        self.samples.len() / self.data_dim
    }

    /// Whether there are no pairs.
    pub fn is_empty(&self) -> bool {
        self.samples.is_empty()
    }

    /// The data set's name.
    pub fn name(&self) -> &str {
        &self.name
    }
}

/// One row of the loss log.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct LossRow {
    /// Optimiser steps done at the end of the window.
    pub step: usize,
    /// Mean training loss over the window.
    pub loss: f64,
}

/// What a checkpoint's `state.json` holds besides the tensors.
#[derive(Clone, Debug, Serialize, Deserialize)]
struct CheckpointState {
    network: DiffusionConfig,
    training: TrainConfig,
    dataset: String,
    step: usize,
    log: Vec<LossRow>,
    window_loss_sum: f64,
    window_steps: usize,
}

/// The training state: Burn model and optimiser on an autodiff device, EMA weights, loss log.
pub struct Trainer {
    network: DiffusionConfig,
    training: TrainConfig,
    device: Device,
    model: Denoiser,
    optimizer: burn::optim::ModuleOptimizer,
    ema: DenoiserWeights,
    schedule: CosineSchedule,
    time_table: Vec<f32>,
    dataset: String,
    step: usize,
    log: Vec<LossRow>,
    window_loss_sum: f64,
    window_steps: usize,
}

fn optimizer(training: &TrainConfig) -> burn::optim::ModuleOptimizer {
    AdamWConfig::new()
        .with_weight_decay(training.weight_decay as f32)
        .with_grad_clipping(Some(GradientClippingConfig::Norm(
            training.grad_clip_norm as f32,
        )))
        .init()
}

fn time_table(network: &DiffusionConfig) -> Vec<f32> {
    let mut table = vec![0.0; network.timesteps * network.time_dim];
    for (t, row) in table.chunks_exact_mut(network.time_dim).enumerate() {
        sinusoidal_embedding(t, row);
    }
    table
}

impl Trainer {
    /// A fresh run on `backend` for `data` (weights initialised from `training.seed`).
    pub fn new(
        network: DiffusionConfig,
        training: TrainConfig,
        backend: Backend,
        data: &TrainingSet,
    ) -> Result<Self, TrainError> {
        check_shapes(&network, data)?;
        let device = backend.device().autodiff();
        device.seed(training.seed);
        let model = Denoiser::new(&network, &device);
        let ema = DenoiserWeights::from_model(&model, &network, data.name(), 0);
        Ok(Self {
            schedule: CosineSchedule::new(network.timesteps),
            time_table: time_table(&network),
            optimizer: optimizer(&training),
            dataset: data.name().to_string(),
            network,
            training,
            device,
            model,
            ema,
            step: 0,
            log: Vec::new(),
            window_loss_sum: 0.0,
            window_steps: 0,
        })
    }

    /// Resumes the run saved in checkpoint directory `dir`; fails with a clear error when the
    /// checkpoint was made with other settings or data.
    pub fn resume(
        dir: &Path,
        network: DiffusionConfig,
        training: TrainConfig,
        backend: Backend,
        data: &TrainingSet,
    ) -> Result<Self, TrainError> {
        let state: CheckpointState = checkpoint::read_state(dir)?;
        if state.network != network {
            return Err(TrainError::ConfigMismatch {
                what: "network config",
            });
        }
        if (TrainConfig {
            steps: state.training.steps,
            ..training.clone()
        }) != state.training
        {
            return Err(TrainError::ConfigMismatch {
                what: "training config",
            });
        }
        if state.dataset != data.name() {
            return Err(TrainError::ConfigMismatch { what: "data set" });
        }
        let mut trainer = Self::new(network, training, backend, data)?;
        (trainer.model, trainer.optimizer) =
            checkpoint::read_training(dir, trainer.model, optimizer(&trainer.training))?;
        trainer.ema = DenoiserWeights::read(&dir.join("ema.weights"))?;
        trainer.step = state.step;
        trainer.log = state.log;
        trainer.window_loss_sum = state.window_loss_sum;
        trainer.window_steps = state.window_steps;
        Ok(trainer)
    }

    /// Writes a checkpoint into `dir` (built beside it and swapped in, so a stop mid-write keeps
    /// the previous checkpoint).
    pub fn save_checkpoint(&self, dir: &Path) -> Result<(), TrainError> {
        let staging = checkpoint::stage(dir)?;
        checkpoint::write_training(&staging, &self.model, &self.optimizer)?;
        self.ema.write(&staging.join("ema.weights"))?;
        let state = CheckpointState {
            network: self.network.clone(),
            training: self.training.clone(),
            dataset: self.dataset.clone(),
            step: self.step,
            log: self.log.clone(),
            window_loss_sum: self.window_loss_sum,
            window_steps: self.window_steps,
        };
        checkpoint::write_state(&staging, &state)?;
        Ok(checkpoint::publish(dir)?)
    }

    /// Steps done.
    pub fn step_count(&self) -> usize {
        self.step
    }

    /// The loss log so far (one row per `log_every_steps`).
    pub fn loss_log(&self) -> &[LossRow] {
        &self.log
    }

    /// The EMA weights (what sampling uses).
    pub fn ema_weights(&self) -> &DenoiserWeights {
        &self.ema
    }

    /// The current (non-averaged) weights.
    pub fn current_weights(&self) -> DenoiserWeights {
        DenoiserWeights::from_model(&self.model.valid(), &self.network, &self.dataset, self.step)
    }

    /// One optimiser step on a random batch of `data`; returns its loss.
    pub fn train_step(&mut self, data: &TrainingSet) -> f64 {
        let batch = self.batch(data);
        let target = batch.1;
        let prediction = self.model.forward(batch.0);
        let loss = (prediction - target).square().mean();
        let loss_value = f64::from(
            loss.clone()
                .into_data()
                .as_slice::<f32>()
                .expect("f32 loss")[0],
        );
        let gradients = GradientsParams::from_grads(loss.backward(), &self.model);
        self.model =
            self.optimizer
                .step(self.training.learning_rate, self.model.clone(), gradients);
        self.step += 1;
        self.update_ema();
        self.window_loss_sum += loss_value;
        self.window_steps += 1;
        if self.window_steps >= self.training.log_every_steps.max(1) {
            self.log.push(LossRow {
                step: self.step,
                loss: self.window_loss_sum / self.window_steps as f64,
            });
            self.window_loss_sum = 0.0;
            self.window_steps = 0;
        }
        loss_value
    }

    /// `ema ← d·ema + (1 − d)·θ` with the warm-up `d = min(decay, (1 + k)/(10 + k))`.
    fn update_ema(&mut self) {
        let current =
            DenoiserWeights::from_model(&self.model, &self.network, &self.dataset, self.step);
        let k = self.step as f64;
        let decay = self.training.ema_decay.min((1.0 + k) / (10.0 + k)) as f32;
        for (e, &c) in self.ema.values_mut().iter_mut().zip(current.values()) {
            *e = decay * *e + (1.0 - decay) * c;
        }
        self.ema.set_train_steps(self.step);
    }

    /// The inputs and the target `v = √ᾱ ε − √(1−ᾱ) x0` of step `self.step`'s batch.
    fn batch(&self, data: &TrainingSet) -> (DenoiserInput, Tensor<2>) {
        let net = &self.network;
        let cfg = &self.training;
        let b = cfg.batch_size;
        let (c_dim, d_dim) = (net.condition_dim, net.data_dim);
        let mut rng = ChaCha8Rng::seed_from_u64(cfg.seed);
        rng.set_stream(self.step as u64 + 1);
        let mut noisy = Vec::with_capacity(b * d_dim);
        let mut target = Vec::with_capacity(b * d_dim);
        let mut conditions = Vec::with_capacity(b * c_dim);
        let mut dropped = Vec::with_capacity(b);
        let mut times = Vec::with_capacity(b * net.time_dim);
        for _ in 0..b {
            let i = rng.random_range(0..data.len());
            let mirror = data
                .mirror
                .as_ref()
                .filter(|_| rng.random::<f64>() < cfg.mirror_probability);
            let c = &data.conditions[i * c_dim..(i + 1) * c_dim];
            let x0 = &data.samples[i * d_dim..(i + 1) * d_dim];
            match mirror {
                Some(m) => conditions.extend(c.iter().zip(&m.condition_signs).map(|(v, s)| v * s)),
                None => conditions.extend_from_slice(c),
            }
            let t = rng.random_range(0..net.timesteps);
            let alpha_bar = self.schedule.alpha_bar(t);
            let (signal, noise) = (alpha_bar.sqrt() as f32, (1.0 - alpha_bar).sqrt() as f32);
            for (j, &value) in x0.iter().enumerate() {
                let x = value * mirror.map_or(1.0, |m| m.sample_signs[j]);
                let epsilon: f32 = rng.sample(StandardNormal);
                noisy.push(signal * x + noise * epsilon);
                target.push(signal * epsilon - noise * x);
            }
            times.extend_from_slice(&self.time_table[t * net.time_dim..(t + 1) * net.time_dim]);
            dropped.push(if rng.random::<f64>() < cfg.condition_drop_probability {
                1.0f32
            } else {
                0.0
            });
        }
        let keep = 1.0 - cfg.dropout;
        let dropout_masks = (cfg.dropout > 0.0).then(|| {
            (0..net.blocks)
                .map(|_| {
                    let mask: Vec<f32> = (0..b * net.hidden)
                        .map(|_| {
                            if rng.random::<f64>() < keep {
                                (1.0 / keep) as f32
                            } else {
                                0.0
                            }
                        })
                        .collect();
                    self.tensor(mask, [b, net.hidden])
                })
                .collect()
        });
        let input = DenoiserInput {
            sample: self.tensor(noisy, [b, d_dim]),
            time_embedding: self.tensor(times, [b, net.time_dim]),
            condition: self.tensor(conditions, [b, c_dim]),
            condition_dropped: self.tensor(dropped, [b, 1]),
            dropout_masks,
        };
        (input, self.tensor(target, [b, d_dim]))
    }

    fn tensor(&self, values: Vec<f32>, shape: [usize; 2]) -> Tensor<2> {
        Tensor::from_data(TensorData::new(values, shape), &self.device)
    }
}

fn check_shapes(network: &DiffusionConfig, data: &TrainingSet) -> Result<(), TrainError> {
    if network.condition_dim != data.condition_dim || network.data_dim != data.data_dim {
        return Err(TrainError::BadData {
            field: "dimensions",
            problem: format!(
                "data has condition {} / sample {}, the network expects {} / {}",
                data.condition_dim, data.data_dim, network.condition_dim, network.data_dim
            ),
        });
    }
    if network.condition_dim < 2 {
        return Err(TrainError::BadData {
            field: "condition_dim",
            problem: "must be at least 2: the LayerNorm of a one-component condition is constant"
                .into(),
        });
    }
    if !network.time_dim.is_multiple_of(2) {
        return Err(TrainError::BadData {
            field: "time_dim",
            problem: "must be even".into(),
        });
    }
    Ok(())
}
