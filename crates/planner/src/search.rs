//! The search planner: many starts instead of one, ranked by rollouts.
//!
//! The task is known before the motion starts, and which self-motion branch the arm starts on
//! decides most of how far it gets. So instead of the paper's first valid seed, the search
//! first rolls out the pipeline's own plan (its seed and controller, so the search never does
//! worse), then gathers candidate starts on the start pose from every source at hand, in a
//! fixed order: the task's generating configuration `q0_seed` and its two heuristic ascents
//! (`q_mu`, `q_jl`), a batch of diffusion samples (all of them, not the first valid one), and
//! cone-IK solutions from seeded random restarts spread over the branches. Each valid start is
//! ranked by a rollout of the classical controller (cheap, no network); the best
//! [`SearchConfig::finalists`] are rolled out again with the requested controller, and the
//! longest rollout of all is the plan.
//!
//! The budget counts control steps (every step evaluated, accepted or rejected), never wall
//! time, so a plan is a pure function of the task and the configuration, whatever the machine
//! or the thread count. Every rollout goes through the shared `emg_control::rollout`: a plan
//! is a sequence of steps the one step implementation accepted.

use emg_control::{
    OutOfRange, RolloutConfig, Task, Termination, Trajectory, first_violation, rollout,
};
use emg_diffusion::{DpSeeder, SeedWorkspace};
use emg_kinematics::{JointVector, PoseTarget, ProjectionConfig, Robot, project_to_pose};
use emg_seeding::{
    HeuristicConfig, HeuristicObjective, IkConfig, cone_ik_solutions, heuristic_seed,
};
use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;
use serde::{Deserialize, Serialize};

use crate::controller::{ControllerKind, Executor, ExecutorConfig, ExecutorError};
use crate::seed::Seed;

/// Settings of the search planner.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct SearchConfig {
    /// Control steps the ranking and final rollouts may spend together; a rollout is started
    /// only while some budget is left.
    pub budget_steps: u64,
    /// Diffusion samples drawn as candidate starts (when the seeder is loaded).
    pub dp_samples: usize,
    /// Random restarts of the cone IK at `p0`.
    pub ik_restarts: usize,
    /// Best-ranked starts rolled out again with the requested controller.
    pub finalists: usize,
    /// Two candidate starts closer than this (rad, largest joint difference) count as one.
    pub distinct_rad: f64,
    /// Seed of the IK restarts.
    pub seed: u64,
}

impl Default for SearchConfig {
    fn default() -> Self {
        Self {
            budget_steps: 20_000,
            dp_samples: 32,
            ik_restarts: 64,
            finalists: 4,
            distinct_rad: 0.05,
            seed: 20_261_123,
        }
    }
}

/// Most steps a search budget may hold (keeps a plan to seconds).
pub const MAX_SEARCH_BUDGET_STEPS: u64 = 10_000_000;

impl SearchConfig {
    /// Checks every value against its allowed range.
    pub fn validate(&self) -> Result<(), OutOfRange> {
        let out = |field, value: f64, allowed| OutOfRange {
            field,
            value,
            allowed,
        };
        if !(1..=MAX_SEARCH_BUDGET_STEPS).contains(&self.budget_steps) {
            return Err(out(
                "search.budget_steps",
                self.budget_steps as f64,
                "[1, 10000000]",
            ));
        }
        for (field, value) in [
            ("search.dp_samples", self.dp_samples),
            ("search.ik_restarts", self.ik_restarts),
        ] {
            if value > 10_000 {
                return Err(out(field, value as f64, "[0, 10000]"));
            }
        }
        if !(1..=64).contains(&self.finalists) {
            return Err(out("search.finalists", self.finalists as f64, "[1, 64]"));
        }
        if !(self.distinct_rad.is_finite() && self.distinct_rad >= 0.0) {
            return Err(out("search.distinct_rad", self.distinct_rad, "[0, ∞)"));
        }
        Ok(())
    }
}

/// A start the search may roll out from, with the name of its source.
#[derive(Clone, Debug)]
struct Candidate {
    q: JointVector,
    source: &'static str,
}

/// Everything the search needs besides the task and the controller.
pub(crate) struct SearchContext<'a> {
    pub robot: &'a Robot,
    pub rollout: &'a RolloutConfig,
    pub executor: &'a ExecutorConfig,
    pub seeder: Option<&'a DpSeeder>,
    pub config: &'a SearchConfig,
}

