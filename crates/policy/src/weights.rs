//! Exported policy weights: one flat little-endian `f32` array behind a JSON header naming the
//! network shape.
//!
//! File layout: the magic `EMGPPOWT`, a `u32` format version, a `u32` header length, the JSON
//! [`WeightsHeader`], a `u64` value count, then the values layer by layer in the order of
//! [`layer_shapes`], each layer its weight (`[in, out]`, row-major) then its bias (`[out]`).

use std::path::Path;

#[cfg(feature = "train")]
use burn::module::Param;
#[cfg(feature = "train")]
use burn::nn::Linear;
#[cfg(feature = "train")]
use burn::tensor::{Device, Tensor, TensorData};
use emg_learning::container::{self, ContainerError, FileAccessError};
use serde::{Deserialize, Serialize};

use crate::config::NetworkConfig;
use crate::format::{WEIGHTS_FORMAT_VERSION, WeightsError};
#[cfg(feature = "train")]
use crate::network::ActorCritic;
use crate::observation::PolicyDims;
use emg_kinematics::{MAX_DOF, MIN_DOF};

const MAGIC: &[u8; 8] = b"EMGPPOWT";

/// What a weights file says about itself.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct WeightsHeader {
    /// Hidden layer widths of the actor and the critic.
    pub network: NetworkConfig,
    /// Observation length the network reads (`3n + 10`: 31 for seven joints).
    pub observation_dim: usize,
    /// Action length the network writes (`n − 3`: 4 for seven joints).
    pub action_dim: usize,
    /// Clamp range of the log standard deviation, `[min, max]`.
    pub log_std_range: [f64; 2],
    /// Environment steps the weights were trained for.
    pub env_steps: u64,
    /// The robot the weights were trained for (absent in files written before robots were
    /// recorded; the planner refuses such a file until it is stamped).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub robot: Option<emg_learning::RobotStamp>,
}

/// `(inputs, outputs)` of every linear layer in file order: actor hidden layers, mean head,
/// log-std head, critic hidden layers, value head.
pub fn layer_shapes(network: &NetworkConfig) -> Vec<(usize, usize)> {
    let dims = PolicyDims::for_joints(network.joints);
    let trunk = || {
        let mut width = dims.observation;
        network.hidden.iter().map(move |&next| {
            let shape = (width, next);
            width = next;
            shape
        })
    };
    let last = network.hidden.last().copied().unwrap_or(dims.observation);
    trunk()
        .chain([(last, dims.action), (last, dims.action)])
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
        let joints = header.network.joints;
        if !(MIN_DOF..=MAX_DOF).contains(&joints) {
            return Err(WeightsError::Format(ContainerError::BadHeader(format!(
                "network.joints is {joints}; arms of {MIN_DOF} or {MAX_DOF} joints are supported"
            ))));
        }
        let dims = PolicyDims::for_joints(joints);
        for (field, expected, found) in [
            ("observation_dim", dims.observation, header.observation_dim),
            ("action_dim", dims.action, header.action_dim),
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
            return Err(WeightsError::Format(ContainerError::BadHeader(format!(
                "network.hidden[{width}] is 0; every hidden layer needs a positive width"
            ))));
        }
        let expected = value_count(&header.network);
        if values.len() != expected {
            return Err(WeightsError::Format(ContainerError::CountMismatch {
                expected,
                found: values.len(),
            }));
        }
        if let Some(index) = values.iter().position(|v| !v.is_finite()) {
            return Err(WeightsError::NotFinite(index));
        }
        Ok(Self { header, values })
    }

    /// The current weights of `model` (on any device, autodiff or not).
    #[cfg(feature = "train")]
    pub fn from_model(
        model: &ActorCritic,
        network: &NetworkConfig,
        log_std_range: (f64, f64),
        env_steps: u64,
    ) -> Self {
        let dims = PolicyDims::for_joints(network.joints);
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
                observation_dim: dims.observation,
                action_dim: dims.action,
                log_std_range: [log_std_range.0, log_std_range.1],
                env_steps,

                robot: None,
            },
            values,
        }
    }

    /// A Burn model holding these weights on `device`.
    #[cfg(feature = "train")]
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

    /// The same weights recorded as trained for `robot` (the values are unchanged).
    pub fn stamped(mut self, robot: emg_learning::RobotStamp) -> Self {
        self.header.robot = Some(robot);
        self
    }

    /// The values in file order.
    pub fn values(&self) -> &[f32] {
        &self.values
    }

    /// The file's bytes.
    pub fn to_bytes(&self) -> Vec<u8> {
        container::encode(MAGIC, WEIGHTS_FORMAT_VERSION, &self.header, &self.values)
    }

    /// Parses a file's bytes, with a clear error for a truncated or mismatched file.
    pub fn from_bytes(bytes: &[u8]) -> Result<Self, WeightsError> {
        let (header, values) = container::decode_checked(
            bytes,
            MAGIC,
            WEIGHTS_FORMAT_VERSION,
            |h: &WeightsHeader| value_count(&h.network),
        )?;
        Self::new(header, values)
    }

    /// Writes the file (via a `.partial` sibling renamed into place).
    pub fn write(&self, path: &Path) -> Result<(), WeightsError> {
        emg_io::write_atomically(path, self.to_bytes())
            .map_err(|source| FileAccessError::new(path, source).into())
    }

    /// Reads a file written by [`PolicyWeights::write`].
    pub fn read(path: &Path) -> Result<Self, WeightsError> {
        Self::from_bytes(&container::read_file(path)?)
    }
}

#[cfg(feature = "train")]
fn layers(model: &ActorCritic) -> impl Iterator<Item = &Linear> {
    model
        .actor
        .layers
        .iter()
        .chain([&model.mean, &model.log_std])
        .chain(&model.critic.layers)
        .chain([&model.value])
}
