//! The one rollout loop shared by every controller (SPEC §3).

use emg_kinematics::{JointVector, Robot};
use serde::{Deserialize, Serialize};

use crate::config::RolloutConfig;
use crate::constraints::{Violation, first_violation, tool_angle_deg};
use crate::controller::{ActingController, NullSpaceController};
use crate::step::{NullAction, StepContext};
use crate::task::Task;

/// One recorded step of a trajectory.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct StepRecord {
    /// Time since the start (s).
    pub time_s: f64,
    /// Joint configuration (rad).
    pub q: JointVector,
    /// TCP position (m).
    pub tcp: emg_kinematics::Vec3,
    /// Angle between the tool axis and `n` (degrees).
    pub tool_angle_deg: f64,
    /// Joint-limit proximity `ρ(q)`.
    pub rho: f64,
    /// Controller that computed the command issued from this step (`None` on the final step of
    /// a rollout that hit the step cap).
    pub controller: Option<ActingController>,
}

/// Why a rollout ended.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(tag = "reason", rename_all = "snake_case")]
pub enum Termination {
    /// The next step would have broken a constraint; it was not taken.
    Violation {
        /// The constraint broken.
        violation: Violation,
        /// The rejected configuration.
        rejected_q: JointVector,
    },
    /// The seed itself breaks a constraint; the trajectory holds only the seed.
    InvalidStart {
        /// The constraint broken at the seed.
        violation: Violation,
    },
    /// The step cap was reached with every constraint held.
    StepCap,
}

impl Termination {
    /// Short name for histograms: the constraint's kind, `invalid_start` or `step_cap`.
    pub fn label(&self) -> &'static str {
        match self {
            Self::Violation { violation, .. } => violation.kind(),
            Self::InvalidStart { .. } => "invalid_start",
            Self::StepCap => "step_cap",
        }
    }
}

impl std::fmt::Display for Termination {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Self::Violation { violation, .. } => write!(f, "{violation}"),
            Self::InvalidStart { violation } => write!(f, "the seed is invalid: {violation}"),
            Self::StepCap => write!(f, "reached the step cap with every constraint held"),
        }
    }
}

/// A rollout: every accepted step, why it ended and how far it went.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Trajectory {
    /// Accepted steps, the seed first.
    pub steps: Vec<StepRecord>,
    /// Why the rollout ended.
    pub termination: Termination,
    /// Path length `L = (p_T − p0)·d` at the last accepted step (m).
    pub path_length_m: f64,
}

/// Runs `controller` on `task` from `seed` until a constraint would break or the step cap.
///
/// Each step: build the [`StepContext`] at `q_t`, ask the controller for `a`, clip it, apply
/// `q̇ = J⁺ẋ + a_max B a` for `Δt`, and accept `q_{t+1}` only if it holds every constraint.
pub fn rollout(
    robot: &Robot,
    task: &Task,
    seed: &JointVector,
    controller: &mut dyn NullSpaceController,
    config: &RolloutConfig,
) -> Trajectory {
    let mut steps = Vec::with_capacity(config.max_steps + 1);
    let mut q = *seed;
    let mut kinematics = robot.forward(&q);
    if let Some(violation) = first_violation(robot, task, &q, &kinematics, &config.constraints) {
        steps.push(record(0, config, robot, task, &q, &kinematics, None));
        return finish(task, steps, Termination::InvalidStart { violation });
    }
    let mut previous = NullAction::zeros();
    for step in 0..config.max_steps {
        let context = StepContext::new(robot, task, config, step, q, kinematics, previous);
        if step == 0 {
            controller.reset(&context);
        }
        let (raw, acting) = controller.act(&context);
        let action = raw.map(|a| a.clamp(-1.0, 1.0));
        let next = q + context.joint_velocity(&action) * config.dt_s;
        steps.push(record(
            step,
            config,
            robot,
            task,
            &q,
            &context.kinematics,
            Some(acting),
        ));
        let next_kinematics = robot.forward(&next);
        if let Some(violation) =
            first_violation(robot, task, &next, &next_kinematics, &config.constraints)
        {
            return finish(
                task,
                steps,
                Termination::Violation {
                    violation,
                    rejected_q: next,
                },
            );
        }
        q = next;
        kinematics = next_kinematics;
        previous = action;
    }
    steps.push(record(
        config.max_steps,
        config,
        robot,
        task,
        &q,
        &kinematics,
        None,
    ));
    finish(task, steps, Termination::StepCap)
}

fn record(
    step: usize,
    config: &RolloutConfig,
    robot: &Robot,
    task: &Task,
    q: &JointVector,
    kinematics: &emg_kinematics::Kinematics,
    controller: Option<ActingController>,
) -> StepRecord {
    StepRecord {
        time_s: step as f64 * config.dt_s,
        q: *q,
        tcp: kinematics.tcp(),
        tool_angle_deg: tool_angle_deg(&kinematics.tool_axis(), &task.n),
        rho: robot.limits().limit_proximity(q),
        controller,
    }
}

fn finish(task: &Task, steps: Vec<StepRecord>, termination: Termination) -> Trajectory {
    let last = steps.last().expect("a trajectory holds at least its seed");
    let path_length_m = task.progress(&last.tcp);
    Trajectory {
        steps,
        termination,
        path_length_m,
    }
}
