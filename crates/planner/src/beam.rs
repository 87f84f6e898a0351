//! The search's beam stage: a search over action sequences along the whole line, independent
//! of the start ranking and the repair's detours.
//!
//! Every member of the beam is an episode at the same step. Every [`HOLD_STEPS`] steps, each
//! member is expanded into children that follow the search's classical controller or hold one
//! null-space basis direction at full speed (`±e_i` of `B(q)`) until the next expansion; every
//! step goes through the one step implementation (`Episode::apply`), so every child obeys the
//! step rules. After each step the members are grouped by a cell of the normalised joint
//! space `q̄` ([`CELL`] wide) and only the best of each cell is kept, so that the beam does not
//! collapse onto one self-motion branch; of those, the `width` best go on ([`score`]). Every
//! [`ROLLOUT_EVERY`] steps the [`ROLLOUTS`] best members are also handed to the classical
//! controller to the end of the line, so a branch that the beam drops later is still measured.
//! The plan is the longest of those rollouts and of the members the beam ends with.

use std::collections::HashMap;

use emg_control::{
    ActingController, ClassicalController, Episode, NullAction, NullSpaceController, RolloutConfig,
    StepContext, StepOutcome, Task, Trajectory, continue_rollout,
};
use emg_kinematics::{JointVector, Robot};

use crate::search::steps_evaluated;

/// Side of a diversity cell in the normalised joint space `q̄ ∈ [−1, 1]ⁿ` (16 cells per
/// joint). Measured on the 38 tasks of the first 1,000 FR3 evaluation tasks whose bound is
/// 1 m or more and whose best-known length (`cargo xtask limit` before this stage existed)
/// ended below 0.9 × the bound, where that length reached Σ length / Σ bound 0.453: a first
/// version of this beam (512 members, expanded every step, from the best-known motion's start
/// and 128 cone-IK starts) reached 0.551 with cells of 0.25, 0.555 with 0.125 and 0.523 with
/// 0.0625.
const CELL: f64 = 0.125;

/// Steps between two expansions of the beam: in between, each member holds the basis
/// direction it was expanded with (or goes on with the classical controller). Measured on the
/// same 38 tasks with the search's large settings and a beam of 512 (Σ length / Σ bound, time
/// for the 38 plans): held 1 step 0.525 in 19 s, 2 steps 0.535 in 10 s, 3 steps 0.541 in 8 s,
/// 5 steps 0.500 in 6 s.
const HOLD_STEPS: usize = 3;

/// Steps between the classical rollouts from the best members.
const ROLLOUT_EVERY: usize = 10;

/// Best members handed to the classical controller every [`ROLLOUT_EVERY`] steps.
const ROLLOUTS: usize = 4;

/// Weight of the directional manipulability `w_d` beside the constraint margin in [`score`].
const MANIPULABILITY_WEIGHT: f64 = 0.25;

/// The limits of one beam search.
#[derive(Clone, Copy, Debug)]
pub(crate) struct BeamLimits {
    /// Members kept each step.
    pub width: usize,
    /// Control steps the beam may evaluate.
    pub budget_steps: u64,
    /// The beam ends once a motion gets this far (m).
    pub enough_m: f64,
}

/// The longest motion a beam search found.
#[derive(Clone, Debug)]
pub(crate) struct BeamPlan {
    /// Index of the start (in the starts given) it began from.
    pub start: usize,
    /// The motion.
    pub trajectory: Trajectory,
}

/// A member of the beam: an episode, the index of its start, and what it does until the
/// next expansion.
#[derive(Clone)]
struct Member<'a> {
    start: usize,
    episode: Episode<'a>,
    /// The basis direction it holds; `None`: the classical controller chooses every step.
    held: Option<NullAction>,
}

