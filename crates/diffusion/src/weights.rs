//! Exported denoiser weights: one flat little-endian `f32` array behind a JSON header naming the
//! network shape and the data set the weights were trained on.
//!
//! File layout: the magic `EMGDIFFW`, a `u32` format version, a `u32` header length, the JSON
//! [`WeightsHeader`], a `u64` value count, then the values in the order of [`parameter_layout`].

use std::path::Path;

#[cfg(feature = "train")]
use burn::module::Param;
#[cfg(feature = "train")]
use burn::nn::{LayerNorm, Linear};
#[cfg(feature = "train")]
use burn::tensor::{Device, Tensor, TensorData};
use emg_learning::container::{self, ContainerError, FileAccessError};
use serde::{Deserialize, Serialize};

use crate::config::DiffusionConfig;
#[cfg(feature = "train")]
use crate::model::Denoiser;

const MAGIC: &[u8; 8] = b"EMGDIFFW";

/// Version of the weights file layout.
pub const WEIGHTS_FORMAT_VERSION: u32 = 1;

/// What a weights file says about itself.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct WeightsHeader {
    /// The network shape.
    pub config: DiffusionConfig,
    /// The training data the weights came from (e.g. `data/labels/train-v1.labels`, its version).
    pub dataset: String,
    /// Optimiser steps the weights were trained for.
    pub train_steps: usize,
    /// The robot the weights were trained for (absent in files written before robots were
    /// recorded; the planner refuses such a file until it is stamped).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub robot: Option<emg_learning::RobotStamp>,
}

/// Why a weights file cannot be used.
#[derive(Debug, thiserror::Error)]
pub enum WeightsError {
    /// The file could not be read or written.
    #[error(transparent)]
    Io(#[from] FileAccessError),
    /// The bytes are not a well-formed denoiser weights file of this layout version (the cause
    /// says what is wrong: magic, version, truncation, header, value count, trailing bytes).
    #[error(
        "not a valid denoiser weights file (EMGDIFFW, format version {WEIGHTS_FORMAT_VERSION})"
    )]
    Format(#[from] ContainerError),
    /// The network shape differs from what the caller needs.
    #[error("weights field 'config.{field}' is {found}, but {expected} is required")]
    ShapeMismatch {
        /// The config field.
        field: &'static str,
        /// Required value.
        expected: usize,
        /// Value in the file.
        found: usize,
    },
    /// A value is NaN or infinite.
    #[error("weights value {index} ({tensor}) is not finite")]
    NotFinite {
        /// Flat index.
        index: usize,
        /// Tensor holding it.
        tensor: String,
    },
}

/// One named tensor of the flat layout.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct TensorSpec {
    /// Dotted name, e.g. `blocks.2.expand.weight`.
    pub name: String,
    /// Shape; linear weights are `[inputs, outputs]` (row-major, `y = x W + b`).
    pub shape: Vec<usize>,
}

impl TensorSpec {
    /// Number of values.
    pub fn len(&self) -> usize {
        self.shape.iter().product()
    }

    /// Whether the tensor holds no values.
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }
}

/// The tensors of a denoiser of shape `config`, in file order.
pub fn parameter_layout(config: &DiffusionConfig) -> Vec<TensorSpec> {
    let mut specs = Vec::new();
    let mut push = |name: String, shape: Vec<usize>| specs.push(TensorSpec { name, shape });
    let norm = |push: &mut dyn FnMut(String, Vec<usize>), name: &str, d: usize| {
        push(format!("{name}.gamma"), vec![d]);
        push(format!("{name}.beta"), vec![d]);
    };
    let linear = |push: &mut dyn FnMut(String, Vec<usize>), name: &str, i: usize, o: usize| {
        push(format!("{name}.weight"), vec![i, o]);
        push(format!("{name}.bias"), vec![o]);
    };
    let w = config.width;
    norm(&mut push, "condition_norm", config.condition_dim);
    linear(&mut push, "condition_in", config.condition_dim, w);
    linear(&mut push, "condition_out", w, w);
    linear(&mut push, "time_in", config.time_dim, 2 * w);
    linear(&mut push, "time_out", 2 * w, w);
    linear(&mut push, "sample_in", config.data_dim, w);
    for b in 0..config.blocks {
        norm(&mut push, &format!("blocks.{b}.norm"), w);
        linear(&mut push, &format!("blocks.{b}.expand"), w, config.hidden);
        linear(&mut push, &format!("blocks.{b}.contract"), config.hidden, w);
    }
    norm(&mut push, "output_norm", w);
    linear(&mut push, "head", w, config.data_dim);
    push("null_condition".into(), vec![config.condition_dim]);
    specs
}

