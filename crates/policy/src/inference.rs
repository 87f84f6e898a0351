//! An allocation-free plain-Rust forward of the exported actor and critic: the batch-1 path
//! used inside rollouts (training environments and the evaluated controller).

use crate::observation::{ACTION_DIM, OBSERVATION_DIM};
use crate::weights::{PolicyWeights, layer_shapes};

/// One dense layer `y = x W + b` with `W` stored `[in, out]` row-major.
#[derive(Clone, Debug)]
struct Layer {
    input: usize,
    output: usize,
    weight: Vec<f32>,
    bias: Vec<f32>,
}

impl Layer {
    fn forward(&self, x: &[f32], y: &mut [f32]) {
        let y = &mut y[..self.output];
        y.copy_from_slice(&self.bias);
        for (xi, row) in x[..self.input]
            .iter()
            .zip(self.weight.chunks_exact(self.output))
        {
            for (yo, w) in y.iter_mut().zip(row) {
                *yo += xi * w;
            }
        }
    }
}

/// Working memory of [`PlainPolicy`]: one per thread, reused across calls.
#[derive(Clone, Debug)]
pub struct PolicyScratch {
    front: Vec<f32>,
    back: Vec<f32>,
}

/// What the actor outputs for one observation.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct ActorOutput {
    /// Gaussian mean `μ` (before the tanh squash).
    pub mean: [f32; ACTION_DIM],
    /// Clamped log standard deviation.
    pub log_std: [f32; ACTION_DIM],
}

impl ActorOutput {
    /// The deterministic action `tanh(μ)` used at evaluation (SPEC §5).
    pub fn deterministic_action(&self) -> [f32; ACTION_DIM] {
        self.mean.map(f32::tanh)
    }
}

/// The actor and critic of exported [`PolicyWeights`] as plain `f32` loops (ReLU hidden layers).
#[derive(Clone, Debug)]
pub struct PlainPolicy {
    actor: Vec<Layer>,
    mean: Layer,
    log_std: Layer,
    critic: Vec<Layer>,
    value: Layer,
    log_std_range: (f32, f32),
    widest: usize,
}

impl PlainPolicy {
    /// The network of `weights`.
    pub fn new(weights: &PolicyWeights) -> Self {
        let header = weights.header();
        let mut values = weights.values();
        let mut layers = layer_shapes(&header.network)
            .into_iter()
            .map(|(input, output)| {
                let (weight, rest) = values.split_at(input * output);
                let (bias, rest) = rest.split_at(output);
                values = rest;
                Layer {
                    input,
                    output,
                    weight: weight.to_vec(),
                    bias: bias.to_vec(),
                }
            })
            .collect::<Vec<_>>();
        let hidden = header.network.hidden.len();
        let value = layers.pop().expect("a value head");
        let critic = layers.split_off(hidden + 2);
        let log_std = layers.pop().expect("a log-std head");
        let mean = layers.pop().expect("a mean head");
        let widest = header
            .network
            .hidden
            .iter()
            .copied()
            .chain([OBSERVATION_DIM, ACTION_DIM])
            .max()
            .unwrap_or(OBSERVATION_DIM);
        Self {
            actor: layers,
            mean,
            log_std,
            critic,
            value,
            log_std_range: (
                header.log_std_range[0] as f32,
                header.log_std_range[1] as f32,
            ),
            widest,
        }
    }

    /// Working memory for this network.
    pub fn scratch(&self) -> PolicyScratch {
        PolicyScratch {
            front: vec![0.0; self.widest],
            back: vec![0.0; self.widest],
        }
    }

    /// The Gaussian of `observation` (allocation-free).
    pub fn actor(
        &self,
        observation: &[f32; OBSERVATION_DIM],
        scratch: &mut PolicyScratch,
    ) -> ActorOutput {
        let hidden = trunk(&self.actor, observation, scratch);
        let mut output = ActorOutput::default();
        self.mean.forward(hidden, &mut output.mean);
        self.log_std.forward(hidden, &mut output.log_std);
        let (low, high) = self.log_std_range;
        for s in &mut output.log_std {
            *s = s.clamp(low, high);
        }
        output
    }

    /// The value `V(observation)` (allocation-free).
    pub fn value(&self, observation: &[f32; OBSERVATION_DIM], scratch: &mut PolicyScratch) -> f32 {
        let hidden = trunk(&self.critic, observation, scratch);
        let mut value = [0.0];
        self.value.forward(hidden, &mut value);
        value[0]
    }
}

/// ReLU hidden layers; returns the last activation (inside `scratch`).
fn trunk<'s>(
    layers: &[Layer],
    observation: &[f32; OBSERVATION_DIM],
    scratch: &'s mut PolicyScratch,
) -> &'s [f32] {
    scratch.front[..OBSERVATION_DIM].copy_from_slice(observation);
    let mut width = OBSERVATION_DIM;
    for layer in layers {
        layer.forward(&scratch.front, &mut scratch.back);
        for v in &mut scratch.back[..layer.output] {
            *v = v.max(0.0);
        }
        std::mem::swap(&mut scratch.front, &mut scratch.back);
        width = layer.output;
    }
    &scratch.front[..width]
}