/// Beam search along `task` from every valid configuration of `starts` (module
/// documentation), `controller` the search's classical controller; returns the longest motion
/// found (`None` when no start holds every constraint) and the control steps evaluated.
pub(crate) fn beam_search(
    robot: &Robot,
    task: &Task,
    rollout: &RolloutConfig,
    starts: &[JointVector],
    controller: &mut ClassicalController,
    limits: BeamLimits,
) -> (Option<BeamPlan>, u64) {
    let mut spent = 0u64;
    let mut best: Option<BeamPlan> = None;
    let keep = |plan: BeamPlan, best: &mut Option<BeamPlan>| {
        if best
            .as_ref()
            .is_none_or(|b| plan.trajectory.path_length_m > b.trajectory.path_length_m)
        {
            *best = Some(plan);
        }
    };
    let arrived = |best: &Option<BeamPlan>| {
        best.as_ref()
            .is_some_and(|b| b.trajectory.path_length_m >= limits.enough_m)
    };
    let members = starts.iter().enumerate().map(|(start, q)| Member {
        start,
        episode: Episode::start(robot, task, q, rollout),
        held: None,
    });
    let mut members = select(
        members.filter(|m| !m.episode.is_finished()).collect(),
        limits.width,
    );
    let actions = null_actions(robot.dof() - 3);
    let mut depth = 0usize;
    while !members.is_empty() && spent < limits.budget_steps && !arrived(&best) {
        if depth.is_multiple_of(ROLLOUT_EVERY) {
            for member in members.iter().take(ROLLOUTS) {
                let trajectory = continue_rollout(member.episode.clone(), controller);
                spent += steps_evaluated(&trajectory) - member.episode.step_count() as u64;
                let start = member.start;
                keep(BeamPlan { start, trajectory }, &mut best);
            }
        }
        let expand = depth.is_multiple_of(HOLD_STEPS);
        let mut children = Vec::with_capacity(members.len() * (actions.len() + 1));
        for member in &members {
            let context = member.episode.context().expect("members are running");
            let classical = controller.act(context).0;
            let choices: Vec<Option<NullAction>> = if expand {
                std::iter::once(None)
                    .chain(actions.iter().copied().map(Some))
                    .collect()
            } else {
                vec![member.held]
            };
            for held in choices {
                let mut child = member.clone();
                child.held = held;
                let action = held.unwrap_or(classical);
                spent += 1;
                match child.episode.apply(&action, ActingController::Search) {
                    StepOutcome::Continued { .. } => children.push(child),
                    StepOutcome::Truncated { .. } => {
                        let start = child.start;
                        let trajectory = child.episode.finish();
                        keep(BeamPlan { start, trajectory }, &mut best);
                    }
                    StepOutcome::Terminated => {}
                }
            }
        }
        if children.is_empty() {
            break;
        }
        members = select(children, limits.width);
        depth += 1;
    }
    for member in members {
        let start = member.start;
        let trajectory = member.episode.finish();
        keep(BeamPlan { start, trajectory }, &mut best);
    }
    (best, spent)
}

/// Each null-space basis direction at full speed, both ways (`±e_i`, `dims` of them).
pub(crate) fn null_actions(dims: usize) -> Vec<NullAction> {
    (0..dims)
        .flat_map(|axis| {
            [1.0, -1.0].map(|sign| {
                let mut action = NullAction::zeros();
                action[axis] = sign;
                action
            })
        })
        .collect()
}

/// The best member of each diversity cell, then the `width` best of those.
fn select(members: Vec<Member<'_>>, width: usize) -> Vec<Member<'_>> {
    let mut cells: HashMap<Vec<i64>, (f64, Member<'_>)> = HashMap::new();
    for member in members {
        let state = member.episode.state();
        let key = cell_of(state);
        let score = score(state);
        if cells.get(&key).is_none_or(|(kept, _)| score > *kept) {
            cells.insert(key, (score, member));
        }
    }
    let mut ranked: Vec<(f64, Vec<i64>, Member<'_>)> = cells
        .into_iter()
        .map(|(key, (score, member))| (score, key, member))
        .collect();
    // Ties are broken by the cell, so the order never depends on the hash map's.
    ranked.sort_by(|a, b| b.0.total_cmp(&a.0).then_with(|| a.1.cmp(&b.1)));
    ranked.truncate(width);
    ranked.into_iter().map(|(_, _, member)| member).collect()
}

/// The diversity cell of a state: its `q̄` quantised by [`CELL`].
fn cell_of(state: &StepContext<'_>) -> Vec<i64> {
    (0..state.robot.dof())
        .map(|i| ((state.q_normalised[i] + 1.0) / CELL).floor() as i64)
        .collect()
}

/// How promising a state is: its progress along the line first (10 per metre), then the
/// smaller of its joint-limit margin `1 − ρ` and its tool-tilt margin `(θ_max − θ)/θ_max`,
/// plus [`MANIPULABILITY_WEIGHT`] × `w_d`.
fn score(state: &StepContext<'_>) -> f64 {
    let theta_max = state.config.constraints.theta_max_deg;
    let joints = 1.0 - state.rho;
    let tilt = (theta_max - state.tool_angle_deg) / theta_max;
    10.0 * state.along.s_m + joints.min(tilt) + MANIPULABILITY_WEIGHT * state.manipulability
}
