//! The classical null-space controller (Eq. 3 with the cone gate of SPEC §4).

use emg_kinematics::{JointVector, Vec3, tool_alignment_gradient};

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

    /// The secondary command `ξ` of Eq. 3 at this step, plus the leading tilt term
    /// `k_lead ∇(z·m)` when `k_lead > 0` ([`lead_axis`]).
    pub fn secondary_command(&self, step: &StepContext<'_>) -> JointVector {
        let limits = step.robot.limits();
        let centring = (step.q - limits.mid()).component_div(&(limits.upper - limits.lower));
        let gate = self.cone_gate(step.tool_angle_deg, step.config.constraints.theta_max_deg);
        let xi = step.manipulability_gradient * self.gains.k_mu - centring * self.gains.k_jl
            + step.alignment_gradient * (self.gains.k_theta * gate);
        if self.gains.k_lead > 0.0 {
            let lead = lead_axis(step, self.gains.lead_deg);
            xi + tool_alignment_gradient(&step.kinematics, &lead) * self.gains.k_lead
        } else {
            xi
        }
    }
}

impl NullSpaceController for ClassicalController {
    fn reset(&mut self, _first: &StepContext<'_>) {}

    fn act(&mut self, step: &StepContext<'_>) -> (NullAction, ActingController) {
        let xi = self.secondary_command(step);
        (step.action_from_secondary(&xi), ActingController::Classical)
    }
}

/// The axis `m = n cos β − t̂ sin β` the leading tilt term aims the tool at: `lead_deg` (β) from
/// `n`, against the tilt `t = (I − n nᵀ) ∂z/∂q J⁺ẋ` by which the task command alone turns the
/// tool axis. Along a line the task motion keeps tilting the tool the same way; an axis held
/// ahead of that drift leaves it the whole cone to drift through instead of half of it. `n`
/// itself where the task command does not tilt the tool.
pub fn lead_axis(step: &StepContext<'_>, lead_deg: f64) -> Vec3 {
    let n = step.task.n;
    let task_rate = step.pseudo_inverse.matrix * step.task_velocity();
    let axis_rate = step.kinematics.tool_axis_jacobian() * task_rate;
    let tilt = axis_rate - n * n.dot(&axis_rate);
    let norm = tilt.norm();
    if norm < 1e-9 {
        return n;
    }
    let (sin, cos) = libm::sincos(lead_deg.to_radians());
    n * cos - tilt * (sin / norm)
}
