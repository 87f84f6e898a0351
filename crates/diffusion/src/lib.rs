//! The diffusion seeder (Sec. 4.1, Eq. 5; SPEC §6): a conditional DDPM over start
//! configurations, trained in Burn on CPU and sampled with DDIM (η = 0) and classifier-free
//! guidance by an allocation-free plain-Rust forward.
//!
//! * [`Denoiser`]: the residual-MLP `v_θ(x_t, t, c)` (v-prediction, learnable null condition).
//! * [`Trainer`]: AdamW, gradient clipping, EMA, guidance dropout, mirror augmentation,
//!   checkpoints with exact resume, on the Burn backend named by [`Backend`].
//! * [`DenoiserWeights`]: the exported EMA weights (flat `f32` + header naming the data set).
//! * [`DdimSampler`]: DDIM with guidance `v = v_∅ + w (v_c − v_∅)`, batched over candidates.
//! * [`DpSeeder`]: the DP seed pipeline — sample, Newton-project onto `(p0, n)`, first IK-valid
//!   candidate within 32 tries, else `q0_seed`.
//!
//! ```
//! use emg_diffusion::{Backend, DdimSampler, DiffusionConfig, SampleConfig, TrainConfig, Trainer, TrainingSet};
//! // A toy conditional distribution: x = ±0.5 for the condition (±1, 0).
//! let signs: Vec<f32> = (0..32).map(|i| if i % 2 == 0 { 1.0 } else { -1.0 }).collect();
//! let conditions: Vec<f32> = signs.iter().flat_map(|&s| [s, 0.0]).collect();
//! let samples: Vec<f32> = signs.iter().map(|s| 0.5 * s).collect();
//! let data = TrainingSet::new(conditions, samples, 2, 1, "toy")?;
//! let network = DiffusionConfig { data_dim: 1, condition_dim: 2, width: 16, hidden: 32, blocks: 1, time_dim: 8, timesteps: 100 };
//! let training = TrainConfig { steps: 5, batch_size: 16, ..TrainConfig::default() };
//! let mut trainer = Trainer::new(network, training, Backend::Flex, &data)?;
//! for _ in 0..5 {
//!     assert!(trainer.train_step(&data).is_finite());
//! }
//! let sampler = DdimSampler::new(trainer.ema_weights());
//! let mut samples = vec![0.3f32, -1.0, 0.8];
//! sampler.sample(&[1.0, 0.0], &SampleConfig { steps: 10, ..SampleConfig::default() }, &mut samples, &mut Default::default())?;
//! assert!(samples.iter().all(|x| x.abs() <= 1.2));
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```

mod config;
#[cfg(feature = "train")]
mod dataset;
mod embedding;
mod forward;
#[cfg(feature = "train")]
mod model;
mod sampler;
mod schedule;
mod seed;
#[cfg(feature = "train")]
mod train;
mod weights;

pub use config::{Backend, DiffusionConfig, SampleConfig, TrainConfig};
#[cfg(feature = "train")]
pub use dataset::{MIRROR_CONDITION_SIGNS, MIRROR_JOINT_SIGNS, has_mirror_symmetry, training_set};
pub use embedding::sinusoidal_embedding;
#[cfg(feature = "train")]
pub use emg_learning::checkpoint::CheckpointError;
pub use emg_learning::container::ContainerError;
pub use forward::{ForwardScratch, PlainDenoiser};
#[cfg(feature = "train")]
pub use model::{Denoiser, DenoiserInput, ResidualBlock};
pub use sampler::{DdimSampler, SampleError, SamplerWorkspace};
pub use schedule::CosineSchedule;
pub use seed::{
    CONDITION_DIM, DpSeed, DpSeedConfig, DpSeedError, DpSeeder, RollTarget, SeedOrigin,
    SeedWorkspace, condition_of, denormalise,
};
#[cfg(feature = "train")]
pub use train::{LossRow, Mirror, TrainError, Trainer, TrainingSet};
pub use weights::{
    DenoiserWeights, TensorSpec, WEIGHTS_FORMAT_VERSION, WeightsError, WeightsHeader,
    parameter_layout,
};
