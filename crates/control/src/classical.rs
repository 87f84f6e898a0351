//! The classical null-space controller (Eq. 3 with the cone gate of SPEC §4).

use emg_kinematics::JointVector;

use crate::config::ClassicalGains;
use crate::controller::{ActingController, NullSpaceController};
use crate::step::{NullAction, StepContext};

/// Secondary command `ξ = k_μ ∇w_d − k_jl (q − q_mid)/(q_max − q_min) + k_θ g(θ) ∇(z·n)`,
/// expressed in `B(q)` as `a = clip(Bᵀξ / a_max, −1, 1)`.
#[derive(Clone, Debug, Default)]
pub struct ClassicalController {
    /// The gains `(k_μ, k_jl, k_θ)` and the gate width.
    pub gains: ClassicalGains,
}

impl ClassicalController {
    /// A controller with the given gains.
    pub fn new(gains: ClassicalGains) -> Self {
        Self { gains }
    }

    /// Cone gate `g(θ) = clip((θ − θ_max + w)/w, 0, 1)`: 0 far from the cone edge, 1 at it.
    pub fn cone_gate(&self, theta_deg: f64, theta_max_deg: f64) -> f64 {
        let width = self.gains.cone_gate_width_deg;
        ((theta_deg - theta_max_deg + width) / width).clamp(0.0, 1.0)
    }

    /// The secondary command `ξ` of Eq. 3 at this step.
    pub fn secondary_command(&self, step: &StepContext<'_>) -> JointVector {
        let limits = step.robot.limits();
        let centring = (step.q - limits.mid()).component_div(&(limits.upper - limits.lower));
        let gate = self.cone_gate(step.tool_angle_deg, step.config.constraints.theta_max_deg);
        step.manipulability_gradient * self.gains.k_mu - centring * self.gains.k_jl
            + step.alignment_gradient * (self.gains.k_theta * gate)
    }
}

impl NullSpaceController for ClassicalController {
    fn reset(&mut self, _first: &StepContext<'_>) {}

    fn act(&mut self, step: &StepContext<'_>) -> (NullAction, ActingController) {
        let xi = self.secondary_command(step);
        (step.action_from_secondary(&xi), ActingController::Classical)
    }
}
