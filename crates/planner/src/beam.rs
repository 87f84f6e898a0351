//! The search's beam stage: a search over action sequences along the whole line, independent
//! of the start ranking and the repair's detours.
//!
//! Every member of the beam is an episode at the same step. Every [`HOLD_STEPS`] steps, each
//! member is expanded into children that follow the search's classical controller or hold one
//! null-space basis direction at full speed (`±e_i` of `B(q)`) until the next expansion; every
//! step goes through the one step implementation (`Episode::apply`), so every child obeys the
//! step rules. The members are grouped by a cell of the normalised joint space `q̄` ([`CELL`]
//! wide) and only the best of each cell is kept ([`score_of`]), so that the beam does not
//! collapse onto one self-motion branch; of those, the `width` best go on. At an expansion
//! the children are judged before their steps are taken ([`predict`]), and only the best
//! [`STEPPED_PER_CELL`] of each cell are stepped. Every
//! [`ROLLOUT_EVERY`] steps the [`ROLLOUTS`] best members are also handed to the classical
//! controller to the end of the line, so a branch that the beam drops later is still measured.
//! The plan is the longest of those rollouts and of the members the beam ends with.

use std::collections::HashMap;

use emg_control::{
    ActingController, ClassicalController, Episode, NullAction, NullSpaceController, RolloutConfig,
    StepContext, StepOutcome, Task, Termination, Trajectory, continue_rollout, tool_angle_deg,
};
use emg_kinematics::{JointVector, Robot};

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

/// Children stepped per diversity cell at an expansion, the best by their prediction
/// ([`predict`]); the best of them by its real state goes on. Measured on the 38 tasks of
/// [`CELL`] with the default search and a beam of 512 (Σ length / Σ bound, time for the 38
/// plans; 0.442 in 3.5 s without the beam): every child stepped 0.541 in 8.0 s, 1 per cell
/// 0.510 in 5.8 s, 2 per cell 0.541 in 6.2 s, 4 per cell 0.541 in 6.9 s.
const STEPPED_PER_CELL: usize = 2;

/// Weight of the directional manipulability `w_d` beside the constraint margin in
/// [`score_of`].
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
struct Member<'a> {
    start: usize,
    episode: Episode<'a>,
    /// The basis direction it holds; `None`: the classical controller chooses every step.
    held: Option<NullAction>,
}

/// A child a member may branch into at an expansion, judged before its step is taken.
struct Proposal {
    /// Index of the member it branches from.
    member: usize,
    /// What it holds until the next expansion.
    held: Option<NullAction>,
    /// Its first action.
    action: NullAction,
    /// The diversity cell of its predicted configuration.
    cell: Vec<i64>,
    /// Its predicted [`score_of`].
    score: f64,
}

