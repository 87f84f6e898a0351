//! The planner's one configuration, which is also the `--config` JSON schema of `emg plan`:
//! rollout settings, classical gains, the hybrid switch and the reachability scan, every field
//! optional with SPEC defaults.

use std::path::Path;

use emg_control::{ClassicalGains, OutOfRange, RolloutConfig, Tracking};
use emg_hybrid::{BoundaryMeasure, SwitchConfig, SwitchConfigError};
use emg_kinematics::WorkSurface;
use serde::{Deserialize, Serialize};

use crate::controller::ExecutorConfig;
use crate::reach::ReachConfig;
use crate::search::SearchConfig;

/// Every setting of a plan; unset fields keep their defaults (SPEC §2–4, Sec. 4.3):
/// `rollout` ([`RolloutConfig`]: `dt_s` 0.05 s, `speed_m_per_s` 0.2 m/s, `max_steps` 500,
/// `null_speed_max_rad_per_s` 0.5, `lateral_gain_per_s` 5, constraints: `line_tolerance_m` 0.02,
/// `theta_max_deg` 30, `collision_margin_m` 0, `velocity_limit_fraction` 1; `tracking`
/// `first_order`, the paper's step), `gains`
/// ([`ClassicalGains`]: `k_mu` 0.8, `k_jl` 0.4, `k_theta` 0.2, `cone_gate_width_deg` 8,
/// `k_lead` 0),
/// `switch` ([`SwitchConfig`]: `tau_enter` 0.98, `tau_exit` 0.94), `measure`
/// ([`BoundaryMeasure`], default `rho`), `reach` ([`ReachConfig`]) and `search`
/// ([`SearchConfig`]).
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct PlannerConfig {
    /// Settings of the shared rollout loop.
    pub rollout: RolloutConfig,
    /// Gains of the classical controller.
    pub gains: ClassicalGains,
    /// Hysteresis thresholds of the hybrid switch.
    pub switch: SwitchConfig,
    /// Boundary measure of the hybrid switch.
    pub measure: BoundaryMeasure,
    /// The reachability scan ([`ReachConfig`]: `grid_m` 0.01, `restarts` 64, `branches` 4,
    /// `offsets` 6).
    pub reach: ReachConfig,
    /// The search planner ([`SearchConfig`]: `budget_steps` 10,000, `dp_samples` 32,
    /// `ik_restarts` 64, `finalists` 8, `repaired_starts` 8, `detour_steps` 10, its own
    /// `classical_gains`; 25,000 more steps at breadth 4 where a plan ends short of its
    /// bound, `widened_budget_steps` and `widened_breadth`; then, where it still ends short,
    /// motions planned back to `p0` from 95, 80, 65 and 50 % of the scan, `far_end_shares`;
    /// then, where it still ends below 0.95 × the bound (`beam_below_share`), a beam of 512
    /// members and 100,000 steps, `beam_width` and `beam_budget_steps`).
    pub search: SearchConfig,
}

/// Where a configuration's JSON sets the work surface.
const SURFACE_FIELD: &str = "/rollout/constraints/work_surface";

/// Where a configuration's JSON sets how the step tracks its line or path.
const TRACKING_FIELD: &str = "/rollout/tracking";

/// Why a configuration file cannot be used.
#[derive(Debug, thiserror::Error)]
pub enum ConfigError {
    /// The file cannot be read.
    #[error("cannot read config file {path}")]
    Io {
        /// The file.
        path: String,
        /// The cause.
        #[source]
        source: std::io::Error,
    },
    /// The text is not a planner configuration; the message names the field.
    #[error("invalid config file {path}: {message}")]
    Parse {
        /// The file.
        path: String,
        /// The JSON reader's message (field, value, line and column).
        message: String,
    },
    /// A value lies outside its allowed range.
    #[error("invalid configuration: {0}")]
    OutOfRange(#[from] OutOfRange),
    /// The switch thresholds are not `0 < τ_exit ≤ τ_enter ≤ 1`.
    #[error("invalid configuration: {0}")]
    Switch(#[from] SwitchConfigError),
}

impl PlannerConfig {
    /// The configuration of a work cell, what `emg plan` and Python plan with when given none:
    /// the defaults with the task's work plate on ([`WorkSurface::plate`]: the arm keeps off a
    /// plate under the line) and the corrected step ([`Tracking::Corrected`]: the TCP held on
    /// its line or path at any tolerance). [`PlannerConfig::default`] is the paper's protocol,
    /// with no work surface and the paper's step.
    pub fn cell() -> Self {
        let mut config = Self::default();
        config.rollout.constraints.work_surface = WorkSurface::plate();
        config.rollout.tracking = Tracking::Corrected;
        config
    }

    /// The controllers' settings.
    pub fn executor(&self) -> ExecutorConfig {
        ExecutorConfig {
            gains: self.gains.clone(),
            switch: self.switch.clone(),
            measure: self.measure.clone(),
        }
    }

    /// Checks every value against its allowed range ([`RolloutConfig::validate`],
    /// [`ClassicalGains::validate`], the switch thresholds and the boundary measure's scale);
    /// the error names the field, the value and the range.
    pub fn validate(&self) -> Result<(), ConfigError> {
        self.rollout.validate()?;
        self.gains.validate()?;
        self.switch.validate()?;
        self.reach.validate()?;
        self.search.validate()?;
        if let BoundaryMeasure::AllConstraints { clearance_scale_m } = self.measure {
            OutOfRange::require(
                "measure.clearance_scale_m",
                clearance_scale_m,
                "(0, ∞)",
                |v| v > 0.0,
            )?;
        }
        Ok(())
    }

    /// Reads and validates a configuration file (JSON).
    pub fn read(path: &Path) -> Result<Self, ConfigError> {
        let text = std::fs::read_to_string(path).map_err(|source| ConfigError::Io {
            path: path.display().to_string(),
            source,
        })?;
        Self::from_json(&path.display().to_string(), &text)
    }

    /// Parses and validates a configuration's JSON text; `origin` names it in errors. Unset
    /// fields keep the values of [`PlannerConfig::cell`]: a text that sets no
    /// `rollout.constraints.work_surface` plans with the work plate, one that sets no
    /// `rollout.tracking` with the corrected step.
    pub fn from_json(origin: &str, text: &str) -> Result<Self, ConfigError> {
        let parse_error = |e: serde_json::Error| ConfigError::Parse {
            path: origin.to_string(),
            message: e.to_string(),
        };
        let mut config: Self = serde_json::from_str(text).map_err(parse_error)?;
        let value: serde_json::Value = serde_json::from_str(text).map_err(parse_error)?;
        if value.pointer(SURFACE_FIELD).is_none() {
            config.rollout.constraints.work_surface = WorkSurface::plate();
        }
        if value.pointer(TRACKING_FIELD).is_none() {
            config.rollout.tracking = Tracking::Corrected;
        }
        config.validate()?;
        Ok(config)
    }
}
