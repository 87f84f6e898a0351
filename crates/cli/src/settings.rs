//! The optional `--config` file: rollout settings and controller gains.

use std::path::Path;

use anyhow::{Context, Result};
use emg_control::{ClassicalGains, RolloutConfig};
use serde::{Deserialize, Serialize};

/// Contents of a `--config` JSON file; every field is optional and defaults to SPEC values.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct Settings {
    /// Settings of the shared rollout loop.
    pub rollout: RolloutConfig,
    /// Gains of the classical controller.
    pub gains: ClassicalGains,
}

impl Settings {
    /// Reads a config file, or the defaults when none is given.
    pub fn load(path: Option<&Path>) -> Result<Self> {
        let Some(path) = path else {
            return Ok(Self::default());
        };
        let text = std::fs::read_to_string(path)
            .with_context(|| format!("cannot read config file {}", path.display()))?;
        serde_json::from_str(&text)
            .with_context(|| format!("invalid config file {}", path.display()))
    }
}