/// Beam search along `task` from every valid configuration of `starts` (module
/// documentation), `controller` the search's classical controller; returns the longest motion
/// found (`None` when no start holds every constraint) and the control steps evaluated. It
/// ends early, with what it has, once `stop` (asked every depth) returns true.
pub(crate) fn beam_search(
    robot: &Robot,
    task: &Task,
    rollout: &RolloutConfig,
    starts: &[JointVector],
    controller: &mut ClassicalController,
    limits: BeamLimits,
    stop: &dyn Fn() -> bool,
) -> (Option<BeamPlan>, u64) {
    let mut beam = Beam {
        spent: 0,
        best: None,
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
    while !members.is_empty()
        && beam.spent < limits.budget_steps
        && !beam.arrived(limits)
        && !stop()
    {
        if depth.is_multiple_of(ROLLOUT_EVERY) {
            for member in members.iter().take(ROLLOUTS) {
                let trajectory = continue_rollout(member.episode.clone(), controller);
                beam.spent += steps_evaluated(&trajectory) - member.episode.step_count() as u64;
                beam.keep(member.start, trajectory);
            }
        }
        members = if depth.is_multiple_of(HOLD_STEPS) {
            beam.expand(&members, &actions, controller, limits.width)
        } else {
            let stepped = members.into_iter().map(|mut member| {
                let context = member.episode.context().expect("members are running");
                let action = member.held.unwrap_or_else(|| controller.act(context).0);
                (
                    member.episode.apply(&action, ActingController::Search),
                    member,
                )
            });
            select(beam.advance(stepped.collect::<Vec<_>>()), limits.width)
        };
        depth += 1;
    }
    for member in members {
        beam.keep(member.start, member.episode.finish());
    }
    (beam.best, beam.spent)
}

/// What a beam search has spent and found so far.
struct Beam {
    spent: u64,
    best: Option<BeamPlan>,
}

impl Beam {
    /// Keeps `trajectory` (from start `start`) if it is the longest so far.
    fn keep(&mut self, start: usize, trajectory: Trajectory) {
        if self
            .best
            .as_ref()
            .is_none_or(|b| trajectory.path_length_m > b.trajectory.path_length_m)
        {
            self.best = Some(BeamPlan { start, trajectory });
        }
    }

    /// Whether a motion has got far enough.
    fn arrived(&self, limits: BeamLimits) -> bool {
        self.best
            .as_ref()
            .is_some_and(|b| b.trajectory.path_length_m >= limits.enough_m)
    }

    /// The members that go on after a step: a member whose step ended its episode (a broken
    /// constraint, the line's end or the step cap) leaves the beam, its motion kept if it is
    /// the longest.
    fn advance<'a>(&mut self, stepped: Vec<(StepOutcome, Member<'a>)>) -> Vec<Member<'a>> {
        stepped
            .into_iter()
            .filter_map(|(outcome, member)| self.settle(outcome, member))
            .collect()
    }

    /// `member` after a step with `outcome`: still in the beam, or (its episode over) its
    /// motion kept if it is the longest.
    fn settle<'a>(&mut self, outcome: StepOutcome, member: Member<'a>) -> Option<Member<'a>> {
        self.spent += 1;
        match outcome {
            StepOutcome::Continued { .. } => Some(member),
            StepOutcome::Truncated { .. } | StepOutcome::Terminated => {
                self.keep(member.start, member.episode.finish());
                None
            }
        }
    }

    /// The members after an expansion: each member's classical action and every basis
    /// direction, judged before the step by the configuration it would reach ([`predict`]);
    /// taken best first, the first [`STEPPED_PER_CELL`] children of each diversity cell whose
    /// steps hold every constraint are stepped (a child whose step breaks one leaves its place
    /// to the next best), then [`select`] keeps the best of each cell by its real state and
    /// the `width` best of those. Judging before stepping saves the steps, and the copies of
    /// the episodes, that the selection would discard.
    fn expand<'a>(
        &mut self,
        members: &[Member<'a>],
        actions: &[NullAction],
        controller: &mut ClassicalController,
        width: usize,
    ) -> Vec<Member<'a>> {
        let mut proposals = Vec::with_capacity(members.len() * (actions.len() + 1));
        for (index, member) in members.iter().enumerate() {
            let context = member.episode.context().expect("members are running");
            let classical = controller.act(context).0;
            let choices =
                std::iter::once((None, classical)).chain(actions.iter().map(|a| (Some(*a), *a)));
            for (held, action) in choices {
                proposals.push(predict(context, index, held, action));
            }
        }
        // Best first; ties keep the order of the members and their actions (a stable sort).
        proposals.sort_by(|a, b| b.score.total_cmp(&a.score));
        let mut filled: HashMap<Vec<i64>, usize> = HashMap::new();
        let mut children = Vec::with_capacity(width);
        for proposal in proposals {
            if filled
                .get(&proposal.cell)
                .is_some_and(|&n| n >= STEPPED_PER_CELL)
            {
                continue;
            }
            let parent = &members[proposal.member];
            let mut child = Member {
                start: parent.start,
                episode: parent.episode.clone(),
                held: proposal.held,
            };
            let outcome = child
                .episode
                .apply(&proposal.action, ActingController::Search);
            if let Some(going_on) = self.settle(outcome, child) {
                *filled.entry(proposal.cell).or_insert(0) += 1;
                children.push(going_on);
            }
        }
        select(children, width)
    }
}

