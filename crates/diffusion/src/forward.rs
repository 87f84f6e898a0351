//! Allocation-free plain-Rust forward of the denoiser over exported weights, batched over rows.
//!
//! Burn's per-call overhead dominates at the batch sizes of seed sampling (a few candidates ×
//! 50 DDIM steps), so sampling runs this forward. Everything that does not depend on the noisy
//! sample is computed once: the time embedding `MLP(sinusoidal(t))` for every `t` at load, the
//! condition embeddings once per task. A test proves agreement with the Burn model.

use crate::config::DiffusionConfig;
use crate::embedding::sinusoidal_embedding;
use crate::weights::{DenoiserWeights, parameter_layout};

/// LayerNorm epsilon (Burn's `LayerNormConfig` default).
const LAYER_NORM_EPSILON: f32 = 1e-5;

/// A linear layer `y = x W + b` as offsets into the flat weights.
#[derive(Clone, Copy, Debug)]
struct LinearView {
    weight: usize,
    bias: usize,
    inputs: usize,
    outputs: usize,
}

/// A LayerNorm as offsets into the flat weights.
#[derive(Clone, Copy, Debug)]
struct NormView {
    gamma: usize,
    beta: usize,
    dim: usize,
}

#[derive(Clone, Copy, Debug)]
struct BlockView {
    norm: NormView,
    expand: LinearView,
    contract: LinearView,
}

/// Walks the flat layout in order, handing out views.
struct LayoutCursor {
    parts: std::vec::IntoIter<(usize, Vec<usize>)>,
}

impl LayoutCursor {
    fn new(config: &DiffusionConfig) -> Self {
        let mut at = 0;
        let parts: Vec<_> = parameter_layout(config)
            .into_iter()
            .map(|spec| {
                let start = at;
                at += spec.len();
                (start, spec.shape)
            })
            .collect();
        Self {
            parts: parts.into_iter(),
        }
    }

    fn next(&mut self) -> (usize, Vec<usize>) {
        self.parts.next().expect("views follow parameter_layout")
    }

    /// The next two parameters of a layer (its scale or weight, then its shift or bias): their
    /// offsets and the first one's shape.
    fn layer(&mut self) -> (usize, usize, Vec<usize>) {
        let (first, shape) = self.next();
        let (second, _) = self.next();
        (first, second, shape)
    }

    fn norm(&mut self) -> NormView {
        let (gamma, beta, shape) = self.layer();
        NormView {
            gamma,
            beta,
            dim: shape[0],
        }
    }

    fn linear(&mut self) -> LinearView {
        let (weight, bias, shape) = self.layer();
        LinearView {
            weight,
            bias,
            inputs: shape[0],
            outputs: shape[1],
        }
    }
}

/// Reusable buffers of [`PlainDenoiser::velocity`]; they grow to the largest batch seen, then
/// the forward allocates nothing.
#[derive(Clone, Debug, Default)]
pub struct ForwardScratch {
    residual: Vec<f32>,
    normed: Vec<f32>,
    inner: Vec<f32>,
}

/// The denoiser over exported weights, with the time and null-condition embeddings precomputed.
#[derive(Clone, Debug)]
pub struct PlainDenoiser {
    config: DiffusionConfig,
    values: Vec<f32>,
    condition_norm: NormView,
    condition_in: LinearView,
    condition_out: LinearView,
    sample_in: LinearView,
    blocks: Vec<BlockView>,
    output_norm: NormView,
    head: LinearView,
    /// `T × width`: the embedded time of every step.
    time_table: Vec<f32>,
    /// The embedded null condition `∅` (`width`).
    null_embedding: Vec<f32>,
    /// Whether the CPU runs AVX2 (the forward then uses 256-bit vectors).
    avx2: bool,
}

