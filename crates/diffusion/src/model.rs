//! The residual-MLP denoiser `v_θ(x_t, t, c)` in Burn (SPEC §6, Eq. 5's network).
//!
//! The backend is the tensor device the model lives on (`Device::flex()` or `Device::ndarray()`,
//! `.autodiff()` for training), so the same code runs on any Burn backend.

use burn::module::{Module, Param};
use burn::nn::{LayerNorm, LayerNormConfig, Linear, LinearConfig};
use burn::tensor::activation::silu;
use burn::tensor::{Device, Tensor};

use crate::config::DiffusionConfig;

/// One residual block: `h + W₂ · dropout(SiLU(W₁ · LN(h)))`.
#[derive(Module, Debug)]
pub struct ResidualBlock {
    /// Pre-normalisation.
    pub norm: LayerNorm,
    /// `width → hidden`.
    pub expand: Linear,
    /// `hidden → width`.
    pub contract: Linear,
}

/// The denoiser: condition, time and sample embeddings summed, residual blocks, LayerNorm, head.
#[derive(Module, Debug)]
pub struct Denoiser {
    /// LayerNorm of the condition.
    pub condition_norm: LayerNorm,
    /// `condition_dim → width`.
    pub condition_in: Linear,
    /// `width → width` (after SiLU).
    pub condition_out: Linear,
    /// `time_dim → 2·width`.
    pub time_in: Linear,
    /// `2·width → width` (after SiLU).
    pub time_out: Linear,
    /// `data_dim → width`.
    pub sample_in: Linear,
    /// The residual blocks.
    pub blocks: Vec<ResidualBlock>,
    /// Final LayerNorm.
    pub output_norm: LayerNorm,
    /// `width → data_dim`: the predicted `v`.
    pub head: Linear,
    /// The learnable null condition `∅` that replaces a dropped `c` (classifier-free guidance).
    pub null_condition: Param<Tensor<1>>,
}

/// One batch of denoiser inputs.
pub struct DenoiserInput {
    /// Noisy samples `x_t`, `[B, data_dim]`.
    pub sample: Tensor<2>,
    /// Sinusoidal embeddings of `t`, `[B, time_dim]`.
    pub time_embedding: Tensor<2>,
    /// Conditions `c`, `[B, condition_dim]`.
    pub condition: Tensor<2>,
    /// 1 where the condition is replaced by `∅`, else 0, `[B, 1]`.
    pub condition_dropped: Tensor<2>,
    /// Per-block dropout multipliers (0 or `1/(1−p)`), `[B, hidden]` each; `None` at inference.
    pub dropout_masks: Option<Vec<Tensor<2>>>,
}

impl Denoiser {
    /// A freshly initialised denoiser (Burn's default Kaiming-uniform linear layers, the null
    /// condition at zero) on `device`; seed the device first for reproducible weights.
    pub fn new(config: &DiffusionConfig, device: &Device) -> Self {
        let linear = |i: usize, o: usize| LinearConfig::new(i, o).init(device);
        let norm = |d: usize| LayerNormConfig::new(d).init(device);
        let w = config.width;
        Self {
            condition_norm: norm(config.condition_dim),
            condition_in: linear(config.condition_dim, w),
            condition_out: linear(w, w),
            time_in: linear(config.time_dim, 2 * w),
            time_out: linear(2 * w, w),
            sample_in: linear(config.data_dim, w),
            blocks: (0..config.blocks)
                .map(|_| ResidualBlock {
                    norm: norm(w),
                    expand: linear(w, config.hidden),
                    contract: linear(config.hidden, w),
                })
                .collect(),
            output_norm: norm(w),
            head: linear(w, config.data_dim),
            null_condition: Param::from_tensor(Tensor::zeros([config.condition_dim], device)),
        }
    }

    /// The predicted velocity `v̂ = v_θ(x_t, t, c or ∅)`, `[B, data_dim]`.
    pub fn forward(&self, input: DenoiserInput) -> Tensor<2> {
        let [batch, condition_dim] = input.condition.dims();
        let null = self
            .null_condition
            .val()
            .reshape([1, condition_dim])
            .expand([batch, condition_dim]);
        let keep = input.condition_dropped.clone().neg().add_scalar(1.0);
        let condition = input.condition * keep + null * input.condition_dropped;
        let condition = self.condition_out.forward(silu(
            self.condition_in
                .forward(self.condition_norm.forward(condition)),
        ));
        let time = self
            .time_out
            .forward(silu(self.time_in.forward(input.time_embedding)));
        let mut h = self.sample_in.forward(input.sample) + condition + time;
        for (i, block) in self.blocks.iter().enumerate() {
            let mut inner = silu(block.expand.forward(block.norm.forward(h.clone())));
            if let Some(masks) = &input.dropout_masks {
                inner = inner * masks[i].clone();
            }
            h = h + block.contract.forward(inner);
        }
        self.head.forward(self.output_norm.forward(h))
    }
}
