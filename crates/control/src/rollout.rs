//! The one rollout loop shared by every controller (SPEC §3).

use emg_kinematics::{JointVector, Robot};
use serde::{Deserialize, Serialize};

use crate::config::{RolloutConfig, Tracking};
use crate::constraints::{Violation, admit, first_violation, tool_angle_deg, within_reached};
use crate::controller::{ActingController, NullSpaceController};
use crate::step::{NullAction, StepContext};
use crate::task::Task;
use crate::tracking::{CORRECTION_TRIGGER, correct_onto_task};

/// Steps a rollout reserves room for up front (the default step cap and its seed fit); longer
/// rollouts grow their record as they go, so memory follows the steps taken, not the cap.
const PREALLOCATED_STEPS: usize = 1024;

/// One recorded step of a trajectory.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct StepRecord {
    /// Time since the start (s): `Δt` per step, more for steps slowed to honour the joint-velocity
    /// limits.
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
    /// The tool reached the end of its path (path tasks only).
    Completed,
}

impl Termination {
    /// Short name for histograms: the constraint's kind, `invalid_start` or `step_cap`.
    pub fn label(&self) -> &'static str {
        match self {
            Self::Violation { violation, .. } => violation.kind(),
            Self::InvalidStart { .. } => "invalid_start",
            Self::StepCap => "step_cap",
            Self::Completed => "completed",
        }
    }
}

impl std::fmt::Display for Termination {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Self::Violation { violation, .. } => write!(f, "{violation}"),
            Self::InvalidStart { violation } => write!(f, "the seed is invalid: {violation}"),
            Self::StepCap => write!(f, "reached the step cap with every constraint held"),
            Self::Completed => write!(f, "reached the end of the path"),
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
    /// Path length `L = (p_T − p0)·d` at the last accepted step (m); on a path task, the arc
    /// length reached.
    pub path_length_m: f64,
}

impl Trajectory {
    /// The controllers that computed its steps' commands, each once, in the order they first
    /// acted.
    pub fn acting_controllers(&self) -> Vec<ActingController> {
        let mut acted = Vec::new();
        for controller in self.steps.iter().filter_map(|step| step.controller) {
            if !acted.contains(&controller) {
                acted.push(controller);
            }
        }
        acted
    }
}

/// What one applied step did.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum StepOutcome {
    /// The step was accepted; the episode goes on. `progress_m` is its advance along `d` (on a
    /// path, the arc length it gained).
    Continued {
        /// `(p_{t+1} − p_t)·d` (m).
        progress_m: f64,
    },
    /// The step was accepted and reached the step cap or the end of its path (a truncation,
    /// not a failure).
    Truncated {
        /// `(p_{t+1} − p_t)·d` (m).
        progress_m: f64,
    },
    /// The step would break a constraint; it was rejected and the episode ended.
    Terminated,
}

/// A rollout in progress, advanced one control step at a time: the one implementation of the
/// step (SPEC §3) that [`rollout`] and every learning environment share.
///
/// Each step: read the [`StepContext`] at `q_t` ([`Episode::context`], computed once when the
/// step was accepted), choose an action, and [`Episode::apply`] it: clip to `[−1, 1]⁴`,
/// integrate `q̇ = J⁺ẋ + a_max B a` for `Δt` (on a path, for the share of it that lands on the
/// next corner or the end when a full step would pass it, [`StepContext::step_fraction`]),
/// under [`Tracking::Corrected`] correct its end onto the line or path where it drifted, and
/// accept `q_{t+1}` only if it holds every constraint.
///
/// Joint-velocity limits are honoured by time scaling: a step whose `q̇` would exceed
/// `fraction · v_max,i` on some joint keeps its shape but lasts `Δt · max_i |q̇_i| / (fraction ·
/// v_max,i)` instead of `Δt`, so the line progress slows for that step and the recorded
/// timestamps are the real ones. The geometric path is the same with limits on or off.
#[derive(Clone, Debug)]
pub struct Episode<'a> {
    /// The state at the current configuration (its `q`, kinematics and previous action).
    current: StepContext<'a>,
    time_s: f64,
    steps: Vec<StepRecord>,
    termination: Option<Termination>,
}