impl PlainDenoiser {
    /// Builds the forward from exported weights (precomputes every time embedding).
    pub fn new(weights: &DenoiserWeights) -> Self {
        let config = weights.config().clone();
        let values = weights.values().to_vec();
        let mut cursor = LayoutCursor::new(&config);
        let condition_norm = cursor.norm();
        let condition_in = cursor.linear();
        let condition_out = cursor.linear();
        let time_in = cursor.linear();
        let time_out = cursor.linear();
        let sample_in = cursor.linear();
        let blocks = (0..config.blocks)
            .map(|_| BlockView {
                norm: cursor.norm(),
                expand: cursor.linear(),
                contract: cursor.linear(),
            })
            .collect();
        let output_norm = cursor.norm();
        let head = cursor.linear();
        let (null_offset, _) = cursor.next();

        let w = config.width;
        let mut time_table = vec![0.0; config.timesteps * w];
        let mut sinusoid = vec![0.0; config.time_dim];
        let mut hidden = vec![0.0; 2 * w];
        for (t, row) in time_table.chunks_exact_mut(w).enumerate() {
            sinusoidal_embedding(t, &mut sinusoid);
            linear(&values, time_in, &sinusoid, 1, &mut hidden);
            silu_in_place(&mut hidden);
            linear(&values, time_out, &hidden, 1, row);
        }
        let mut denoiser = Self {
            config,
            values,
            condition_norm,
            condition_in,
            condition_out,
            sample_in,
            blocks,
            output_norm,
            head,
            time_table,
            null_embedding: Vec::new(),
            #[cfg(target_arch = "x86_64")]
            avx2: std::arch::is_x86_feature_detected!("avx2"),
            #[cfg(not(target_arch = "x86_64"))]
            avx2: false,
        };
        let null =
            denoiser.values[null_offset..null_offset + denoiser.config.condition_dim].to_vec();
        let mut null_embedding = vec![0.0; w];
        denoiser.embed_condition(&null, &mut null_embedding);
        denoiser.null_embedding = null_embedding;
        denoiser
    }

    /// The network shape.
    pub fn config(&self) -> &DiffusionConfig {
        &self.config
    }

    /// Writes the embedding `MLP(LN(c))` of condition `c` (`condition_dim`) into `out` (`width`).
    pub fn embed_condition(&self, condition: &[f32], out: &mut [f32]) {
        debug_assert_eq!(condition.len(), self.config.condition_dim);
        let mut normed = vec![0.0; condition.len()];
        layer_norm(&self.values, self.condition_norm, condition, 1, &mut normed);
        let mut hidden = vec![0.0; self.config.width];
        linear(&self.values, self.condition_in, &normed, 1, &mut hidden);
        silu_in_place(&mut hidden);
        linear(&self.values, self.condition_out, &hidden, 1, out);
    }

    /// The embedding of the learnable null condition `∅` (`width`).
    pub fn null_embedding(&self) -> &[f32] {
        &self.null_embedding
    }

    /// The predicted velocity `v̂` of `rows` samples at timestep `t`: `samples` and `out` are
    /// `rows × data_dim`, `condition_embeddings` is `rows × width` (from
    /// [`embed_condition`](Self::embed_condition) or [`null_embedding`](Self::null_embedding)).
    /// Runs 256-bit vector code where the CPU has AVX2; the arithmetic (no fused multiply-add,
    /// sums in order) and so the result are the same either way.
    pub fn velocity(
        &self,
        t: usize,
        samples: &[f32],
        condition_embeddings: &[f32],
        rows: usize,
        scratch: &mut ForwardScratch,
        out: &mut [f32],
    ) {
        let batch = VelocityBatch {
            t,
            samples,
            condition_embeddings,
            rows,
        };
        #[cfg(target_arch = "x86_64")]
        if self.avx2 {
            // SAFETY: `avx2` is set only when the running CPU reports AVX2 (see `new`).
            unsafe { self.velocity_avx2(&batch, scratch, out) };
            return;
        }
        self.velocity_portable(&batch, scratch, out);
    }

    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx2")]
    fn velocity_avx2(&self, batch: &VelocityBatch, scratch: &mut ForwardScratch, out: &mut [f32]) {
        self.velocity_portable(batch, scratch, out);
    }

    #[inline(always)]
    fn velocity_portable(
        &self,
        batch: &VelocityBatch,
        scratch: &mut ForwardScratch,
        out: &mut [f32],
    ) {
        let VelocityBatch {
            t,
            samples,
            condition_embeddings,
            rows,
        } = *batch;
        let (w, h) = (self.config.width, self.config.hidden);
        grow(&mut scratch.residual, rows * w);
        grow(&mut scratch.normed, rows * w);
        grow(&mut scratch.inner, rows * h);
        let residual = &mut scratch.residual[..rows * w];
        let normed = &mut scratch.normed[..rows * w];
        let inner = &mut scratch.inner[..rows * h];
        linear(&self.values, self.sample_in, samples, rows, residual);
        let time = &self.time_table[t * w..(t + 1) * w];
        for (row, condition) in residual
            .chunks_exact_mut(w)
            .zip(condition_embeddings.chunks_exact(w))
        {
            for ((r, c), e) in row.iter_mut().zip(condition).zip(time) {
                *r += c + e;
            }
        }
        for block in &self.blocks {
            layer_norm(&self.values, block.norm, residual, rows, normed);
            linear(&self.values, block.expand, normed, rows, inner);
            silu_in_place(inner);
            linear_accumulate(&self.values, block.contract, inner, rows, residual);
        }
        layer_norm(&self.values, self.output_norm, residual, rows, normed);
        linear(&self.values, self.head, normed, rows, out);
    }
}

