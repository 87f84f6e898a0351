//! DDIM (η = 0) sampling with classifier-free guidance (Eq. 5), batched over candidates.

use crate::config::SampleConfig;
use crate::forward::{ForwardScratch, PlainDenoiser};
use crate::schedule::CosineSchedule;
use crate::weights::DenoiserWeights;

/// Why a sampling request is refused.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum SampleError {
    /// `steps` outside `1 … T`.
    #[error("sample config field 'steps' = {steps} must lie in 1..={timesteps}")]
    Steps {
        /// Requested steps.
        steps: usize,
        /// `T`.
        timesteps: usize,
    },
    /// A non-finite guidance scale or clip.
    #[error("sample config field '{field}' = {value} must be finite{extra}")]
    NotFinite {
        /// Field name.
        field: &'static str,
        /// Its value.
        value: f64,
        /// Further requirement.
        extra: &'static str,
    },
    /// Buffer lengths that do not match the network.
    #[error("{what} has {found} values, expected {expected}")]
    Length {
        /// Which argument.
        what: &'static str,
        /// Expected length.
        expected: usize,
        /// Given length.
        found: usize,
    },
}

/// Reusable buffers of [`DdimSampler::sample`].
#[derive(Clone, Debug, Default)]
pub struct SamplerWorkspace {
    rows: Vec<f32>,
    condition_rows: Vec<f32>,
    velocities: Vec<f32>,
    condition: Vec<f32>,
    scratch: ForwardScratch,
}

/// DDIM sampler over the plain forward of exported weights.
#[derive(Clone, Debug)]
pub struct DdimSampler {
    denoiser: PlainDenoiser,
    schedule: CosineSchedule,
}

impl DdimSampler {
    /// A sampler for `weights`.
    pub fn new(weights: &DenoiserWeights) -> Self {
        Self {
            schedule: CosineSchedule::new(weights.config().timesteps),
            denoiser: PlainDenoiser::new(weights),
        }
    }

    /// The forward it runs.
    pub fn denoiser(&self) -> &PlainDenoiser {
        &self.denoiser
    }

    /// Checks a sampling configuration against this model.
    pub fn validate(&self, config: &SampleConfig) -> Result<(), SampleError> {
        let timesteps = self.schedule.len();
        if !(1..=timesteps).contains(&config.steps) {
            return Err(SampleError::Steps {
                steps: config.steps,
                timesteps,
            });
        }
        if !config.guidance_scale.is_finite() {
            return Err(SampleError::NotFinite {
                field: "guidance_scale",
                value: config.guidance_scale,
                extra: "",
            });
        }
        if !(config.x0_clip.is_finite() && config.x0_clip > 0.0) {
            return Err(SampleError::NotFinite {
                field: "x0_clip",
                value: config.x0_clip,
                extra: " and positive",
            });
        }
        Ok(())
    }

    /// Denoises `samples` (`n × data_dim`, holding `x_T ~ N(0, I)` on entry) in place into
    /// `x_0`, conditioned on `condition` with guidance `v = v_∅ + w (v_c − v_∅)` (Eq. 5). Each
    /// row's result depends only on its own noise, never on the batch it shares. Allocates
    /// nothing once `workspace` has served a batch this large.
    pub fn sample(
        &self,
        condition: &[f32],
        config: &SampleConfig,
        samples: &mut [f32],
        workspace: &mut SamplerWorkspace,
    ) -> Result<(), SampleError> {
        self.validate(config)?;
        let model = self.denoiser.config();
        let (d, w) = (model.data_dim, model.width);
        if condition.len() != model.condition_dim {
            return Err(SampleError::Length {
                what: "condition",
                expected: model.condition_dim,
                found: condition.len(),
            });
        }
        if !samples.len().is_multiple_of(d) {
            return Err(SampleError::Length {
                what: "samples",
                expected: samples.len().div_ceil(d) * d,
                found: samples.len(),
            });
        }
        let n = samples.len() / d;
        let scale = config.guidance_scale as f32;
        // Which branches Eq. 5 needs: w = 0 is unconditional, w = 1 purely conditional.
        let (conditional, unconditional) = (scale != 0.0, scale != 1.0);
        let branches = usize::from(conditional) + usize::from(unconditional);
        let rows = branches * n;
        workspace.condition.resize(w, 0.0);
        workspace.rows.resize(rows * d, 0.0);
        workspace.velocities.resize(rows * d, 0.0);
        workspace.condition_rows.resize(rows * w, 0.0);
        if conditional {
            self.denoiser
                .embed_condition(condition, &mut workspace.condition);
        }
        for (i, row) in workspace.condition_rows.chunks_exact_mut(w).enumerate() {
            let use_condition = conditional && i < n;
            row.copy_from_slice(if use_condition {
                &workspace.condition
            } else {
                self.denoiser.null_embedding()
            });
        }
        let clip = config.x0_clip as f32;
        for k in 0..config.steps {
            let t = self.schedule.ddim_time(k, config.steps);
            let alpha_bar = self.schedule.alpha_bar(t) as f32;
            let alpha_bar_next = if k + 1 < config.steps {
                self.schedule
                    .alpha_bar(self.schedule.ddim_time(k + 1, config.steps)) as f32
            } else {
                1.0
            };
            for chunk in workspace.rows.chunks_exact_mut(n * d) {
                chunk.copy_from_slice(samples);
            }
            self.denoiser.velocity(
                t,
                &workspace.rows,
                &workspace.condition_rows,
                rows,
                &mut workspace.scratch,
                &mut workspace.velocities,
            );
            let (first, second) =
                workspace
                    .velocities
                    .split_at(if branches == 2 { n * d } else { rows * d });
            let (signal, noise) = (alpha_bar.sqrt(), (1.0 - alpha_bar).sqrt());
            let (signal_next, noise_next) = (alpha_bar_next.sqrt(), (1.0 - alpha_bar_next).sqrt());
            for (i, x) in samples.iter_mut().enumerate() {
                let v = match branches {
                    2 => second[i] + scale * (first[i] - second[i]),
                    _ => first[i],
                };
                let x0 = (signal * *x - noise * v).clamp(-clip, clip);
                let epsilon = noise * *x + signal * v;
                *x = signal_next * x0 + noise_next * epsilon;
            }
        }
        Ok(())
    }
}
