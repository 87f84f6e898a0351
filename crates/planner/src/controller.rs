//! The controllers the executor offers, chosen by name: classical, learned, or hybrid.

use emg_control::{
    ActingController, ClassicalController, ClassicalGains, NullAction, NullSpaceController,
    StepContext,
};
use emg_policy::RlController;
use serde::{Deserialize, Serialize};

use emg_hybrid::{
    BoundaryMeasure, HybridController, HysteresisSwitch, SwitchConfig, SwitchConfigError,
};

/// Which null-space controller drives a rollout.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum ControllerKind {
    /// The classical controller everywhere (Eq. 3).
    Classical,
    /// The learned policy everywhere (Sec. 4.2).
    Rl,
    /// Learned inside, classical in the boundary shell (Sec. 4.3).
    Hybrid,
}

impl ControllerKind {
    /// All controllers in table order.
    pub const ALL: [ControllerKind; 3] = [Self::Classical, Self::Rl, Self::Hybrid];

    /// Lower-case name used in files and command lines.
    pub fn name(self) -> &'static str {
        match self {
            Self::Classical => "classical",
            Self::Rl => "rl",
            Self::Hybrid => "hybrid",
        }
    }

    /// Name for tables (`Classical`, `RL`, `Hybrid`).
    pub fn title(self) -> &'static str {
        match self {
            Self::Classical => "Classical",
            Self::Rl => "RL",
            Self::Hybrid => "Hybrid",
        }
    }

    /// Whether it needs a trained policy.
    pub fn needs_policy(self) -> bool {
        !matches!(self, Self::Classical)
    }
}

impl std::str::FromStr for ControllerKind {
    type Err = crate::parse::ParseError;

    /// `classical`, `rl` or `hybrid`.
    fn from_str(s: &str) -> Result<Self, Self::Err> {
        Self::ALL
            .into_iter()
            .find(|kind| kind.name() == s)
            .ok_or_else(|| crate::parse::ParseError::Controller(s.to_string()))
    }
}

impl std::fmt::Display for ControllerKind {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.name())
    }
}

/// Settings of the controllers (SPEC §4 gains, Sec. 4.3 switch).
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct ExecutorConfig {
    /// Classical gains.
    pub gains: ClassicalGains,
    /// Hysteresis thresholds of the hybrid switch.
    pub switch: SwitchConfig,
    /// Boundary measure the switch compares with its thresholds.
    pub measure: BoundaryMeasure,
}

/// Why a controller could not be built.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum ExecutorError {
    /// The controller needs a trained policy and none was given.
    #[error("the {0} controller needs trained policy weights")]
    MissingPolicy(&'static str),
    /// The switch thresholds are invalid.
    #[error(transparent)]
    Switch(#[from] SwitchConfigError),
}

/// One of the offered controllers, ready for a rollout.
#[derive(Clone)]
pub enum Executor {
    /// Classical everywhere.
    Classical(ClassicalController),
    /// Learned everywhere.
    Rl(RlController),
    /// Learned inside, classical near the boundary.
    Hybrid(HybridController<RlController>),
}

impl Executor {
    /// Builds the `kind` controller; `policy` is cloned for the learned parts.
    pub fn new(
        kind: ControllerKind,
        policy: Option<&RlController>,
        config: &ExecutorConfig,
    ) -> Result<Self, ExecutorError> {
        let classical = ClassicalController::new(config.gains.clone());
        let policy = || {
            policy
                .cloned()
                .ok_or(ExecutorError::MissingPolicy(kind.name()))
        };
        Ok(match kind {
            ControllerKind::Classical => Self::Classical(classical),
            ControllerKind::Rl => Self::Rl(policy()?),
            ControllerKind::Hybrid => Self::Hybrid(HybridController::new(
                policy()?,
                classical,
                HysteresisSwitch::new(config.switch.clone())?,
                config.measure.clone(),
            )),
        })
    }
}

impl NullSpaceController for Executor {
    fn reset(&mut self, first: &StepContext<'_>) {
        match self {
            Self::Classical(c) => c.reset(first),
            Self::Rl(c) => c.reset(first),
            Self::Hybrid(c) => c.reset(first),
        }
    }

    fn act(&mut self, step: &StepContext<'_>) -> (NullAction, ActingController) {
        match self {
            Self::Classical(c) => c.act(step),
            Self::Rl(c) => c.act(step),
            Self::Hybrid(c) => c.act(step),
        }
    }
}
