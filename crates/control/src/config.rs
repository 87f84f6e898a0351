//! Every constant of the rollout and the classical controller, with SPEC defaults (serde).

use emg_kinematics::{BasisConfig, DampingConfig};
use serde::{Deserialize, Serialize};

/// The constraints a rollout must hold at every step (SPEC §2).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct ConstraintConfig {
    /// Largest lateral distance `ε_pos` of the TCP from the task line (m).
    pub line_tolerance_m: f64,
    /// Largest angle `θ_max` between the tool axis and the task normal (degrees).
    pub theta_max_deg: f64,
    /// Smallest clearance between checked capsule pairs (m); 0 means "not touching".
    pub collision_margin_m: f64,
    /// Joint speeds stay within this fraction of the robot file's velocity limits; `None` (JSON
    /// `null`) leaves joint speeds unbounded, as the paper's runs do. Steps that would be faster
    /// are slowed down in time, not changed in shape (see [`crate::Episode`]).
    pub velocity_limit_fraction: Option<VelocityLimitFraction>,
}

impl Default for ConstraintConfig {
    fn default() -> Self {
        Self {
            line_tolerance_m: 0.02,
            theta_max_deg: 30.0,
            collision_margin_m: 0.0,
            velocity_limit_fraction: Some(VelocityLimitFraction::FULL),
        }
    }
}

/// A configuration value outside its allowed range; names the field, the value and the range.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
#[error("{field} must be in {allowed}, got {value}")]
pub struct OutOfRange {
    /// The field.
    pub field: &'static str,
    /// The value given.
    pub value: f64,
    /// The allowed range.
    pub allowed: &'static str,
}

/// A fraction in `(0, 1]` of the joint-velocity limits; reading any other value is an error that
/// names the field.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(try_from = "f64", into = "f64")]
pub struct VelocityLimitFraction(f64);

impl VelocityLimitFraction {
    /// The whole limit.
    pub const FULL: Self = Self(1.0);

    /// `fraction` if it lies in `(0, 1]`.
    pub fn new(fraction: f64) -> Result<Self, OutOfRange> {
        if fraction > 0.0 && fraction <= 1.0 {
            Ok(Self(fraction))
        } else {
            Err(OutOfRange {
                field: "velocity_limit_fraction",
                value: fraction,
                allowed: "(0, 1]",
            })
        }
    }

    /// The fraction as a number.
    pub fn get(self) -> f64 {
        self.0
    }
}

impl TryFrom<f64> for VelocityLimitFraction {
    type Error = OutOfRange;

    fn try_from(fraction: f64) -> Result<Self, OutOfRange> {
        Self::new(fraction)
    }
}

impl From<VelocityLimitFraction> for f64 {
    fn from(fraction: VelocityLimitFraction) -> f64 {
        fraction.0
    }
}

/// Settings of the shared rollout loop (SPEC §3–4, Eq. 2).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct RolloutConfig {
    /// Control period `Δt` (s).
    pub dt_s: f64,
    /// Commanded TCP speed `v` along the line (m/s).
    pub speed_m_per_s: f64,
    /// Step cap of one rollout.
    pub max_steps: usize,
    /// Null-space speed bound `a_max` (rad/s): `q̇_null = a_max·B a`, `a ∈ [−1, 1]⁴`.
    pub null_speed_max_rad_per_s: f64,
    /// Lateral correction gain `k_lat` (1/s) of the task command `ẋ = v d + k_lat e_lat`.
    pub lateral_gain_per_s: f64,
    /// Damping `λ_μ` inside the directional manipulability `w_d`.
    pub manipulability_damping: f64,
    /// Variable damping of the pseudo-inverse.
    pub damping: DampingConfig,
    /// Gram–Schmidt thresholds of `B(q)`.
    pub basis: BasisConfig,
    /// Constraints checked after every step.
    pub constraints: ConstraintConfig,
}

impl Default for RolloutConfig {
    fn default() -> Self {
        Self {
            dt_s: 0.05,
            speed_m_per_s: 0.2,
            max_steps: 500,
            null_speed_max_rad_per_s: 0.5,
            lateral_gain_per_s: 5.0,
            manipulability_damping: 1e-3,
            damping: DampingConfig::default(),
            basis: BasisConfig::default(),
            constraints: ConstraintConfig::default(),
        }
    }
}

/// Gains of the classical secondary command `ξ` (Eq. 3).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct ClassicalGains {
    /// `k_μ`: weight of the directional-manipulability gradient.
    pub k_mu: f64,
    /// `k_jl`: weight of joint centring.
    pub k_jl: f64,
    /// `k_θ`: weight of the gated tool-cone term.
    pub k_theta: f64,
    /// Width of the cone gate `g(θ)` (degrees): active only this close to `θ_max`.
    pub cone_gate_width_deg: f64,
}

impl Default for ClassicalGains {
    fn default() -> Self {
        Self {
            k_mu: 0.8,
            k_jl: 0.4,
            k_theta: 0.2,
            cone_gate_width_deg: 8.0,
        }
    }
}