/// The searched plan of `task`: its start and its rollout. The pipeline's own plan (`seed`
/// rolled out by `finalist`, the executor of `controller`) is always evaluated first, so the search never returns less;
/// then the other candidates are ranked by classical rollouts and the best
/// [`SearchConfig::finalists`] rolled out by `controller`, while budget is left.
pub(crate) fn search(
    context: &SearchContext<'_>,
    task: &Task,
    seed: Seed,
    controller: ControllerKind,
    finalist: &mut Executor,
) -> Result<(Seed, Trajectory), ExecutorError> {
    let robot = context.robot;
    let budget = context.config.budget_steps;
    let mut classical = Executor::new(ControllerKind::Classical, None, context.executor)?;
    let pipeline = rollout(robot, task, &seed.q, finalist, context.rollout);
    let mut spent = steps_evaluated(&pipeline);
    let candidates = candidates(context, task, &seed.q);
    let mut best = (seed, pipeline);
    let mut consider = |candidate: &Candidate, trajectory: Trajectory| {
        if trajectory.path_length_m > best.1.path_length_m {
            let seed = Seed {
                q: candidate.q,
                source: candidate.source,
                projection_iterations: None,
            };
            best = (seed, trajectory);
        }
    };
    let mut ranked: Vec<(usize, f64)> = Vec::new();
    for (index, candidate) in candidates.iter().enumerate() {
        if spent >= budget {
            break;
        }
        let trajectory = rollout(robot, task, &candidate.q, &mut classical, context.rollout);
        spent += steps_evaluated(&trajectory);
        ranked.push((index, trajectory.path_length_m));
        consider(candidate, trajectory);
    }
    if controller != ControllerKind::Classical {
        // Longest first; equal lengths keep the candidates' order.
        ranked.sort_by(|a, b| b.1.total_cmp(&a.1));
        for &(index, _) in ranked.iter().take(context.config.finalists) {
            if spent >= budget {
                break;
            }
            let candidate = &candidates[index];
            let trajectory = rollout(robot, task, &candidate.q, finalist, context.rollout);
            spent += steps_evaluated(&trajectory);
            consider(candidate, trajectory);
        }
    }
    Ok(best)
}

/// Steps a rollout evaluated: every accepted step, and the rejected one that ended it.
fn steps_evaluated(trajectory: &Trajectory) -> u64 {
    let accepted = trajectory.steps.len().saturating_sub(1) as u64;
    accepted
        + u64::from(matches!(
            trajectory.termination,
            Termination::Violation { .. }
        ))
}

/// The distinct valid starts on the start pose other than `pipeline` (the seed already
/// rolled out), in the fixed order of the module documentation.
fn candidates(context: &SearchContext<'_>, task: &Task, pipeline: &JointVector) -> Vec<Candidate> {
    let robot = context.robot;
    let constraints = &context.rollout.constraints;
    let distinct_rad = context.config.distinct_rad;
    let mut found: Vec<Candidate> = Vec::new();
    let mut offer = |q: JointVector, source: &'static str| {
        let kinematics = robot.forward(&q);
        let valid = first_violation(robot, task, &q, &kinematics, constraints).is_none();
        let distinct = (pipeline - q).amax() >= distinct_rad
            && found.iter().all(|c| (c.q - q).amax() >= distinct_rad);
        if valid && distinct {
            found.push(Candidate { q, source });
        }
    };
    let projection = ProjectionConfig::default();
    let target = PoseTarget {
        position: task.p0,
        tool_axis: task.n,
        roll_axis: None,
    };
    if let Some(q0) = task.q0_seed {
        offer(q0, "generating");
        for (objective, source) in [
            (HeuristicObjective::Manipulability, "q_mu"),
            (HeuristicObjective::JointCentring, "q_jl"),
        ] {
            if let Ok(seed) = heuristic_seed(
                robot,
                task,
                objective,
                &HeuristicConfig::default(),
                &projection,
            ) {
                offer(seed.q, source);
            }
        }
    }
    if let Some(seeder) = context.seeder
        && context.config.dp_samples > 0
        && let Ok(samples) = seeder.candidates(
            robot,
            task,
            context.config.dp_samples,
            &mut SeedWorkspace::default(),
        )
    {
        for sample in &samples {
            if let Ok((q, _)) = project_to_pose(robot, sample, &target, &projection) {
                offer(q, "dp");
            }
        }
    }
    let ik = IkConfig {
        restarts: context.config.ik_restarts,
        ..IkConfig::default()
    };
    let mut rng = ChaCha8Rng::seed_from_u64(context.config.seed);
    for q in cone_ik_solutions(robot, &task.p0, &task.n, &ik, &mut rng) {
        offer(q, "ik");
    }
    found
}