/// The inputs of one [`PlainDenoiser::velocity`] call, as its vector and portable bodies take
/// them.
#[derive(Clone, Copy)]
struct VelocityBatch<'a> {
    t: usize,
    samples: &'a [f32],
    condition_embeddings: &'a [f32],
    rows: usize,
}

#[inline(always)]
fn grow(buffer: &mut Vec<f32>, len: usize) {
    if buffer.len() < len {
        buffer.resize(len, 0.0);
    }
}

/// `out = input · W + b` for `rows` rows.
#[inline(always)]
fn linear(values: &[f32], view: LinearView, input: &[f32], rows: usize, out: &mut [f32]) {
    out[..rows * view.outputs].fill(0.0);
    linear_accumulate(values, view, input, rows, out);
}

/// `out += input · W + b` for `rows` rows (the residual update of a block).
///
/// Register-blocked: [`ROW_BLOCK`] rows × [`LANE_BLOCK`] outputs accumulate in registers while
/// the inputs stream by, so each weight row is loaded once per row block; leftover rows and
/// outputs take narrower blocks. Every output is summed in input order, so the result does not
/// depend on the blocking.
#[inline(always)]
fn linear_accumulate(
    values: &[f32],
    view: LinearView,
    input: &[f32],
    rows: usize,
    out: &mut [f32],
) {
    let mut row = 0;
    while row + ROW_BLOCK <= rows {
        linear_rows::<ROW_BLOCK>(values, view, input, row, out);
        row += ROW_BLOCK;
    }
    while row < rows {
        linear_rows::<1>(values, view, input, row, out);
        row += 1;
    }
}

/// Rows per register block of [`linear_accumulate`].
const ROW_BLOCK: usize = 4;
/// Outputs per register block of [`linear_accumulate`].
const LANE_BLOCK: usize = 16;
/// Outputs per block of the outputs a [`LANE_BLOCK`] leaves over (a head's few outputs).
const NARROW_BLOCK: usize = 4;

/// `out += input · W + b` for rows `first … first + R`: blocks of [`LANE_BLOCK`] outputs, then
/// of [`NARROW_BLOCK`], then single outputs.
#[inline(always)]
fn linear_rows<const R: usize>(
    values: &[f32],
    view: LinearView,
    input: &[f32],
    first: usize,
    out: &mut [f32],
) {
    let column = linear_blocks::<R, LANE_BLOCK>(values, view, input, first, 0, out);
    let column = linear_blocks::<R, NARROW_BLOCK>(values, view, input, first, column, out);
    linear_blocks::<R, 1>(values, view, input, first, column, out);
}

/// Outputs `column…` of [`linear_rows`] in blocks of `L` while a whole block fits; returns the
/// first output left.
#[inline(always)]
fn linear_blocks<const R: usize, const L: usize>(
    values: &[f32],
    view: LinearView,
    input: &[f32],
    first: usize,
    mut column: usize,
    out: &mut [f32],
) -> usize {
    let (n_in, n_out) = (view.inputs, view.outputs);
    let weight = &values[view.weight..view.weight + n_in * n_out];
    let bias = &values[view.bias..view.bias + n_out];
    let x: [&[f32]; R] =
        std::array::from_fn(|r| &input[(first + r) * n_in..(first + r + 1) * n_in]);
    while column + L <= n_out {
        let mut acc = [[0.0f32; L]; R];
        for (i, w_row) in weight.chunks_exact(n_out).enumerate() {
            let w: &[f32; L] = w_row[column..column + L].try_into().expect("block");
            for r in 0..R {
                let a = x[r][i];
                for l in 0..L {
                    acc[r][l] += a * w[l];
                }
            }
        }
        for (r, acc_row) in acc.iter().enumerate() {
            let y = &mut out[(first + r) * n_out + column..(first + r) * n_out + column + L];
            for ((yl, al), bl) in y.iter_mut().zip(acc_row).zip(&bias[column..]) {
                *yl += al + bl;
            }
        }
        column += L;
    }
    column
}

