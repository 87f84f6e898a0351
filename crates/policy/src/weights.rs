//! Exported policy weights: one flat little-endian `f32` array behind a JSON header naming the
//! network shape.
//!
//! File layout: the magic `EMGPPOWT`, a `u32` format version, a `u32` header length, the JSON
//! [`WeightsHeader`], a `u64` value count, then the values layer by layer in the order of
//! [`layer_shapes`], each layer its weight (`[in, out]`, row-major) then its bias (`[out]`).

use std::io::Write;
use std::path::Path;

use burn::module::Param;
use burn::nn::Linear;
use burn::tensor::{Device, Tensor, TensorData};
use serde::{Deserialize, Serialize};

use crate::config::NetworkConfig;
use crate::network::ActorCritic;
use crate::observation::{ACTION_DIM, OBSERVATION_DIM};

const MAGIC: &[u8; 8] = b"EMGPPOWT";

/// Version of the weights file layout this build reads and writes.
pub const WEIGHTS_FORMAT_VERSION: u32 = 1;

/// What a weights file says about itself.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct WeightsHeader {
    /// Hidden layer widths of the actor and the critic.
    pub network: NetworkConfig,
    /// Observation length the network reads (31).
    pub observation_dim: usize,
    /// Action length the network writes (4).
    pub action_dim: usize,
    /// Clamp range of the log standard deviation, `[min, max]`.
    pub log_std_range: [f64; 2],
    /// Environment steps the weights were trained for.
    pub env_steps: u64,
}

/// Why a weights file is unusable; every variant says what is wrong.
#[derive(Debug, thiserror::Error)]
pub enum WeightsError {
    /// The file could not be read or written.
    #[error("weights file {path}: {source}")]
    Io {
        /// File.
        path: String,
        /// Cause.
        source: std::io::Error,
    },
    /// The file does not start with the magic bytes.
    #[error("not a policy weights file (missing the EMGPPOWT magic)")]
    BadMagic,
    /// A layout version this build cannot read.
    #[error(
        "weights format version {found} is not supported (this build reads {WEIGHTS_FORMAT_VERSION})"
    )]
    UnsupportedVersion {
        /// Version in the file.
        found: u32,
    },
    /// The file ends early.
    #[error(
        "weights file is truncated: it ends inside the {part} ({expected} bytes needed, {found} present)"
    )]
    Truncated {
        /// `header` or `values`.
        part: &'static str,
        /// Bytes needed.
        expected: usize,
        /// Bytes present.
        found: usize,
    },
    /// The JSON header does not parse.
    #[error("weights header is not valid: {0}")]
    BadHeader(String),
    /// The value count disagrees with the header's network shape.
    #[error("weights hold {found} values but the header's network shape needs {expected}")]
    CountMismatch {
        /// Values the shape needs.
        expected: usize,
        /// Values present.
        found: usize,
    },
    /// Bytes after the values.
    #[error("weights file has {0} unexpected bytes after the values")]
    TrailingBytes(usize),
    /// A header field disagrees with what this build uses.
    #[error("weights field '{field}' is {found}, but {expected} is required")]
    ShapeMismatch {
        /// Header field.
        field: &'static str,
        /// Required value.
        expected: usize,
        /// Value in the file.
        found: usize,
    },
    /// A NaN or infinite value.
    #[error("weights value {0} is not finite")]
    NotFinite(usize),
}

/// `(inputs, outputs)` of every linear layer in file order: actor hidden layers, mean head,
/// log-std head, critic hidden layers, value head.
pub fn layer_shapes(network: &NetworkConfig) -> Vec<(usize, usize)> {
    let trunk = || {
        let mut width = OBSERVATION_DIM;
        network.hidden.iter().map(move |&next| {
            let shape = (width, next);
            width = next;
            shape
        })
    };
    let last = network.hidden.last().copied().unwrap_or(OBSERVATION_DIM);
    trunk()
        .chain([(last, ACTION_DIM), (last, ACTION_DIM)])
        .chain(trunk())
        .chain([(last, 1)])
        .collect()
}

