//! An allocation-free plain-Rust forward of the exported actor and critic: the batch-1 path
//! used inside rollouts (training environments and the evaluated controller).

use crate::observation::{ACTION_DIM, OBSERVATION_DIM, PolicyDims};
use crate::weights::{PolicyWeights, layer_shapes};

/// One dense layer `y = x W + b` with `W` stored `[in, out]` row-major.
#[derive(Clone, Debug)]
struct Layer {
    input: usize,
    output: usize,
    weight: Vec<f32>,
    bias: Vec<f32>,
}

/// Outputs per register block of [`Layer::forward`]: 32 `f32` accumulators (four 256-bit or
/// eight 128-bit registers).
const LANE_BLOCK: usize = 32;

impl Layer {
    /// `y = b + Σᵢ xᵢ Wᵢ`, each output summed in input order starting from its bias.
    ///
    /// Register-blocked: blocks of [`LANE_BLOCK`] outputs, then of [`ACTION_DIM`] (the heads),
    /// then single outputs accumulate in registers while the inputs stream by. Every output is
    /// summed in the same order whatever its block, so the result does not depend on the
    /// blocking (nor on the vector width: no fused multiply-add).
    #[inline(always)]
    fn forward(&self, x: &[f32], y: &mut [f32]) {
        let x = &x[..self.input];
        let column = self.forward_blocks::<LANE_BLOCK>(x, y, 0);
        let column = self.forward_blocks::<ACTION_DIM>(x, y, column);
        self.forward_blocks::<1>(x, y, column);
    }

    /// Outputs `first…` of [`Layer::forward`] in blocks of `N` while a whole block fits;
    /// returns the first output left.
    #[inline(always)]
    fn forward_blocks<const N: usize>(&self, x: &[f32], y: &mut [f32], first: usize) -> usize {
        let n_out = self.output;
        let mut column = first;
        while column + N <= n_out {
            let mut acc: [f32; N] = self.bias[column..column + N]
                .try_into()
                .expect("a full block");
            for (&xi, row) in x.iter().zip(self.weight.chunks_exact(n_out)) {
                let w: &[f32; N] = row[column..column + N].try_into().expect("a full block");
                for (a, &wl) in acc.iter_mut().zip(w) {
                    *a += xi * wl;
                }
            }
            y[column..column + N].copy_from_slice(&acc);
            column += N;
        }
        column
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
    /// Gaussian mean `μ` (before the tanh squash); zero past the action's length.
    pub mean: [f32; ACTION_DIM],
    /// Clamped log standard deviation; zero past the action's length.
    pub log_std: [f32; ACTION_DIM],
}

impl ActorOutput {
    /// The deterministic action `tanh(μ)` used at evaluation (SPEC §5).
    pub fn deterministic_action(&self) -> [f32; ACTION_DIM] {
        self.mean.map(libm::tanhf)
    }
}

/// The actor and critic of exported [`PolicyWeights`] as plain `f32` loops (ReLU hidden layers).
#[derive(Clone, Debug)]
pub struct PlainPolicy {
    dims: PolicyDims,
    actor: Vec<Layer>,
    mean: Layer,
    log_std: Layer,
    critic: Vec<Layer>,
    value: Layer,
    log_std_range: (f32, f32),
    widest: usize,
    /// Whether the CPU runs AVX2 (the hidden layers then use 256-bit vectors).
    avx2: bool,
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
            dims: PolicyDims::for_joints(header.network.joints),
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
            #[cfg(target_arch = "x86_64")]
            avx2: std::arch::is_x86_feature_detected!("avx2"),
            #[cfg(not(target_arch = "x86_64"))]
            avx2: false,
        }
    }

    /// The observation and action lengths the network reads and writes.
    pub fn dims(&self) -> PolicyDims {
        self.dims
    }

    /// Working memory for this network.
    pub fn scratch(&self) -> PolicyScratch {
        PolicyScratch {
            front: vec![0.0; self.widest],
            back: vec![0.0; self.widest],
        }
    }

    /// The Gaussian of `observation` (allocation-free): its first [`PlainPolicy::dims`]
    /// entries are read, and the output's entries past the action's are zero.
    pub fn actor(
        &self,
        observation: &[f32; OBSERVATION_DIM],
        scratch: &mut PolicyScratch,
    ) -> ActorOutput {
        let hidden = self.trunk(&self.actor, observation, scratch);
        let mut output = ActorOutput::default();
        self.mean.forward(hidden, &mut output.mean);
        self.log_std.forward(hidden, &mut output.log_std);
        let (low, high) = self.log_std_range;
        for s in &mut output.log_std[..self.dims.action] {
            *s = s.clamp(low, high);
        }
        output
    }

    /// The value `V(observation)` (allocation-free).
    pub fn value(&self, observation: &[f32; OBSERVATION_DIM], scratch: &mut PolicyScratch) -> f32 {
        let hidden = self.trunk(&self.critic, observation, scratch);
        let mut value = [0.0];
        self.value.forward(hidden, &mut value);
        value[0]
    }

    /// The ReLU hidden `layers` (the bulk of the work); returns the last activation (inside
    /// `scratch`). Runs 256-bit vector code where the CPU has AVX2; the arithmetic and so the
    /// result are the same either way.
    fn trunk<'s>(
        &self,
        layers: &[Layer],
        observation: &[f32; OBSERVATION_DIM],
        scratch: &'s mut PolicyScratch,
    ) -> &'s [f32] {
        #[cfg(target_arch = "x86_64")]
        if self.avx2 {
            // SAFETY: `avx2` is set only when the running CPU reports AVX2 (see `new`).
            return unsafe { trunk_avx2(layers, observation, scratch) };
        }
        trunk_portable(layers, observation, scratch)
    }
}