/// LayerNorm of each `view.dim`-long row.
#[inline(always)]
fn layer_norm(values: &[f32], view: NormView, input: &[f32], rows: usize, out: &mut [f32]) {
    let d = view.dim;
    let gamma = &values[view.gamma..view.gamma + d];
    let beta = &values[view.beta..view.beta + d];
    for (x, y) in input[..rows * d]
        .chunks_exact(d)
        .zip(out[..rows * d].chunks_exact_mut(d))
    {
        let mean = x.iter().sum::<f32>() / d as f32;
        let variance = x.iter().map(|v| (v - mean) * (v - mean)).sum::<f32>() / d as f32;
        let scale = 1.0 / (variance + LAYER_NORM_EPSILON).sqrt();
        for (((yi, &xi), &g), &b) in y.iter_mut().zip(x).zip(gamma).zip(beta) {
            *yi = (xi - mean) * scale * g + b;
        }
    }
}

/// `x ← x·σ(x)` with a vectorisable exponential.
#[inline(always)]
fn silu_in_place(xs: &mut [f32]) {
    for x in xs {
        *x /= 1.0 + fast_exp(-*x);
    }
}

/// `eˣ` to about 2e-7 relative error: `2ⁿ · e^r` with `n = round(x/ln 2)`, `|r| ≤ ln 2 / 2` and a
/// degree-6 Taylor polynomial; branch-free so the compiler vectorises it.
#[inline(always)]
fn fast_exp(x: f32) -> f32 {
    const ROUND: f32 = 12_582_912.0; // 1.5·2²³: adding and subtracting rounds to an integer
    const LN2_HI: f32 = 0.693_145_75;
    const LN2_LO: f32 = 1.428_606_8e-6;
    let x = x.clamp(-87.0, 88.0);
    let n = (x * std::f32::consts::LOG2_E + ROUND) - ROUND;
    let r = x - n * LN2_HI - n * LN2_LO;
    let p = 1.0
        + r * (1.0
            + r * (0.5
                + r * (1.0 / 6.0 + r * (1.0 / 24.0 + r * (1.0 / 120.0 + r * (1.0 / 720.0))))));
    // 2ⁿ from its exponent bits: n + 127 + 2²³ is exact and its low mantissa bits are n + 127
    // (n is an integer in [−126, 127]); shifting by 23 drops the rest. Float arithmetic, unlike
    // a saturating float-to-int cast, vectorises.
    p * f32::from_bits((n + EXPONENT_BITS).to_bits() << 23)
}

/// `127 + 2²³`: the exponent bias, plus the power of two whose float has unit spacing.
const EXPONENT_BITS: f32 = 8_388_735.0;

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_block_shape_sums_like_the_plain_loop() {
        let value = |i: usize| (libm::sinf(i as f32 * 0.618) * 1.7).fract();
        let inputs = 23;
        // Row and output counts that use each block shape alone and together.
        for rows in [1, 3, 4, 5, 9] {
            for outputs in [1, 3, 4, 7, 16, 21, 37] {
                let view = LinearView {
                    weight: 5,
                    bias: 5 + inputs * outputs,
                    inputs,
                    outputs,
                };
                let values: Vec<f32> = (0..view.bias + outputs).map(value).collect();
                let input: Vec<f32> = (0..rows * inputs).map(|i| value(i + 911)).collect();
                let start: Vec<f32> = (0..rows * outputs).map(|i| value(i + 313)).collect();
                let mut blocked = start.clone();
                linear_accumulate(&values, view, &input, rows, &mut blocked);
                for r in 0..rows {
                    for j in 0..outputs {
                        let mut sum = 0.0f32;
                        for i in 0..inputs {
                            sum += input[r * inputs + i] * values[view.weight + i * outputs + j];
                        }
                        let want = start[r * outputs + j] + (sum + values[view.bias + j]);
                        let got = blocked[r * outputs + j];
                        assert_eq!(
                            got.to_bits(),
                            want.to_bits(),
                            "{rows}×{outputs}: ({r}, {j})"
                        );
                    }
                }
            }
        }
    }

    #[test]
    fn the_exponent_bits_are_every_power_of_two_fast_exp_takes() {
        for n in -126..=127 {
            let power = f32::from_bits((n as f32 + EXPONENT_BITS).to_bits() << 23);
            assert_eq!(power, 2f32.powi(n), "2^{n}");
        }
    }

    #[test]
    fn fast_exp_matches_the_library_exponential() {
        for i in -8000..8000 {
            let x = i as f32 * 0.01;
            let (fast, exact) = (fast_exp(x), libm::expf(x));
            assert!(
                ((fast - exact) / exact).abs() < 5e-7,
                "x = {x}: {fast} vs {exact}"
            );
        }
        assert!(fast_exp(-200.0) < 1e-37 && fast_exp(-200.0) >= 0.0);
    }
}
