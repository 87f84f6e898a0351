//! The actor and critic MLPs in Burn (SPEC §5): ReLU hidden layers, orthogonal initialisation,
//! a tanh-squashed Gaussian policy with a state-dependent log standard deviation.
//!
//! The backend is the tensor device the model lives on (`Device::flex()` or
//! `Device::ndarray()`, `.autodiff()` for training), so the same code runs on any Burn backend.

use burn::module::{Module, Param};
use burn::nn::{Initializer, Linear, LinearConfig};
use burn::tensor::activation::relu;
use burn::tensor::{Device, Tensor};

use crate::config::NetworkConfig;
use crate::observation::PolicyDims;

/// A ReLU MLP trunk: `input → hidden[0] → … → hidden[last]`, ReLU after every layer.
#[derive(Module, Debug)]
pub struct Trunk {
    /// The layers, input side first.
    pub layers: Vec<Linear>,
}

impl Trunk {
    fn new(input: usize, hidden: &[usize], device: &Device) -> Self {
        let mut layers = Vec::with_capacity(hidden.len());
        let mut width = input;
        for &next in hidden {
            layers.push(orthogonal_linear(width, next, 2f64.sqrt(), 0.0, device));
            width = next;
        }
        Self { layers }
    }

    fn forward(&self, mut x: Tensor<2>) -> Tensor<2> {
        for layer in &self.layers {
            x = relu(layer.forward(x));
        }
        x
    }
}

/// The policy `π(u | o) = N(μ(o), diag σ(o)²)`, `a = tanh(u)`, and the value `V(o)`: separate
/// actor and critic networks (SPEC §5).
#[derive(Module, Debug)]
pub struct ActorCritic {
    /// Hidden layers of the actor.
    pub actor: Trunk,
    /// Actor head: the Gaussian mean `μ` (before the tanh squash).
    pub mean: Linear,
    /// Actor head: `log σ` before clamping (bias initialised to `log_std_bias`).
    pub log_std: Linear,
    /// Hidden layers of the critic.
    pub critic: Trunk,
    /// Critic head: the value.
    pub value: Linear,
}

/// What the actor outputs for a batch.
pub struct PolicyOutput {
    /// Gaussian means, `[B, 4]`.
    pub mean: Tensor<2>,
    /// Clamped log standard deviations, `[B, 4]`.
    pub log_std: Tensor<2>,
}

impl ActorCritic {
    /// A freshly initialised network on `device` (orthogonal weights: gain √2 in hidden layers,
    /// 0.01 in the actor heads, 1 in the value head; zero biases except the log-std head's
    /// `log_std_bias`). Seed the device first for reproducible weights.
    pub fn new(config: &NetworkConfig, log_std_bias: f64, device: &Device) -> Self {
        let dims = PolicyDims::for_joints(config.joints);
        let last = config.hidden.last().copied().unwrap_or(dims.observation);
        Self {
            actor: Trunk::new(dims.observation, &config.hidden, device),
            mean: orthogonal_linear(last, dims.action, 0.01, 0.0, device),
            log_std: orthogonal_linear(last, dims.action, 0.01, log_std_bias, device),
            critic: Trunk::new(dims.observation, &config.hidden, device),
            value: orthogonal_linear(last, 1, 1.0, 0.0, device),
        }
    }

    /// The Gaussian of each observation row (`[B, 31]`), log-std clamped to `log_std_range`.
    pub fn policy(&self, observations: Tensor<2>, log_std_range: (f64, f64)) -> PolicyOutput {
        let hidden = self.actor.forward(observations);
        PolicyOutput {
            mean: self.mean.forward(hidden.clone()),
            log_std: self
                .log_std
                .forward(hidden)
                .clamp(log_std_range.0, log_std_range.1),
        }
    }

    /// The value of each observation row, `[B]`.
    pub fn value(&self, observations: Tensor<2>) -> Tensor<1> {
        let values = self.value.forward(self.critic.forward(observations));
        let [batch, _] = values.dims();
        values.reshape([batch])
    }
}

fn orthogonal_linear(input: usize, output: usize, gain: f64, bias: f64, device: &Device) -> Linear {
    let mut linear = LinearConfig::new(input, output)
        .with_bias(false)
        .with_initializer(Initializer::Orthogonal { gain })
        .init(device);
    linear.bias = Some(Param::from_tensor(Tensor::full([output], bias, device)));
    linear
}