impl<'a> Episode<'a> {
    /// Starts at `seed`; the episode is already over if the seed breaks a constraint.
    pub fn start(
        robot: &'a Robot,
        task: &'a Task,
        seed: &JointVector,
        config: &'a RolloutConfig,
    ) -> Self {
        let current = StepContext::new(
            robot,
            task,
            config,
            0,
            robot.forward(seed),
            NullAction::zeros(),
        );
        let mut episode = Self {
            current,
            time_s: 0.0,
            steps: Vec::with_capacity((config.max_steps + 1).min(PREALLOCATED_STEPS)),
            termination: None,
        };
        if let Some(violation) = first_violation(
            robot,
            task,
            &episode.current.kinematics,
            &config.constraints,
        ) {
            episode.record(None);
            episode.termination = Some(Termination::InvalidStart { violation });
        } else if config.max_steps == 0 {
            episode.record(None);
            episode.termination = Some(Termination::StepCap);
        }
        episode
    }

    /// The state a controller sees at the current step, or `None` once the episode is over.
    pub fn context(&self) -> Option<&StepContext<'a>> {
        self.termination.is_none().then_some(&self.current)
    }

    /// The state at the last accepted configuration, also once the episode is over.
    pub fn state(&self) -> &StepContext<'a> {
        &self.current
    }

    /// Applies `action` (clipped to `[−1, 1]⁴`), chosen by `acting` at the current
    /// [`Episode::context`].
    pub fn apply(&mut self, action: &NullAction, acting: ActingController) -> StepOutcome {
        debug_assert!(self.termination.is_none(), "apply after the episode ended");
        let StepContext {
            robot,
            task,
            config,
            ..
        } = self.current;
        let action = action.map(|a| a.clamp(-1.0, 1.0));
        let fraction = self.current.step_fraction();
        let step_s = config.dt_s * fraction;
        let mut velocity = self.current.joint_velocity(&action);
        let mut next = self.current.q + velocity * step_s;
        // The context already holds this configuration's tool angle and ρ.
        self.push_record(Some(acting), self.current.tool_angle_deg, self.current.rho);
        // The next configuration's kinematics are written in place; the rest of the context is
        // derived from them before the check (which it overlaps, see `StepContext::derive`)
        // and taken on once the step is accepted.
        let previous_tcp = self.current.kinematics.tcp();
        robot.forward_into(&next, &mut self.current.kinematics);
        let mut derived = self.current.derive();
        let mut applied = action;
        if config.tracking == Tracking::Corrected
            && step_s > 0.0
            && derived.along.lateral.norm()
                > CORRECTION_TRIGGER * config.constraints.line_tolerance_m
            && let Some(corrected) = self.corrected_step(&action, step_s, next)
        {
            (next, applied) = corrected;
            // The joints' mean velocity over the corrected step.
            velocity = (next - self.current.q) / step_s;
            derived = self.current.derive();
        }
        let admitted = admit(robot, task, &self.current.kinematics, &config.constraints)
            .and_then(|angle| within_reached(&derived.along, &config.constraints).map(|()| angle));
        let tool_angle_deg = match admitted {
            Ok(tool_angle_deg) => tool_angle_deg,
            Err(violation) => {
                // The state stays at the last accepted configuration, kinematics included.
                robot.forward_into(&self.current.q, &mut self.current.kinematics);
                self.termination = Some(Termination::Violation {
                    violation,
                    rejected_q: next,
                });
                return StepOutcome::Terminated;
            }
        };
        let progress_m = match task.path {
            None => (self.current.kinematics.tcp() - previous_tcp).dot(&task.d),
            Some(_) => derived.along.s_m - self.current.along.s_m,
        };
        self.time_s += config.step_duration_s(&velocity, &robot.limits().velocity) * fraction;
        self.current
            .advance(self.steps.len(), tool_angle_deg, applied, derived);
        if task.completed(self.current.along.s_m) {
            self.record(None);
            self.termination = Some(Termination::Completed);
            return StepOutcome::Truncated { progress_m };
        }
        if self.steps.len() == config.max_steps {
            self.record(None);
            self.termination = Some(Termination::StepCap);
            return StepOutcome::Truncated { progress_m };
        }
        StepOutcome::Continued { progress_m }
    }

    /// The corrected step of [`Tracking::Corrected`] from the current configuration, whose
    /// paper step of `step_s` seconds with `action` ended at `paper_end` (the kinematics in the
    /// context): Newton corrections `Δq = J⁺ e` toward the nearest line or path point
    /// ([`correct_onto_task`]); then the same without the null-space motion. The end
    /// configuration and the action it applied, with the context's kinematics at it; `None`, the
    /// kinematics back at `paper_end`, where neither comes within [`CORRECTION_TRIGGER`] of the
    /// tolerance. Shortening the step as well (a half, a quarter) was measured and left out: `cargo xtask precision-eval` found the same
    /// shares of the bound at 0.5 mm, the step cap ending what the tolerance had, and lower
    /// ones at 20 mm.
    fn corrected_step(
        &mut self,
        action: &NullAction,
        step_s: f64,
        paper_end: JointVector,
    ) -> Option<(JointVector, NullAction)> {
        let StepContext {
            robot,
            task,
            config,
            ..
        } = self.current;
        let target_m = CORRECTION_TRIGGER * config.constraints.line_tolerance_m;
        for (index, applied) in [*action, NullAction::zeros()].into_iter().enumerate() {
            let mut q = if index == 0 {
                paper_end
            } else {
                let q = self.current.q + self.current.joint_velocity(&applied) * step_s;
                robot.forward_into(&q, &mut self.current.kinematics);
                q
            };
            if correct_onto_task(
                robot,
                task,
                self.current.along.s_m,
                target_m,
                &mut q,
                &mut self.current.kinematics,
            ) {
                return Some((q, applied));
            }
        }
        robot.forward_into(&paper_end, &mut self.current.kinematics);
        None
    }

    /// Whether the episode is over.
    pub fn is_finished(&self) -> bool {
        self.termination.is_some()
    }

    /// Steps accepted so far (the seed counts as step 0).
    pub fn step_count(&self) -> usize {
        self.steps.len()
    }

    /// The recorded trajectory; an episode stopped before its end is reported as reaching the
    /// step cap at its current step.
    pub fn finish(mut self) -> Trajectory {
        let termination = match self.termination.take() {
            Some(termination) => termination,
            None => {
                self.record(None);
                Termination::StepCap
            }
        };
        // The last record is the current configuration, whose progress (on a line
        // `(p − p0)·d`, on a path the arc length) the context holds.
        let path_length_m = self.current.along.s_m;
        Trajectory {
            steps: self.steps,
            termination,
            path_length_m,
        }
    }

    /// Records the current configuration, measuring its tool angle and `ρ`.
    fn record(&mut self, controller: Option<ActingController>) {
        let current = &self.current;
        let angle = tool_angle_deg(&current.kinematics.tool_axis(), &current.task.n);
        let rho = current.robot.limits().limit_proximity(&current.q);
        self.push_record(controller, angle, rho);
    }

    /// Records the current configuration with its tool angle and `ρ` already known.
    fn push_record(&mut self, controller: Option<ActingController>, tool_angle_deg: f64, rho: f64) {
        self.steps.push(StepRecord {
            time_s: self.time_s,
            q: self.current.q,
            tcp: self.current.kinematics.tcp(),
            tool_angle_deg,
            rho,
            controller,
        });
    }
}

/// Runs `controller` on `task` from `seed` until a constraint would break or the step cap
/// (an [`Episode`] driven by one controller).
pub fn rollout(
    robot: &Robot,
    task: &Task,
    seed: &JointVector,
    controller: &mut dyn NullSpaceController,
    config: &RolloutConfig,
) -> Trajectory {
    continue_rollout(Episode::start(robot, task, seed, config), controller)
}

/// Drives `episode` with `controller` from its current step to its end (a broken constraint or
/// the step cap); `controller` is reset at that step first. An episode taken over midway (a
/// clone of another at some step) goes on from exactly that state.
pub fn continue_rollout(
    mut episode: Episode<'_>,
    controller: &mut dyn NullSpaceController,
) -> Trajectory {
    if let Some(first) = episode.context() {
        controller.reset(first);
    }
    while let Some(context) = episode.context() {
        let (action, acting) = controller.act(context);
        episode.apply(&action, acting);
    }
    episode.finish()
}