fn value_count(network: &NetworkConfig) -> usize {
    layer_shapes(network).iter().map(|(i, o)| i * o + o).sum()
}

/// The weights of an [`ActorCritic`] as plain `f32` values, with their header.
#[derive(Clone, Debug, PartialEq)]
pub struct PolicyWeights {
    header: WeightsHeader,
    values: Vec<f32>,
}

impl PolicyWeights {
    /// Weights from a header and values, checked for shape and finiteness.
    pub fn new(header: WeightsHeader, values: Vec<f32>) -> Result<Self, WeightsError> {
        for (field, expected, found) in [
            ("observation_dim", OBSERVATION_DIM, header.observation_dim),
            ("action_dim", ACTION_DIM, header.action_dim),
        ] {
            if expected != found {
                return Err(WeightsError::ShapeMismatch {
                    field,
                    expected,
                    found,
                });
            }
        }
        if let Some(width) = header.network.hidden.iter().position(|&w| w == 0) {
            return Err(WeightsError::BadHeader(format!(
                "network.hidden[{width}] is 0; every hidden layer needs a positive width"
            )));
        }
        let expected = value_count(&header.network);
        if values.len() != expected {
            return Err(WeightsError::CountMismatch {
                expected,
                found: values.len(),
            });
        }
        if let Some(index) = values.iter().position(|v| !v.is_finite()) {
            return Err(WeightsError::NotFinite(index));
        }
        Ok(Self { header, values })
    }

    /// The current weights of `model` (on any device, autodiff or not).
    pub fn from_model(
        model: &ActorCritic,
        network: &NetworkConfig,
        log_std_range: (f64, f64),
        env_steps: u64,
    ) -> Self {
        let mut values = Vec::with_capacity(value_count(network));
        for linear in layers(model) {
            for tensor in [
                linear.weight.val().into_data(),
                linear
                    .bias
                    .as_ref()
                    .expect("layers have biases")
                    .val()
                    .into_data(),
            ] {
                values.extend_from_slice(tensor.as_slice::<f32>().expect("f32 parameters"));
            }
        }
        Self {
            header: WeightsHeader {
                network: network.clone(),
                observation_dim: OBSERVATION_DIM,
                action_dim: ACTION_DIM,
                log_std_range: [log_std_range.0, log_std_range.1],
                env_steps,
            },
            values,
        }
    }

    /// A Burn model holding these weights on `device`.
    pub fn to_model(&self, device: &Device) -> ActorCritic {
        let mut model = ActorCritic::new(&self.header.network, 0.0, device);
        let mut offset = 0;
        let mut take = |shape: Vec<usize>| {
            let len: usize = shape.iter().product();
            let data = TensorData::new(self.values[offset..offset + len].to_vec(), shape);
            offset += len;
            data
        };
        let set = |linear: &mut Linear, take: &mut dyn FnMut(Vec<usize>) -> TensorData| {
            let [input, output] = linear.weight.val().dims();
            linear.weight =
                Param::from_tensor(Tensor::from_data(take(vec![input, output]), device));
            linear.bias = Some(Param::from_tensor(Tensor::from_data(
                take(vec![output]),
                device,
            )));
        };
        for linear in model.actor.layers.iter_mut() {
            set(linear, &mut take);
        }
        set(&mut model.mean, &mut take);
        set(&mut model.log_std, &mut take);
        for linear in model.critic.layers.iter_mut() {
            set(linear, &mut take);
        }
        set(&mut model.value, &mut take);
        model
    }

    /// The header.
    pub fn header(&self) -> &WeightsHeader {
        &self.header
    }

    /// The values in file order.
    pub fn values(&self) -> &[f32] {
        &self.values
    }

