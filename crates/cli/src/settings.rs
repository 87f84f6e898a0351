//! The optional `--config` file: rollout settings, controller gains and the hybrid switch.

use std::path::Path;

use anyhow::{Context, Result};
use emg_control::{ClassicalGains, RolloutConfig};
use emg_hybrid::{BoundaryMeasure, ExecutorConfig, SwitchConfig};
use serde::{Deserialize, Serialize};

/// Contents of a `--config` JSON file; every field is optional and defaults to SPEC values.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct Settings {
    /// Settings of the shared rollout loop.
    pub rollout: RolloutConfig,
    /// Gains of the classical controller.
    pub gains: ClassicalGains,
    /// Hysteresis thresholds of the hybrid switch.
    pub switch: SwitchConfig,
    /// Boundary measure of the hybrid switch.
    pub measure: BoundaryMeasure,
}

impl Settings {
    /// The controllers' settings.
    pub fn executor(&self) -> ExecutorConfig {
        ExecutorConfig {
            gains: self.gains.clone(),
            switch: self.switch.clone(),
            measure: self.measure.clone(),
        }
    }

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
