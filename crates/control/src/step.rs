//! What a controller sees at one control step: the kinematic quantities of Eqs. 2–4.

use emg_kinematics::{
    DampedPseudoInverse, JointVector, Kinematics, Robot, TaskBasis, Vec3, damped_pseudo_inverse,
    directional_manipulability, task_aligned_basis, tool_alignment_gradient,
};
use nalgebra::SVector;

use crate::config::RolloutConfig;
use crate::constraints::tool_angle_deg;
use crate::task::{Along, Task};

/// A null-space action `a ∈ [−1, 1]⁴`: coordinates in the basis `B(q)` (Sec. 4.2); an arm of six
/// joints uses the first three (the fourth column of its `B(q)` is zero).
pub type NullAction = SVector<f64, 4>;

/// The state of one control step, computed once and shared by every controller.
#[derive(Clone, Debug)]
pub struct StepContext<'a> {
    /// The robot.
    pub robot: &'a Robot,
    /// The task being followed.
    pub task: &'a Task,
    /// The rollout settings.
    pub config: &'a RolloutConfig,
    /// Step index (0 at the seed).
    pub step: usize,
    /// Current configuration `q`.
    pub q: JointVector,
    /// Forward kinematics at `q`.
    pub kinematics: Kinematics,
    /// Normalised configuration `q̄ ∈ [−1, 1]ⁿ` (zero past the arm's joints).
    pub q_normalised: JointVector,
    /// Joint-limit proximity `ρ(q) = max_i |q̄_i|` (Eq. 8).
    pub rho: f64,
    /// Angle between tool axis and `n` (degrees).
    pub tool_angle_deg: f64,
    /// Where the TCP stands along the task (its progress, heading and lateral error).
    pub along: Along,
    /// Directional manipulability `w_d` along `d`.
    pub manipulability: f64,
    /// `∇w_d` (SPEC §4).
    pub manipulability_gradient: JointVector,
    /// `∇(z·n)`.
    pub alignment_gradient: JointVector,
    /// `∇(−mean q̄²)`, the joint-centring direction of `B(q)`.
    pub centring_gradient: JointVector,
    /// Damped pseudo-inverse `J⁺`.
    pub pseudo_inverse: DampedPseudoInverse,
    /// Task-aligned null-space basis `B(q)`.
    pub basis: TaskBasis,
    /// The previous action (zero at reset).
    pub previous_action: NullAction,
}

impl<'a> StepContext<'a> {
    /// Computes every quantity of the step at the configuration whose forward kinematics
    /// ([`Robot::forward`]) `kinematics` is (no allocation); on a path task the TCP is located
    /// near the path's start.
    pub fn new(
        robot: &'a Robot,
        task: &'a Task,
        config: &'a RolloutConfig,
        step: usize,
        kinematics: Kinematics,
        previous_action: NullAction,
    ) -> Self {
        let tool_angle_deg = tool_angle_deg(&kinematics.tool_axis(), &task.n);
        let derived = Derived::of(robot, task, config, &kinematics, 0.0);
        Self {
            robot,
            task,
            config,
            step,
            q: derived.q,
            kinematics,
            q_normalised: derived.q_normalised,
            rho: derived.rho,
            tool_angle_deg,
            along: derived.along,
            manipulability: derived.manipulability,
            manipulability_gradient: derived.manipulability_gradient,
            alignment_gradient: derived.alignment_gradient,
            centring_gradient: derived.centring_gradient,
            pseudo_inverse: derived.pseudo_inverse,
            basis: derived.basis,
            previous_action,
        }
    }

    /// Moves the context to step `step`: its configuration's forward kinematics have been
    /// written over `self.kinematics` ([`Robot::forward_into`]), `derived` is what
    /// [`StepContext::derive`] computed from them, and the constraint check that accepted the
    /// configuration measured `tool_angle_deg`. A rollout's step copies no context. Always
    /// inlined into [`crate::Episode`]'s step.
    #[inline(always)]
    pub(crate) fn advance(
        &mut self,
        step: usize,
        tool_angle_deg: f64,
        previous_action: NullAction,
        derived: Derived,
    ) {
        self.step = step;
        self.q = derived.q;
        self.q_normalised = derived.q_normalised;
        self.rho = derived.rho;
        self.tool_angle_deg = tool_angle_deg;
        self.along = derived.along;
        self.manipulability = derived.manipulability;
        self.manipulability_gradient = derived.manipulability_gradient;
        self.alignment_gradient = derived.alignment_gradient;
        self.centring_gradient = derived.centring_gradient;
        self.pseudo_inverse = derived.pseudo_inverse;
        self.basis = derived.basis;
        self.previous_action = previous_action;
    }

