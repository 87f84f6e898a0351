//! Boundary measures the switch compares with its thresholds.

use emg_control::StepContext;
use serde::{Deserialize, Serialize};

/// How close a step is to the boundary that would end the rollout (1 = on it).
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
#[serde(tag = "kind", rename_all = "snake_case", deny_unknown_fields)]
pub enum BoundaryMeasure {
    /// The paper's rule: joint-limit proximity `ρ(q) = max_i |q̄_i|` (Eq. 8).
    #[default]
    JointLimits,
    /// Every constraint that ends rollouts: `max(ρ(q), θ/θ_max, 1 − clearance/clearance_scale_m)`,
    /// covering the joint limits, the tool cone and self-collision.
    AllConstraints {
        /// Clearance (m) at which the collision term starts to rise above 0.
        clearance_scale_m: f64,
    },
}

impl BoundaryMeasure {
    /// The measure at a step.
    pub fn evaluate(&self, step: &StepContext<'_>) -> f64 {
        match self {
            Self::JointLimits => step.rho,
            Self::AllConstraints { clearance_scale_m } => {
                let cone = step.tool_angle_deg / step.config.constraints.theta_max_deg;
                let clearance = step
                    .robot
                    .min_clearance(&step.kinematics)
                    .map_or(f64::INFINITY, |hit| hit.clearance);
                let collision = 1.0 - clearance / clearance_scale_m;
                step.rho.max(cone).max(collision)
            }
        }
    }

    /// Short name for tables (`joint_limits`, `all_constraints`).
    pub fn name(&self) -> &'static str {
        match self {
            Self::JointLimits => "joint_limits",
            Self::AllConstraints { .. } => "all_constraints",
        }
    }
}