#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2")]
fn trunk_avx2<'s>(
    layers: &[Layer],
    observation: &[f32; OBSERVATION_DIM],
    scratch: &'s mut PolicyScratch,
) -> &'s [f32] {
    trunk_portable(layers, observation, scratch)
}

#[inline(always)]
fn trunk_portable<'s>(
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

#[cfg(test)]
mod tests {
    use super::*;

    /// A layer with deterministic pseudo-random weights and biases.
    fn layer(input: usize, output: usize, salt: f32) -> Layer {
        let value = |i: usize| (libm::sinf(i as f32 * 0.618 + salt) * 1.7).fract();
        Layer {
            input,
            output,
            weight: (0..input * output).map(value).collect(),
            bias: (0..output).map(|j| value(j + 7919)).collect(),
        }
    }

    #[test]
    fn every_block_width_sums_like_the_plain_loop() {
        // Output counts that use each block width alone and together.
        for output in [1, 3, 4, 5, 31, 32, 33, 36, 37, 128, 133] {
            let layer = layer(29, output, output as f32);
            let x: Vec<f32> = (0..29).map(|i| libm::cosf(i as f32 * 0.37)).collect();
            let mut blocked = vec![f32::NAN; output];
            layer.forward(&x, &mut blocked);
            for (j, got) in blocked.iter().enumerate() {
                let mut want = layer.bias[j];
                for (i, xi) in x.iter().enumerate() {
                    want += xi * layer.weight[i * output + j];
                }
                assert_eq!(got.to_bits(), want.to_bits(), "output {j} of {output}");
            }
        }
    }

    #[cfg(target_arch = "x86_64")]
    #[test]
    fn the_avx2_trunk_equals_the_portable_one_bit_for_bit() {
        if !std::arch::is_x86_feature_detected!("avx2") {
            return;
        }
        let layers = [layer(OBSERVATION_DIM, 128, 0.1), layer(128, 96, 0.2)];
        let mut scratch = PolicyScratch {
            front: vec![0.0; 128],
            back: vec![0.0; 128],
        };
        for k in 0..50 {
            let observation: [f32; OBSERVATION_DIM] =
                std::array::from_fn(|i| libm::sinf((i * 31 + k) as f32 * 0.77));
            let portable = trunk_portable(&layers, &observation, &mut scratch).to_vec();
            // SAFETY: the CPU reports AVX2 (checked above).
            let vector = unsafe { trunk_avx2(&layers, &observation, &mut scratch) };
            assert_eq!(portable.len(), vector.len());
            for (p, v) in portable.iter().zip(vector) {
                assert_eq!(p.to_bits(), v.to_bits(), "observation {k}");
            }
        }
    }
}