/// A denoiser's weights as one flat `f32` array in [`parameter_layout`] order.
#[derive(Clone, Debug, PartialEq)]
pub struct DenoiserWeights {
    header: WeightsHeader,
    values: Vec<f32>,
}

impl DenoiserWeights {
    /// Wraps `values`, checking their count against the header's network shape.
    pub fn new(header: WeightsHeader, values: Vec<f32>) -> Result<Self, WeightsError> {
        let layout = parameter_layout(&header.config);
        let expected: usize = layout.iter().map(TensorSpec::len).sum();
        if values.len() != expected {
            return Err(WeightsError::Format(ContainerError::CountMismatch {
                expected,
                found: values.len(),
            }));
        }
        if let Some(index) = values.iter().position(|v| !v.is_finite()) {
            let mut start = 0;
            let tensor = layout
                .iter()
                .find(|spec| {
                    start += spec.len();
                    index < start
                })
                .map_or_else(String::new, |spec| spec.name.clone());
            return Err(WeightsError::NotFinite { index, tensor });
        }
        Ok(Self { header, values })
    }

    /// Reads the weights of a Burn denoiser built with `config`.
    #[cfg(feature = "train")]
    pub fn from_model(
        model: &Denoiser,
        config: &DiffusionConfig,
        dataset: &str,
        train_steps: usize,
    ) -> Self {
        let config = config.clone();
        let mut values =
            Vec::with_capacity(parameter_layout(&config).iter().map(TensorSpec::len).sum());
        visit_parameters(model, |tensor| {
            values.extend_from_slice(
                tensor
                    .as_slice::<f32>()
                    .expect("denoiser parameters are f32"),
            );
        });
        Self {
            header: WeightsHeader {
                config,
                dataset: dataset.to_string(),
                train_steps,

                robot: None,
            },
            values,
        }
    }