    /// The file's bytes.
    pub fn to_bytes(&self) -> Vec<u8> {
        let header = serde_json::to_vec(&self.header).expect("header serialises");
        let mut bytes = Vec::with_capacity(24 + header.len() + 4 * self.values.len());
        bytes.extend_from_slice(MAGIC);
        bytes.extend_from_slice(&WEIGHTS_FORMAT_VERSION.to_le_bytes());
        bytes.extend_from_slice(&(header.len() as u32).to_le_bytes());
        bytes.extend_from_slice(&header);
        bytes.extend_from_slice(&(self.values.len() as u64).to_le_bytes());
        for v in &self.values {
            bytes.extend_from_slice(&v.to_le_bytes());
        }
        bytes
    }

    /// Parses a file's bytes, with a clear error for a truncated or mismatched file.
    pub fn from_bytes(bytes: &[u8]) -> Result<Self, WeightsError> {
        let mut cursor = Cursor { bytes, at: 0 };
        if cursor.take(8, "header")? != MAGIC {
            return Err(WeightsError::BadMagic);
        }
        let version = u32::from_le_bytes(cursor.array::<4>("header")?);
        if version != WEIGHTS_FORMAT_VERSION {
            return Err(WeightsError::UnsupportedVersion { found: version });
        }
        let header_len = u32::from_le_bytes(cursor.array::<4>("header")?) as usize;
        let header: WeightsHeader = serde_json::from_slice(cursor.take(header_len, "header")?)
            .map_err(|e| WeightsError::BadHeader(e.to_string()))?;
        let count = u64::from_le_bytes(cursor.array::<8>("header")?) as usize;
        let expected = value_count(&header.network);
        if count != expected {
            return Err(WeightsError::CountMismatch {
                expected,
                found: count,
            });
        }
        let values = cursor
            .take(4 * count, "values")?
            .chunks_exact(4)
            .map(|c| f32::from_le_bytes(c.try_into().expect("4 bytes")))
            .collect();
        let rest = bytes.len() - cursor.at;
        if rest != 0 {
            return Err(WeightsError::TrailingBytes(rest));
        }
        Self::new(header, values)
    }

    /// Writes the file (via a `.partial` sibling renamed into place).
    pub fn write(&self, path: &Path) -> Result<(), WeightsError> {
        let io = |source| WeightsError::Io {
            path: path.display().to_string(),
            source,
        };
        let partial = path.with_extension("partial");
        let mut file = std::fs::File::create(&partial).map_err(io)?;
        file.write_all(&self.to_bytes()).map_err(io)?;
        file.sync_all().map_err(io)?;
        std::fs::rename(&partial, path).map_err(io)
    }

    /// Reads a file written by [`PolicyWeights::write`].
    pub fn read(path: &Path) -> Result<Self, WeightsError> {
        let bytes = std::fs::read(path).map_err(|source| WeightsError::Io {
            path: path.display().to_string(),
            source,
        })?;
        Self::from_bytes(&bytes)
    }
}

fn layers(model: &ActorCritic) -> impl Iterator<Item = &Linear> {
    model
        .actor
        .layers
        .iter()
        .chain([&model.mean, &model.log_std])
        .chain(&model.critic.layers)
        .chain([&model.value])
}

struct Cursor<'a> {
    bytes: &'a [u8],
    at: usize,
}

impl<'a> Cursor<'a> {
    fn take(&mut self, n: usize, part: &'static str) -> Result<&'a [u8], WeightsError> {
        let end = self.at + n;
        if end > self.bytes.len() {
            return Err(WeightsError::Truncated {
                part,
                expected: end,
                found: self.bytes.len(),
            });
        }
        let slice = &self.bytes[self.at..end];
        self.at = end;
        Ok(slice)
    }

    fn array<const N: usize>(&mut self, part: &'static str) -> Result<[u8; N], WeightsError> {
        Ok(self.take(N, part)?.try_into().expect("N bytes"))
    }
}
