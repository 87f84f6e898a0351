//! The Burn CPU backend choice shared by the training crates.

use serde::{Deserialize, Serialize};

/// The Burn CPU backend training runs on, chosen at run time by the tensor device.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Backend {
    /// Burn's pure-Rust `flex` backend.
    #[default]
    Flex,
    /// Burn's `ndarray` backend.
    Ndarray,
}

impl Backend {
    /// The (non-autodiff) device of this backend.
    #[cfg(feature = "train")]
    pub fn device(self) -> burn::tensor::Device {
        match self {
            Self::Flex => burn::tensor::Device::flex(),
            #[allow(deprecated)] // kept supported and tested beside flex, as the project asks
            Self::Ndarray => burn::tensor::Device::ndarray(),
        }
    }

    /// Name used in files and on the command line.
    pub fn name(self) -> &'static str {
        match self {
            Self::Flex => "flex",
            Self::Ndarray => "ndarray",
        }
    }
}