    /// A Burn denoiser on `device` holding these weights.
    #[cfg(feature = "train")]
    pub fn to_model(&self, device: &Device) -> Denoiser {
        let config = &self.header.config;
        let layout = parameter_layout(config);
        let mut offset = 0;
        let mut specs = layout.iter();
        let mut next_data = || {
            let spec = specs.next().expect("layout matches the model");
            let data = TensorData::new(
                self.values[offset..offset + spec.len()].to_vec(),
                spec.shape.clone(),
            );
            offset += spec.len();
            data
        };
        let mut model = Denoiser::new(config, device);
        let set_norm = |norm: &mut LayerNorm, next: &mut dyn FnMut() -> TensorData| {
            norm.gamma = Param::from_tensor(Tensor::from_data(next(), device));
            norm.beta = Some(Param::from_tensor(Tensor::from_data(next(), device)));
        };
        let set_linear = |linear: &mut Linear, next: &mut dyn FnMut() -> TensorData| {
            linear.weight = Param::from_tensor(Tensor::from_data(next(), device));
            linear.bias = Some(Param::from_tensor(Tensor::from_data(next(), device)));
        };
        set_norm(&mut model.condition_norm, &mut next_data);
        set_linear(&mut model.condition_in, &mut next_data);
        set_linear(&mut model.condition_out, &mut next_data);
        set_linear(&mut model.time_in, &mut next_data);
        set_linear(&mut model.time_out, &mut next_data);
        set_linear(&mut model.sample_in, &mut next_data);
        for block in &mut model.blocks {
            set_norm(&mut block.norm, &mut next_data);
            set_linear(&mut block.expand, &mut next_data);
            set_linear(&mut block.contract, &mut next_data);
        }
        set_norm(&mut model.output_norm, &mut next_data);
        set_linear(&mut model.head, &mut next_data);
        model.null_condition = Param::from_tensor(Tensor::from_data(next_data(), device));
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

    /// The network shape.
    pub fn config(&self) -> &DiffusionConfig {
        &self.header.config
    }

    /// The flat values.
    pub fn values(&self) -> &[f32] {
        &self.values
    }

    /// Mutable flat values (for the EMA update).
    #[cfg(feature = "train")]
    pub(crate) fn values_mut(&mut self) -> &mut [f32] {
        &mut self.values
    }

    /// Sets the training step count recorded in the header.
    #[cfg(feature = "train")]
    pub(crate) fn set_train_steps(&mut self, steps: usize) {
        self.header.train_steps = steps;
    }

    /// Fails unless the sample and condition dimensions are the ones required.
    pub fn require_dimensions(
        &self,
        data_dim: usize,
        condition_dim: usize,
    ) -> Result<(), WeightsError> {
        let config = &self.header.config;
        for (field, expected, found) in [
            ("data_dim", data_dim, config.data_dim),
            ("condition_dim", condition_dim, config.condition_dim),
        ] {
            if expected != found {
                return Err(WeightsError::ShapeMismatch {
                    field,
                    expected,
                    found,
                });
            }
        }
        Ok(())
    }

    /// The file bytes.
    pub fn to_bytes(&self) -> Vec<u8> {
        container::encode(MAGIC, WEIGHTS_FORMAT_VERSION, &self.header, &self.values)
    }

    /// Parses file bytes, rejecting truncated, padded or mismatched content with a clear error.
    pub fn from_bytes(bytes: &[u8]) -> Result<Self, WeightsError> {
        let (header, values) = container::decode_checked(
            bytes,
            MAGIC,
            WEIGHTS_FORMAT_VERSION,
            |h: &WeightsHeader| {
                parameter_layout(&h.config)
                    .iter()
                    .map(TensorSpec::len)
                    .sum()
            },
        )?;
        Self::new(header, values)
    }

    /// Writes the file (to a temporary sibling first, so an interrupted write loses nothing).
    pub fn write(&self, path: &Path) -> Result<(), WeightsError> {
        emg_io::write_atomically(path, self.to_bytes())
            .map_err(|source| FileAccessError::new(path, source).into())
    }

    /// Reads a weights file.
    pub fn read(path: &Path) -> Result<Self, WeightsError> {
        Self::from_bytes(&container::read_file(path)?)
    }
}

/// Calls `f` with the data of every parameter in [`parameter_layout`] order.
#[cfg(feature = "train")]
fn visit_parameters(model: &Denoiser, mut f: impl FnMut(&TensorData)) {
    let norm = |n: &LayerNorm, f: &mut dyn FnMut(&TensorData)| {
        f(&n.gamma.val().into_data());
        f(&n.beta
            .as_ref()
            .expect("LayerNorm with bias")
            .val()
            .into_data());
    };
    let linear = |l: &Linear, f: &mut dyn FnMut(&TensorData)| {
        f(&l.weight.val().into_data());
        f(&l.bias.as_ref().expect("Linear with bias").val().into_data());
    };
    norm(&model.condition_norm, &mut f);
    linear(&model.condition_in, &mut f);
    linear(&model.condition_out, &mut f);
    linear(&model.time_in, &mut f);
    linear(&model.time_out, &mut f);
    linear(&model.sample_in, &mut f);
    for block in &model.blocks {
        norm(&block.norm, &mut f);
        linear(&block.expand, &mut f);
        linear(&block.contract, &mut f);
    }
    norm(&model.output_norm, &mut f);
    linear(&model.head, &mut f);
    f(&model.null_condition.val().into_data());
}
