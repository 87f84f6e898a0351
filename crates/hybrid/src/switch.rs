//! The hysteresis rule of Sec. 4.3 (Eq. 8): learned policy inside, classical near the boundary.

use serde::{Deserialize, Serialize};

/// Thresholds of the switch, `τ_enter ≥ τ_exit`.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct SwitchConfig {
    /// While the learned policy acts, hand over to the classical controller once the boundary
    /// measure reaches `τ_enter`.
    pub tau_enter: f64,
    /// While the classical controller acts, hand back once the measure falls below `τ_exit`.
    pub tau_exit: f64,
}

impl Default for SwitchConfig {
    fn default() -> Self {
        Self {
            tau_enter: 0.98,
            tau_exit: 0.94,
        }
    }
}

/// Why a switch configuration is unusable.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
#[error("switch thresholds: tau_enter = {tau_enter} must be ≥ tau_exit = {tau_exit}, both finite")]
pub struct SwitchConfigError {
    /// The entry threshold given.
    pub tau_enter: f64,
    /// The exit threshold given.
    pub tau_exit: f64,
}

impl SwitchConfig {
    /// Checks `τ_enter ≥ τ_exit` (both finite).
    pub fn validate(&self) -> Result<(), SwitchConfigError> {
        if self.tau_enter.is_finite()
            && self.tau_exit.is_finite()
            && self.tau_enter >= self.tau_exit
        {
            Ok(())
        } else {
            Err(SwitchConfigError {
                tau_enter: self.tau_enter,
                tau_exit: self.tau_exit,
            })
        }
    }
}

/// Which regime acts.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Regime {
    /// The learned policy (interior).
    Learned,
    /// The classical controller (boundary shell).
    Classical,
}

/// The hysteresis state machine: a pure function of the boundary-measure sequence.
#[derive(Clone, Debug)]
pub struct HysteresisSwitch {
    config: SwitchConfig,
    regime: Regime,
    switches: usize,
}

impl HysteresisSwitch {
    /// A switch with validated thresholds, before the first step.
    pub fn new(config: SwitchConfig) -> Result<Self, SwitchConfigError> {
        config.validate()?;
        Ok(Self {
            config,
            regime: Regime::Learned,
            switches: 0,
        })
    }

    /// Starts an episode: classical when the seed already lies in the shell (`measure ≥ τ_enter`),
    /// else learned. Resets the switch count.
    pub fn start(&mut self, measure: f64) -> Regime {
        self.switches = 0;
        self.regime = if measure >= self.config.tau_enter {
            Regime::Classical
        } else {
            Regime::Learned
        };
        self.regime
    }

    /// The regime for a step whose boundary measure is `measure`.
    pub fn update(&mut self, measure: f64) -> Regime {
        let next = match self.regime {
            Regime::Learned if measure >= self.config.tau_enter => Regime::Classical,
            Regime::Classical if measure < self.config.tau_exit => Regime::Learned,
            unchanged => unchanged,
        };
        if next != self.regime {
            self.switches += 1;
            self.regime = next;
        }
        next
    }

    /// The regime now acting.
    pub fn regime(&self) -> Regime {
        self.regime
    }

    /// Switches since [`HysteresisSwitch::start`].
    pub fn switches(&self) -> usize {
        self.switches
    }
}
