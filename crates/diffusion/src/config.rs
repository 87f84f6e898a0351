//! Serde configurations of the denoiser, its training and its sampling (SPEC §6 defaults).

use serde::{Deserialize, Serialize};

/// Shape of the residual-MLP denoiser `v_θ(x_t, t, c)` (SPEC §6).
///
/// The defaults are the paper's network (width 256, four residual blocks of 1024); the shipped
/// model records the (smaller) shape it was trained with in its weights file.
#[derive(Clone, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct DiffusionConfig {
    /// Dimension of the sample `x` (7: `q` normalised to `[−1, 1]` by the joint limits).
    pub data_dim: usize,
    /// Dimension of the condition `c` (9: `[p0, d, n]`).
    pub condition_dim: usize,
    /// Width of the residual stream (256).
    pub width: usize,
    /// Hidden width inside each residual block (1024).
    pub hidden: usize,
    /// Number of residual blocks (4).
    pub blocks: usize,
    /// Length of the sinusoidal time embedding (256); its MLP is `time_dim → 2·width → width`.
    pub time_dim: usize,
    /// Diffusion length `T` (1000).
    pub timesteps: usize,
}

impl Default for DiffusionConfig {
    fn default() -> Self {
        Self {
            data_dim: 7,
            condition_dim: 9,
            width: 256,
            hidden: 1024,
            blocks: 4,
            time_dim: 256,
            timesteps: 1000,
        }
    }
}

/// Hyper-parameters of [`crate::Trainer`] (SPEC §6).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct TrainConfig {
    /// Seed of every random choice (initial weights, batches, noise, dropout, guidance drops).
    pub seed: u64,
    /// Optimiser steps of a full run.
    pub steps: usize,
    /// Samples per step.
    pub batch_size: usize,
    /// AdamW learning rate (2e-4).
    pub learning_rate: f64,
    /// AdamW weight decay (1e-4).
    pub weight_decay: f64,
    /// Gradient norm clip (1.0).
    pub grad_clip_norm: f64,
    /// EMA decay of the sampling weights (0.9995).
    pub ema_decay: f64,
    /// Probability that the condition is replaced by the learnable null condition (`p_drop` = 0.1).
    pub condition_drop_probability: f64,
    /// Dropout inside the residual blocks (0.1).
    pub dropout: f64,
    /// Probability of the mirror augmentation (0.5); applied only when the data set has a mirror.
    pub mirror_probability: f64,
    /// Steps between checkpoints.
    pub checkpoint_every_steps: usize,
    /// Steps averaged into one row of the loss log.
    pub log_every_steps: usize,
}

impl Default for TrainConfig {
    fn default() -> Self {
        Self {
            seed: 0,
            steps: 100_000,
            batch_size: 256,
            learning_rate: 2e-4,
            weight_decay: 1e-4,
            grad_clip_norm: 1.0,
            ema_decay: 0.9995,
            condition_drop_probability: 0.1,
            dropout: 0.1,
            mirror_probability: 0.5,
            checkpoint_every_steps: 2_000,
            log_every_steps: 100,
        }
    }
}

/// DDIM (η = 0) sampling settings (SPEC §6).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct SampleConfig {
    /// Denoising steps, 1 ≤ steps ≤ T (50).
    pub steps: usize,
    /// Classifier-free guidance scale `w` of Eq. 5 (1.5); 0 ignores the condition.
    pub guidance_scale: f64,
    /// Bound on the predicted `x0` at every step (1.2).
    pub x0_clip: f64,
}

impl Default for SampleConfig {
    fn default() -> Self {
        Self {
            steps: 50,
            guidance_scale: 1.5,
            x0_clip: 1.2,
        }
    }
}

/// The Burn CPU backend training runs on (shared with the other learned crates).
pub use emg_learning::Backend;
