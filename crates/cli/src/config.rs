//! The `--config` option of `emg plan` and `emg check`: a planner configuration given as a file or
//! as inline JSON.

use std::path::Path;

use anyhow::Result;
use emg_planner::PlannerConfig;

/// The `--config` option: inline JSON when it starts with `{`, else a file.
pub fn read_config(config: &Path) -> Result<PlannerConfig> {
    match inline_json(config) {
        Some(text) => Ok(PlannerConfig::from_json("--config", text)?),
        None => Ok(PlannerConfig::read(config)?),
    }
}

/// The JSON text of a `--config` value given inline (starting with `{`), `None` for a file.
pub fn inline_json(config: &Path) -> Option<&str> {
    config
        .to_str()
        .map(str::trim_start)
        .filter(|text| text.starts_with('{'))
}