/// The proposal of taking `action` from `state` (member `member`, holding `held` after).
fn predict(
    state: &StepContext<'_>,
    member: usize,
    held: Option<NullAction>,
    action: NullAction,
) -> Proposal {
    let robot = state.robot;
    let step_s = state.config.dt_s * state.step_fraction();
    let dq = state.joint_velocity(&action) * step_s;
    let q = state.q + dq;
    let axis = state.kinematics.tool_axis() + state.kinematics.tool_axis_jacobian() * dq;
    let angle = tool_angle_deg(&axis.normalize(), &state.task.n);
    let normalised = robot.limits().normalise(&q);
    let progress_m = state.along.s_m + state.config.speed_m_per_s * step_s;
    Proposal {
        member,
        held,
        action,
        cell: cell_of(robot.dof(), &normalised),
        score: score_of(state, progress_m, normalised.amax(), angle),
    }
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
/// (Ranked by index: a member is large, so it is moved only once.)
fn select(members: Vec<Member<'_>>, width: usize) -> Vec<Member<'_>> {
    let mut cells: HashMap<Vec<i64>, (f64, usize)> = HashMap::new();
    for (index, member) in members.iter().enumerate() {
        let state = member.episode.state();
        let key = cell_of(state.robot.dof(), &state.q_normalised);
        let score = score_of(state, state.along.s_m, state.rho, state.tool_angle_deg);
        if cells.get(&key).is_none_or(|(kept, _)| score > *kept) {
            cells.insert(key, (score, index));
        }
    }
    let mut ranked: Vec<(f64, Vec<i64>, usize)> = cells
        .into_iter()
        .map(|(key, (score, index))| (score, key, index))
        .collect();
    // Ties are broken by the cell, so the order never depends on the hash map's.
    ranked.sort_by(|a, b| b.0.total_cmp(&a.0).then_with(|| a.1.cmp(&b.1)));
    ranked.truncate(width);
    let mut slots: Vec<Option<Member<'_>>> = members.into_iter().map(Some).collect();
    ranked
        .into_iter()
        .filter_map(|(_, _, index)| slots[index].take())
        .collect()
}

/// The diversity cell of a normalised configuration `q̄` (its first `dof` joints): `q̄`
/// quantised by [`CELL`].
fn cell_of(dof: usize, normalised: &JointVector) -> Vec<i64> {
    (0..dof)
        .map(|i| ((normalised[i] + 1.0) / CELL).floor() as i64)
        .collect()
}

/// How promising a configuration is, at progress `progress_m`, joint-limit proximity `rho`
/// and tool angle `angle_deg`, with `state`'s directional manipulability `w_d`: its progress
/// along the line first (10 per metre), then the smaller of its joint-limit margin `1 − ρ` and
/// its tool-tilt margin `(θ_max − θ)/θ_max`, plus [`MANIPULABILITY_WEIGHT`] × `w_d`.
fn score_of(state: &StepContext<'_>, progress_m: f64, rho: f64, angle_deg: f64) -> f64 {
    let theta_max = state.config.constraints.theta_max_deg;
    let joints = 1.0 - rho;
    let tilt = (theta_max - angle_deg) / theta_max;
    10.0 * progress_m + joints.min(tilt) + MANIPULABILITY_WEIGHT * state.manipulability
}

/// Steps a rollout evaluated: every accepted step, and the rejected one that ended it.
pub(crate) fn steps_evaluated(trajectory: &Trajectory) -> u64 {
    let accepted = trajectory.steps.len().saturating_sub(1) as u64;
    accepted
        + u64::from(matches!(
            trajectory.termination,
            Termination::Violation { .. }
        ))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::test_support::{demo, fr3};

    #[test]
    fn a_proposal_predicts_the_configuration_its_step_reaches() {
        let robot = fr3();
        let (task, q) = demo(&robot);
        let config = RolloutConfig::default();
        let mut controller = ClassicalController::default();
        for action in [
            NullAction::new(1.0, 0.0, 0.0, 0.0),
            NullAction::new(0.0, 0.0, -1.0, 0.0),
            NullAction::new(0.3, -0.7, 0.1, 0.9),
        ] {
            let mut episode = Episode::start(&robot, &task, &q, &config);
            // A few classical steps first, so that the state is not the seed's.
            for _ in 0..5 {
                let context = episode.context().expect("running");
                let classical = controller.act(context).0;
                episode.apply(&classical, ActingController::Classical);
            }
            let state = episode.state().clone();
            let proposal = predict(&state, 0, Some(action), action);
            episode.apply(&action, ActingController::Search);
            let reached = episode.state();
            // The configuration, hence the cell, is exact; the progress and the tool angle are
            // first order (measured within 1.2e-4 of the score the step reaches).
            assert_eq!(proposal.cell, cell_of(robot.dof(), &reached.q_normalised));
            let exact = score_of(
                &state,
                reached.along.s_m,
                reached.rho,
                reached.tool_angle_deg,
            );
            assert!(
                (proposal.score - exact).abs() < 5e-4,
                "predicted {} against {exact}",
                proposal.score
            );
        }
    }
}