    /// The quantities that follow from `self.kinematics` alone (and, on a path, the progress
    /// the last accepted step had), for [`StepContext::advance`].
    /// The step computes them before its constraint check, which needs none of them, so that
    /// the check's work overlaps the tail of their chain of dependent square roots and
    /// divisions (the null-space basis); on a rejected step they are dropped.
    #[inline(always)]
    pub(crate) fn derive(&self) -> Derived {
        Derived::of(
            self.robot,
            self.task,
            self.config,
            &self.kinematics,
            self.along.s_m,
        )
    }

    /// The task-space command `ẋ = v d + k_lat e_lat` (SPEC §3); on a path, `d` is the heading
    /// there.
    pub fn task_velocity(&self) -> Vec3 {
        self.along.heading * self.config.speed_m_per_s
            + self.along.lateral * self.config.lateral_gain_per_s
    }

    /// The share of the control period `Δt` this step lasts: 1, except on a path where a full
    /// step would pass the next corner or the end, which the shortened step lands on (the
    /// joints move that share of a full step, so the arm's self-motion slows with the tool).
    pub fn step_fraction(&self) -> f64 {
        match self.task.path {
            None => 1.0,
            Some(_) => {
                let full_m = self.config.speed_m_per_s * self.config.dt_s;
                (self.task.stop_ahead_m(self.along.s_m) / full_m).min(1.0)
            }
        }
    }

    /// Joint velocity `q̇ = J⁺ẋ + a_max B a` for a (clipped) action `a` (Eq. 2).
    pub fn joint_velocity(&self, action: &NullAction) -> JointVector {
        self.pseudo_inverse.matrix * self.task_velocity()
            + self.basis.columns * action * self.config.null_speed_max_rad_per_s
    }

    /// Coordinates `clip(Bᵀξ / a_max, −1, 1)` of a secondary command `ξ` in `B(q)`: the one
    /// parameterisation shared by every controller.
    pub fn action_from_secondary(&self, xi: &JointVector) -> NullAction {
        (self.basis.columns.transpose() * xi / self.config.null_speed_max_rad_per_s)
            .map(|a| a.clamp(-1.0, 1.0))
    }
}

/// The quantities of a [`StepContext`] that follow from its configuration's forward kinematics
/// alone (Eqs. 2–4): the one definition that [`StepContext::new`] and [`StepContext::derive`]
/// share.
pub(crate) struct Derived {
    q: JointVector,
    pub(crate) along: Along,
    q_normalised: JointVector,
    rho: f64,
    manipulability: f64,
    manipulability_gradient: JointVector,
    alignment_gradient: JointVector,
    centring_gradient: JointVector,
    pseudo_inverse: DampedPseudoInverse,
    basis: TaskBasis,
}

impl Derived {
    /// Computes them at the configuration of `kinematics` (no allocation), locating a path
    /// task's TCP near the progress `s_hint`.
    #[inline(always)]
    fn of(
        robot: &Robot,
        task: &Task,
        config: &RolloutConfig,
        kinematics: &Kinematics,
        s_hint: f64,
    ) -> Self {
        let q = *kinematics.configuration();
        let along = task.along(&kinematics.tcp(), s_hint);
        let limits = robot.limits();
        let q_normalised = limits.normalise(&q);
        let rho = q_normalised.amax();
        let jacobian = kinematics.jacobian();
        let pseudo_inverse = damped_pseudo_inverse(jacobian, &config.damping);
        let (manipulability, manipulability_gradient) = directional_manipulability(
            kinematics,
            pseudo_inverse.gram(),
            &along.heading,
            config.manipulability_damping,
        );
        let alignment_gradient = tool_alignment_gradient(kinematics, &task.n);
        let centring_gradient =
            -q_normalised.component_div(&limits.half_range()) * (2.0 / robot.dof() as f64);
        let basis = task_aligned_basis(
            kinematics,
            [
                &manipulability_gradient,
                &alignment_gradient,
                &centring_gradient,
            ],
            &config.basis,
        );
        Self {
            q,
            along,
            q_normalised,
            rho,
            manipulability,
            manipulability_gradient,
            alignment_gradient,
            centring_gradient,
            pseudo_inverse,
            basis,
        }
    }
}
