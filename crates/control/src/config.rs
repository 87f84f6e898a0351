//! Every constant of the rollout and the classical controller, with SPEC defaults (serde).

use emg_kinematics::{BasisConfig, DampingConfig, JointVector, Scene, WorkSurface};
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
    /// The task's work surface, which every capsule of the arm but the tool's keeps off (SPEC
    /// §9: material on `(x − p0)·n > 0`): a finite plate under the line or the whole
    /// half-space. Off by default, as in the paper's protocol; `emg plan` and Python plan with
    /// the default plate.
    #[serde(skip_serializing_if = "WorkSurface::is_off")]
    pub work_surface: WorkSurface,
    /// Obstacles of the cell; every capsule of the arm, the tool's included unless the obstacle
    /// is the part the tool works on, keeps each one's clearance.
    #[serde(skip_serializing_if = "Scene::is_empty")]
    pub scene: Scene,
}

impl Default for ConstraintConfig {
    fn default() -> Self {
        Self {
            line_tolerance_m: 0.02,
            theta_max_deg: 30.0,
            collision_margin_m: 0.0,
            velocity_limit_fraction: Some(VelocityLimitFraction::FULL),
            work_surface: WorkSurface::Off,
            scene: Scene::default(),
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

impl OutOfRange {
    /// `Ok` if `value` is finite and `check` accepts it, else the range error of `field`.
    pub fn require(
        field: &'static str,
        value: f64,
        allowed: &'static str,
        check: impl Fn(f64) -> bool,
    ) -> Result<(), Self> {
        if value.is_finite() && check(value) {
            Ok(())
        } else {
            Err(Self {
                field,
                value,
                allowed,
            })
        }
    }
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
    /// How a step that drifts from the line or path is handled: the paper's step (the
    /// default, which every published table uses) or the corrected step a cell's tolerance
    /// needs ([`Tracking`]).
    pub tracking: Tracking,
}

/// How the step holds the TCP on its line or path.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Tracking {
    /// The paper's step (Eq. 2): one explicit step of `q̇ = J⁺ẋ + a_max B a`, the task command
    /// `ẋ = v d + k_lat e_lat`; a step whose TCP lands outside the tolerance ends the motion.
    /// Its own tracking error (the step is first order, the arm's kinematics are not) is a few
    /// tenths of a millimetre on lines and grows with the path's curvature, which the 20 mm
    /// benchmark never sees.
    #[default]
    FirstOrder,
    /// The paper's step, corrected where its TCP lands more than
    /// [`CORRECTION_TRIGGER`](crate::CORRECTION_TRIGGER) of the tolerance off the line or path:
    /// the end configuration is moved back onto it by Newton corrections `Δq = J⁺ e` (the
    /// pseudo-inverse at each corrected configuration, lightly damped,
    /// [`CORRECTION_DAMPING`](crate::CORRECTION_DAMPING); `e` the offset to the nearest line or
    /// path point; up to
    /// [`MAX_CORRECTIONS`](crate::MAX_CORRECTIONS)); where those leave it off, the step is
    /// taken again with no null-space motion (the damping near a singularity does not buy
    /// self-motion with task error). Steps that track well are the paper's, bit for bit; what
    /// `emg plan`, `emg job` and Python plan with.
    Corrected,
}

/// The largest accepted `max_steps`: 100,000 steps of 50 ms are well over an hour of motion.
pub const MAX_STEPS_CAP: usize = 100_000;

impl ConstraintConfig {
    /// Checks every bound: `line_tolerance_m > 0`, `0 < theta_max_deg < 90`,
    /// `collision_margin_m ≥ 0`, all finite (the velocity fraction is checked when read).
    pub fn validate(&self) -> Result<(), OutOfRange> {
        OutOfRange::require(
            "constraints.line_tolerance_m",
            self.line_tolerance_m,
            "(0, ∞)",
            |v| v > 0.0,
        )?;
        OutOfRange::require(
            "constraints.theta_max_deg",
            self.theta_max_deg,
            "(0, 90)",
            |v| v > 0.0 && v < 90.0,
        )?;
        OutOfRange::require(
            "constraints.collision_margin_m",
            self.collision_margin_m,
            "[0, ∞)",
            |v| v >= 0.0,
        )
    }
}

impl RolloutConfig {
    /// How long a step at the mean joint velocity `velocity` (rad/s) lasts on an arm with the
    /// joint velocity limits `velocity_limits`: `dt_s`, stretched so that no joint exceeds its
    /// share ([`ConstraintConfig::velocity_limit_fraction`]) of its limit; `dt_s` where joint
    /// speeds are unbounded (`None`). Every rollout step is timed by it, and so is the first step
    /// of a motion planned backwards and read forwards.
    pub fn step_duration_s(&self, velocity: &JointVector, velocity_limits: &JointVector) -> f64 {
        let Some(fraction) = self.constraints.velocity_limit_fraction else {
            return self.dt_s;
        };
        let stretch = (0..velocity.len())
            .map(|i| velocity[i].abs() / (fraction.get() * velocity_limits[i]))
            .fold(1.0, f64::max);
        self.dt_s * stretch
    }

    /// Checks every setting: `dt_s`, `speed_m_per_s` and `null_speed_max_rad_per_s` positive,
    /// `1 ≤ max_steps ≤` [`MAX_STEPS_CAP`], gains, dampings and thresholds finite and
    /// non-negative (the damping threshold and `λ_max` positive), and the constraints.
    pub fn validate(&self) -> Result<(), OutOfRange> {
        let positive = |v: f64| v > 0.0;
        let non_negative = |v: f64| v >= 0.0;
        OutOfRange::require("rollout.dt_s", self.dt_s, "(0, ∞)", positive)?;
        OutOfRange::require(
            "rollout.speed_m_per_s",
            self.speed_m_per_s,
            "(0, ∞)",
            positive,
        )?;
        if self.max_steps == 0 || self.max_steps > MAX_STEPS_CAP {
            return Err(OutOfRange {
                field: "rollout.max_steps",
                value: self.max_steps as f64,
                allowed: "[1, 100000]",
            });
        }
        OutOfRange::require(
            "rollout.null_speed_max_rad_per_s",
            self.null_speed_max_rad_per_s,
            "(0, ∞)",
            positive,
        )?;
        OutOfRange::require(
            "rollout.lateral_gain_per_s",
            self.lateral_gain_per_s,
            "[0, ∞)",
            non_negative,
        )?;
        OutOfRange::require(
            "rollout.manipulability_damping",
            self.manipulability_damping,
            "[0, ∞)",
            non_negative,
        )?;
        OutOfRange::require(
            "rollout.damping.sigma_threshold",
            self.damping.sigma_threshold,
            "(0, ∞)",
            positive,
        )?;
        OutOfRange::require(
            "rollout.damping.lambda_max",
            self.damping.lambda_max,
            "(0, ∞)",
            positive,
        )?;
        OutOfRange::require(
            "rollout.basis.residual_floor",
            self.basis.residual_floor,
            "[0, ∞)",
            non_negative,
        )?;
        OutOfRange::require(
            "rollout.basis.residual_relative",
            self.basis.residual_relative,
            "[0, ∞)",
            non_negative,
        )?;
        self.constraints.validate()
    }
}

impl ClassicalGains {
    /// Checks that every gain is finite and non-negative and the cone gate width positive.
    pub fn validate(&self) -> Result<(), OutOfRange> {
        let non_negative = |v: f64| v >= 0.0;
        OutOfRange::require("gains.k_mu", self.k_mu, "[0, ∞)", non_negative)?;
        OutOfRange::require("gains.k_jl", self.k_jl, "[0, ∞)", non_negative)?;
        OutOfRange::require("gains.k_theta", self.k_theta, "[0, ∞)", non_negative)?;
        OutOfRange::require(
            "gains.cone_gate_width_deg",
            self.cone_gate_width_deg,
            "(0, ∞)",
            |v| v > 0.0,
        )?;
        OutOfRange::require("gains.k_lead", self.k_lead, "[0, ∞)", non_negative)?;
        OutOfRange::require("gains.lead_deg", self.lead_deg, "[0, 90)", |v| {
            (0.0..90.0).contains(&v)
        })
    }
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
            tracking: Tracking::FirstOrder,
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
    /// `k_lead`: weight of the leading tilt term `k_lead ∇(z·m)`, which turns the tool axis
    /// ahead of the tilt the line's motion causes (`crate::lead_axis`); 0, the paper's
    /// controller, leaves it out.
    #[serde(default)]
    pub k_lead: f64,
    /// Angle (degrees) from `n`, against the tilt drift, of the axis `m` the leading tilt term
    /// aims the tool at.
    #[serde(default = "default_lead_deg")]
    pub lead_deg: f64,
}

/// The leading tilt term's default angle (degrees): two thirds of the paper's cone.
fn default_lead_deg() -> f64 {
    20.0
}

impl Default for ClassicalGains {
    fn default() -> Self {
        Self {
            k_mu: 0.8,
            k_jl: 0.4,
            k_theta: 0.2,
            cone_gate_width_deg: 8.0,
            k_lead: 0.0,
            lead_deg: default_lead_deg(),
        }
    }
}
