//! The search planner: many starts instead of one, ranked by rollouts, guided by the
//! reachability bound.
//!
//! The task is known before the motion starts, and which self-motion branch the arm starts on
//! decides most of how far it gets. The planner scans the task's reachability bound first
//! (`crate::reach`) and hands it to the search. The search first rolls out the pipeline's own
//! plan (its seed and controller, so the search never does worse); then, the long-horizon
//! stage, it follows the scan's chains of configurations from `p0` (`witness_chains`: one
//! valid configuration per grid point on one self-motion branch, so the branch that survives
//! far along the line is known before the motion starts) with each controller taking over
//! where a chain ends (`crate::track`); then it gathers candidate starts on the start pose from
//! every source at hand, in a fixed order: the task's generating configuration `q0_seed` and
//! its two heuristic ascents (`q_mu`, `q_jl`), a batch of diffusion samples (all of them, not
//! the first valid one), and cone-IK solutions from seeded random restarts spread over the
//! branches. Each valid start is ranked by a rollout of the search's own classical controller
//! (cheap, no network; [`SearchConfig::classical_gains`]: the paper's Eq. 3 with a far
//! stronger cone term and the tool axis led ahead of its drift, since on long lines the tool
//! tilt ends most motions); the best [`SearchConfig::finalists`] are rolled out again with the
//! requested controller. Then the longest rollouts of the best [`SearchConfig::repaired_starts`]
//! starts are repaired in turn where they failed: from 1, 2, 4, … 32 steps before the end, each
//! null-space basis direction (±`e_i` of `B(q)`) is held for a few steps and the requested and
//! the search's classical controller take over again; a round that goes further starts the next
//! round from the new rollout. The longest rollout of all is the plan. The search ends early once a
//! rollout reaches the first grid point the scan found no configuration at: nothing is left
//! that the bound can tell. Where the budget is spent and the longest rollout ends below
//! [`SHORTFALL_SHARE`] × the bound, the budget grows ([`SearchConfig::widened_budget_steps`])
//! and the search goes on wider: more chains, diffusion samples and IK restarts, the starts not
//! rolled out yet ranked and re-rolled, the leaders not yet settled repaired. Where it still
//! ends short, the far-end stage plans the line backwards, from points beyond the plan's end
//! back to `p0`, and takes each motion that gets past `p0` read forwards and followed forwards
//! from `p0`, asking again beyond each new end ([`SearchConfig::far_end_shares`],
//! `crate::far_end`): planned from `p0`, the search must guess at the start the branch that
//! survives far along the line; planned from there, it starts on one. Where it still ends
//! below [`SearchConfig::beam_below_share`] × the bound, a beam search over action sequences
//! from every start rolled out goes last ([`SearchConfig::beam_width`], `crate::beam`).
//!
//! The repair replays the actions of the rollout it branches from once per round (so its states
//! recur exactly), keeps snapshots of the episode at the branch points, and continues each
//! branch from a copy of its snapshot (`emg_control::continue_rollout`): every rollout goes
//! through the one step implementation. The action each step took is recorded, detours as
//! `ActingController::Search`.
//!
//! The budget counts control steps (every step evaluated, accepted or rejected, replays
//! included; the scan's IK is not counted), never wall time, so a plan is a pure function of
//! the task and the configuration, whatever the machine or the thread count.

use emg_control::{
    ARRIVAL_M, ActingController, ClassicalController, ClassicalGains, Episode, NullAction,
    NullSpaceController, OutOfRange, RolloutConfig, StepContext, StepRecord, Task, Trajectory,
    continue_rollout, first_violation,
};
use emg_diffusion::{DpSeeder, SeedWorkspace};
use emg_kinematics::{JointVector, PoseTarget, ProjectionConfig, Robot, project_to_pose};
use emg_seeding::{
    HeuristicConfig, HeuristicObjective, IkConfig, cone_ik_solutions, heuristic_seed,
};
use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;
use serde::{Deserialize, Serialize};

use crate::beam::{BeamLimits, beam_search, null_actions, steps_evaluated};
use crate::controller::Executor;
use crate::far_end::{
    forward_reference, probe_starts, read_forwards, reversed_reach, reversed_surface, reversed_task,
};
use crate::reach::{Reach, ReachConfig, SHORTFALL_SHARE, witness_chains};
use crate::seed::{CHAIN_SOURCE, FAR_END_SOURCE, Seed};
use crate::track::{Reference, progress_per_step, tracking_action};

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
    /// Steps a detour of the repair stage holds its basis direction.
    pub detour_steps: usize,
    /// Starts whose longest rollouts the repair stage works on, best first.
    pub repaired_starts: usize,
    /// The search ends as soon as a rollout comes this close (m) to the first grid point the
    /// reachability scan found no configuration at (0: once a rollout reaches it, which proves
    /// the scan short there and leaves nothing it can tell).
    pub stop_within_m: f64,
    /// Largest joint change (rad) between the scan's configurations at neighbouring grid
    /// points that still counts as one self-motion branch, in its chains.
    pub chain_jump_rad: f64,
    /// The scan's chains (farthest-reaching first) the long-horizon stage follows.
    pub chains: usize,
    /// Gains of the search's own classical controller, which ranks the candidate starts and
    /// takes over after detours and chains beside the requested controller
    /// ([`search_classical_gains`]). Given in a configuration file, it replaces the whole set:
    /// the gains it leaves out take the paper's values (`ClassicalGains::default`).
    pub classical_gains: ClassicalGains,
    /// Seed of the IK restarts.
    pub seed: u64,
    /// Control steps added to the budget when the search has ended below
    /// [`SHORTFALL_SHARE`] × the task's bound (0: never). The search then goes on from where it
    /// stopped, wider: [`SearchConfig::widened_breadth`] times as many diffusion samples, IK
    /// restarts and chains, the starts it has not rolled out yet ranked and repaired like the
    /// first ones, the leaders it had not finished repairing repaired further. This is where the
    /// bound guides the budget: the work goes to the plans it shows far from their end. Measured
    /// on the first 1,000 evaluation tasks of each shipped arm, Σ length / Σ bound over the
    /// lines whose bound is 1 m or more, without and with the widened pass (25,000 steps,
    /// breadth 4): FR3 0.870 → 0.886, iiwa 0.921 → 0.940, UR5e 0.845 → 0.860; 50,000 steps gave
    /// the same lengths, breadth 2 about half the gain.
    pub widened_budget_steps: u64,
    /// How many times as many diffusion samples, IK restarts and chains the widened search
    /// draws ([`SearchConfig::widened_budget_steps`]).
    pub widened_breadth: usize,
    /// Members of the beam stage (`crate::beam`), run last where the longest rollout still
    /// ends below [`SearchConfig::beam_below_share`] × the bound (0: never): a search over
    /// action sequences from every start the search rolled out, diverse across joint-space
    /// cells. Measured on the first 1,000 evaluation tasks of each shipped arm at the default
    /// budget, Σ length / Σ bound over the lines whose bound is 1 m or more, without and with
    /// a beam of 512 (300,000 steps), and the mean time per plan: FR3 0.886 → 0.907 (42.1 →
    /// 46.8 ms), iiwa 0.940 → 0.948 (44.0 → 46.3 ms), UR5e 0.860 → 0.866 (49.8 → 53.2 ms); a
    /// beam of 1,024 gave the same lengths.
    pub beam_width: usize,
    /// Control steps the beam stage may evaluate (default 100,000); the budget bounds the
    /// slowest plan. On the first 1,000 evaluation tasks of the FR3 and the iiwa 14, 100,000
    /// gave the same lengths as 300,000 and 1,000,000 (with the beam below 0.9 and below 0.95
    /// × the bound); 50,000 gave less.
    pub beam_budget_steps: u64,
    /// The beam stage runs where the longest rollout still ends below this share of the bound
    /// (default 0.95, in (0, 1]): above [`SHORTFALL_SHARE`], where the earlier stages stop,
    /// since the beam also finds the last few centimetres of plans that end near the bound.
    /// Measured on the 10,000 evaluation tasks of each seven-axis arm at the default budget,
    /// Σ length / Σ bound over the lines whose bound is 1 m or more and over all lines, at 0.9
    /// (with a 300,000-step beam) and at 0.95 (100,000): FR3 0.9196 → 0.9206 and 0.9596 →
    /// 0.9602, iiwa 0.9498 → 0.9503 and 0.9691 → 0.9694, at about the same time per plan; on
    /// the first 1,000, 0.99 gave FR3 ≥ 1 m 0.9177 (0.9169 at 0.95) at nearly twice the time.
    pub beam_below_share: f64,
    /// Shares of the scan's reach from which the far-end stage plans back to `p0` (default
    /// 0.95, 0.8, 0.65 and 0.5; empty: no far-end stage), run before the beam where the longest
    /// rollout still ends below [`SHORTFALL_SHARE`] × the bound: from the grid point at each
    /// share beyond the longest rollout, the search's first pass plans the motion back to `p0`
    /// on the scan read backwards, and from the points gap-eval asks from beyond it (3 and 10
    /// grid steps past its end, halfway to the bound, half a grid step before it) the whole
    /// planner does (`Planner::motion_back`, its own far-end stage left out); each
    /// motion that gets back past `p0` is taken read forwards and followed from `p0`, each tail
    /// going on where it ends; while the probes take the plan further, the points beyond its
    /// new end are asked in turn. Measured, when the stage
    /// planned back by the search's first pass from the shares alone, on the first 1,000
    /// evaluation tasks of each shipped arm at the default budget, Σ length / Σ bound over the
    /// lines whose bound is 1 m or more, without and with the stage, and the mean time per
    /// plan: FR3 0.907 → 0.916 (47.1 → 47.2 ms), iiwa 0.948 → 0.958 (45.7 → 45.9 ms), UR5e
    /// 0.866 → 0.886 (55.3 → 59.7 ms). The motions back from gap-eval's points, read forwards
    /// and asked again beyond each new end, then raised it on the 10,000 evaluation tasks of
    /// each arm at the default budget (`cargo xtask search-eval`): FR3 0.921 → 0.928 (49.0 →
    /// 53.2 ms), iiwa 0.950 → 0.955 (47.3 → 45.2 ms), UR5e 0.882 → 0.893 (54.4 → 72.6 ms), the
    /// slowest plan from about 0.4 s to about 3.5 s (each motion back is a whole plan).
    pub far_end_shares: Vec<f64>,
}

/// The search's classical gains ([`SearchConfig::classical_gains`]): the paper's `k_μ` and
/// `k_jl`, the cone term 100 times stronger (`k_θ` 20 against 0.2) and gated from 15° before the
/// cone's edge, and the tool axis led 20° ahead of the tilt the line's motion causes (`k_lead`
/// 5; `emg_control::lead_axis`). On a long line the tool tilt, not the joints, ends most
/// motions: a tilt corrected only near the edge is corrected too late at `a_max`. Measured on
/// the first 1,000 FR3 evaluation tasks at the default budget, Σ length / Σ bound over the
/// lines whose bound is 1 m or more: 0.807 with the paper's gains, 0.861 with the cone term
/// alone, 0.873 with the lead.
pub fn search_classical_gains() -> ClassicalGains {
    ClassicalGains {
        k_theta: 20.0,
        cone_gate_width_deg: 15.0,
        k_lead: 5.0,
        lead_deg: 20.0,
        ..ClassicalGains::default()
    }
}

impl Default for SearchConfig {
    fn default() -> Self {
        Self {
            budget_steps: 10_000,
            dp_samples: 32,
            ik_restarts: 64,
            finalists: 8,
            distinct_rad: 0.05,
            detour_steps: 10,
            repaired_starts: 8,
            stop_within_m: 0.0,
            chain_jump_rad: 0.25,
            chains: 4,
            classical_gains: search_classical_gains(),
            seed: 20_261_123,
            widened_budget_steps: 25_000,
            widened_breadth: 4,
            beam_width: 512,
            beam_budget_steps: 100_000,
            beam_below_share: 0.95,
            far_end_shares: vec![0.95, 0.8, 0.65, 0.5],
        }
    }
}

/// Most shares [`SearchConfig::far_end_shares`] may hold.
pub const MAX_FAR_END_SHARES: usize = 8;

/// Most steps a search budget may hold (keeps a plan to seconds).
pub const MAX_SEARCH_BUDGET_STEPS: u64 = 10_000_000;

impl SearchConfig {
    /// Checks every value against its allowed range.
    pub fn validate(&self) -> Result<(), OutOfRange> {
        let count = |n: usize| n as f64;
        let within = |low: f64, high: f64| move |n: f64| (low..=high).contains(&n);
        OutOfRange::require(
            "search.budget_steps",
            self.budget_steps as f64,
            "[1, 10000000]",
            within(1.0, MAX_SEARCH_BUDGET_STEPS as f64),
        )?;
        for (field, value) in [
            ("search.dp_samples", self.dp_samples),
            ("search.ik_restarts", self.ik_restarts),
        ] {
            OutOfRange::require(field, count(value), "[0, 10000]", within(0.0, 10_000.0))?;
        }
        for (field, value) in [
            ("search.finalists", self.finalists),
            ("search.repaired_starts", self.repaired_starts),
        ] {
            OutOfRange::require(field, count(value), "[1, 64]", within(1.0, 64.0))?;
        }
        OutOfRange::require(
            "search.widened_budget_steps",
            self.widened_budget_steps as f64,
            "[0, 10000000]",
            within(0.0, MAX_SEARCH_BUDGET_STEPS as f64),
        )?;
        OutOfRange::require(
            "search.beam_budget_steps",
            self.beam_budget_steps as f64,
            "[0, 10000000]",
            within(0.0, MAX_SEARCH_BUDGET_STEPS as f64),
        )?;
        OutOfRange::require(
            "search.beam_width",
            count(self.beam_width),
            "[0, 4096]",
            within(0.0, 4096.0),
        )?;
        OutOfRange::require(
            "search.beam_below_share",
            self.beam_below_share,
            "(0, 1]",
            |s| s > 0.0 && s <= 1.0,
        )?;
        OutOfRange::require(
            "search.widened_breadth",
            count(self.widened_breadth),
            "[1, 16]",
            within(1.0, 16.0),
        )?;
        OutOfRange::require(
            "search.detour_steps",
            count(self.detour_steps),
            "[1, 100]",
            within(1.0, 100.0),
        )?;
        OutOfRange::require("search.distinct_rad", self.distinct_rad, "[0, ∞)", |d| {
            d >= 0.0
        })?;
        OutOfRange::require("search.stop_within_m", self.stop_within_m, "[0, 1]", |d| {
            (0.0..=1.0).contains(&d)
        })?;
        OutOfRange::require(
            "search.chain_jump_rad",
            self.chain_jump_rad,
            "(0, 6.3]",
            |r| r > 0.0 && r <= 6.3,
        )?;
        OutOfRange::require("search.chains", count(self.chains), "[0, 64]", |n| {
            n <= 64.0
        })?;
        OutOfRange::require(
            "search.far_end_shares (how many)",
            count(self.far_end_shares.len()),
            "[0, 8]",
            within(0.0, MAX_FAR_END_SHARES as f64),
        )?;
        for &share in &self.far_end_shares {
            OutOfRange::require("search.far_end_shares", share, "(0, 1]", |s| {
                s > 0.0 && s <= 1.0
            })?;
        }
        self.classical_gains.validate().map_err(|error| OutOfRange {
            field: search_gain_field(error.field),
            ..error
        })
    }
}

/// The name under `search` of a classical gain's field (`gains.k_mu` is
/// `search.classical_gains.k_mu` there).
fn search_gain_field(field: &'static str) -> &'static str {
    match field {
        "gains.k_mu" => "search.classical_gains.k_mu",
        "gains.k_jl" => "search.classical_gains.k_jl",
        "gains.k_theta" => "search.classical_gains.k_theta",
        "gains.cone_gate_width_deg" => "search.classical_gains.cone_gate_width_deg",
        "gains.k_lead" => "search.classical_gains.k_lead",
        "gains.lead_deg" => "search.classical_gains.lead_deg",
        other => other,
    }
}

/// How many candidate starts and chains one pass of the search draws.
#[derive(Clone, Copy, Debug)]
struct Breadth {
    dp_samples: usize,
    ik_restarts: usize,
    chains: usize,
}

impl Breadth {
    /// The configured counts, each times `factor`.
    fn of(config: &SearchConfig, factor: usize) -> Self {
        Self {
            dp_samples: config.dp_samples * factor,
            ik_restarts: config.ik_restarts * factor,
            chains: config.chains * factor,
        }
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
    /// The motion the planner the search plans for plans back from a point along the task's
    /// line (`Planner::motion_back`): the far-end stage asks it from the points beyond the plan.
    pub motion_back: &'a dyn Fn(&Task, f64) -> Option<Trajectory>,
    pub robot: &'a Robot,
    pub rollout: &'a RolloutConfig,
    pub reach: &'a ReachConfig,
    pub seeder: Option<&'a DpSeeder>,
    pub config: &'a SearchConfig,
    /// Asked between rollouts whether the one who asked for the plan wants it no more: once it
    /// says so, the search ends with the longest rollout it has.
    pub stop: &'a (dyn Fn() -> bool + Sync),
}

/// An action a rollout issued, and who chose it.
type Issued = (NullAction, ActingController);

/// A detour: one null-space action held for a few steps.
#[derive(Clone, Copy, Debug)]
struct Detour {
    action: NullAction,
    steps: usize,
}

/// What a search rollout does before its tail controller takes over.
#[derive(Clone, Copy)]
enum Lead<'r> {
    /// A detour, held for its steps.
    Detour(Detour),
    /// Follows a reference motion while it reaches one step further along the line.
    Track(&'r Reference),
}

/// The controller of one search rollout from the step it takes over: it follows `lead`, then
/// hands over to `tail` for good; it records every action it issues.
struct Branch<'a, 'r> {
    lead: Option<Lead<'r>>,
    tail: &'a mut Executor,
    issued: Vec<Issued>,
}

impl NullSpaceController for Branch<'_, '_> {
    fn reset(&mut self, first: &StepContext<'_>) {
        self.issued.clear();
        self.tail.reset(first);
    }

    fn act(&mut self, step: &StepContext<'_>) -> Issued {
        let led = match self.lead {
            Some(Lead::Detour(detour)) if self.issued.len() < detour.steps => Some(detour.action),
            Some(Lead::Track(reference)) => {
                let next_m = step.along.s_m + progress_per_step(step);
                reference
                    .at(next_m)
                    .map(|target| tracking_action(step, &target))
            }
            _ => None,
        };
        let chosen = match led {
            Some(action) => (action, ActingController::Search),
            None => {
                self.lead = None;
                self.tail.act(step)
            }
        };
        self.issued.push(chosen);
        chosen
    }
}

/// The longest rollout so far, with its start and the actions that reproduce it.
#[derive(Clone)]
struct Best {
    seed: Seed,
    trajectory: Trajectory,
    issued: Vec<Issued>,
}

/// One task's search: the budget spent so far and the leaders, the longest rollout from each
/// of the best starts so far (longest first, at most [`SearchConfig::repaired_starts`]).
struct Search<'a> {
    context: &'a SearchContext<'a>,
    task: &'a Task,
    /// Control steps the search may evaluate in all.
    budget: u64,
    /// The search ends as soon as a rollout gets this far (m): nothing is left to find.
    enough_m: f64,
    spent: u64,
    leaders: Vec<Best>,
    /// The starts rolled out from the start pose so far (the pipeline's seed and the
    /// candidates; not the chains' starts).
    tried: Vec<Seed>,
    /// The starts whose repair rounds have ended without going further.
    settled: Vec<JointVector>,
}

impl<'a> Search<'a> {
    /// A search of `task` with nothing spent and no leader yet.
    fn new(context: &'a SearchContext<'a>, task: &'a Task, budget: u64, enough_m: f64) -> Self {
        Self {
            context,
            task,
            budget,
            enough_m,
            spent: 0,
            leaders: Vec::new(),
            tried: Vec::new(),
            settled: Vec::new(),
        }
    }
}

impl Search<'_> {
    /// Whether the search is over: its budget spent, its longest rollout long enough, or its
    /// plan no longer wanted.
    fn done(&self) -> bool {
        self.spent >= self.budget || self.arrived() || (self.context.stop)()
    }

    /// Whether the longest rollout has got far enough that nothing is left to find.
    fn arrived(&self) -> bool {
        self.longest_m() >= self.enough_m
    }

    /// The length of the longest rollout so far (m; −∞ before the first).
    fn longest_m(&self) -> f64 {
        self.leaders
            .first()
            .map_or(f64::NEG_INFINITY, |b| b.trajectory.path_length_m)
    }

    /// Rolls out from `seed` with `tail`, charges its steps to the budget, and keeps it if it
    /// is among the longest so far.
    fn try_start(&mut self, seed: &Seed, tail: &mut Executor) -> f64 {
        let context = self.context;
        self.tried.push(seed.clone());
        let episode = Episode::start(context.robot, self.task, &seed.q, context.rollout);
        self.try_branch(seed, episode, &[], None, tail)
    }

    /// Takes over `episode` (from `seed`, after the actions `prefix`) with `lead` then `tail`,
    /// charges the steps it evaluates to the budget, and keeps the rollout if it is among the
    /// longest so far; returns its length.
    fn try_branch(
        &mut self,
        seed: &Seed,
        episode: Episode<'_>,
        prefix: &[Issued],
        lead: Option<Lead<'_>>,
        tail: &mut Executor,
    ) -> f64 {
        let mut branch = Branch {
            lead,
            tail,
            issued: Vec::new(),
        };
        let trajectory = continue_rollout(episode, &mut branch);
        self.spent += steps_evaluated(&trajectory).saturating_sub(prefix.len() as u64);
        let length = trajectory.path_length_m;
        let mut issued = prefix.to_vec();
        issued.extend(branch.issued);
        self.offer(Best {
            seed: seed.clone(),
            trajectory,
            issued,
        });
        length
    }

    /// Keeps `rollout` among the leaders if it is the longest from its start so far and
    /// among the longest of all; a tie keeps the rollout found first.
    fn offer(&mut self, rollout: Best) {
        let length = rollout.trajectory.path_length_m;
        if let Some(same) = self.leaders.iter().position(|b| b.seed.q == rollout.seed.q) {
            if length <= self.leaders[same].trajectory.path_length_m {
                return;
            }
            self.leaders.remove(same);
        }
        let at = self
            .leaders
            .iter()
            .position(|b| length > b.trajectory.path_length_m)
            .unwrap_or(self.leaders.len());
        self.leaders.insert(at, rollout);
        self.leaders.truncate(self.context.config.repaired_starts);
    }

    /// The longest rollout from `seed` so far.
    fn leader_of(&self, seed: &Seed) -> Option<&Best> {
        self.leaders.iter().find(|b| b.seed.q == seed.q)
    }

    /// Repairs the leaders in turn, longest first: rounds of detours near the end of the
    /// longest rollout from the leader's start (from a few steps before where it stopped, each
    /// basis direction held for [`SearchConfig::detour_steps`] steps, then each tail); a round
    /// that goes further starts the next round from the new rollout. A start whose rounds
    /// have ended without going further is settled and not repaired again.
    fn repair(&mut self, tails: &mut [Executor]) {
        let starts: Vec<Seed> = self
            .leaders
            .iter()
            .filter(|b| !self.settled.contains(&b.seed.q))
            .map(|b| b.seed.clone())
            .collect();
        for seed in &starts {
            if !self.repair_from(seed, tails) {
                return;
            }
            self.settled.push(seed.q);
        }
    }

    /// Rounds of detours from `seed`'s leader; false once the budget is spent.
    fn repair_from(&mut self, seed: &Seed, tails: &mut [Executor]) -> bool {
        let directions = null_actions(4);
        loop {
            // A start that has fallen out of the leaders is not repaired further.
            let Some(base) = self.leader_of(seed).cloned() else {
                return true;
            };
            for (at, episode) in self.branch_points(&base) {
                for action in &directions {
                    for tail in tails.iter_mut() {
                        if self.done() {
                            return false;
                        }
                        let detour = Detour {
                            action: *action,
                            steps: self.context.config.detour_steps,
                        };
                        let prefix = &base.issued[..at];
                        let lead = Some(Lead::Detour(detour));
                        self.try_branch(&base.seed, episode.clone(), prefix, lead, tail);
                    }
                }
            }
            let improved = self
                .leader_of(seed)
                .is_some_and(|b| b.trajectory.path_length_m > base.trajectory.path_length_m);
            if !improved {
                return true;
            }
        }
    }
}

impl<'a> Search<'a> {
    /// `base` replayed from its start (its own actions, so its states recur exactly), as
    /// snapshots at [`BACKTRACK_STEPS`] steps before where it stopped, nearest the end first,
    /// each with the number of actions taken to reach it; the replay is charged to the budget.
    fn branch_points(&mut self, base: &Best) -> Vec<(usize, Episode<'a>)> {
        let context = self.context;
        let issued = base.issued.len();
        let wanted: Vec<usize> = BACKTRACK_STEPS
            .into_iter()
            .filter(|&back| back <= issued)
            .map(|back| issued - back)
            .collect();
        let mut episode = Episode::start(context.robot, self.task, &base.seed.q, context.rollout);
        let mut points = Vec::new();
        for (at, (action, acting)) in base.issued.iter().enumerate() {
            if wanted.contains(&at) {
                points.push((at, episode.clone()));
            }
            if at + 1 >= issued {
                break;
            }
            if episode.is_finished() {
                break;
            }
            episode.apply(action, *acting);
            self.spent += 1;
        }
        points.reverse();
        points
    }
}

/// How far back from where the longest rollout stopped its detours start (steps).
const BACKTRACK_STEPS: [usize; 6] = [1, 2, 4, 8, 16, 32];

/// The searched plan of `task`: its start and its rollout. The pipeline's own plan (`seed`
/// rolled out by `finalist`, the requested controller) is always evaluated first, so the
/// search never returns less; then a pass at the configured breadth ([`Search::pass`]) while
/// budget is left and no rollout has come within [`SearchConfig::stop_within_m`] of the first
/// grid point the scan missed. Where the longest rollout then ends below [`SHORTFALL_SHARE`] ×
/// the bound, the budget grows by [`SearchConfig::widened_budget_steps`] and a wider pass
/// ([`SearchConfig::widened_breadth`]) goes on from there.
pub(crate) fn search(
    context: &SearchContext<'_>,
    task: &Task,
    seed: Seed,
    finalist: Executor,
    reach: &Reach,
) -> (Seed, Trajectory) {
    let config = context.config;
    let ranking = Executor::Classical(ClassicalController::new(config.classical_gains.clone()));
    let mut tails = [finalist, ranking];
    // On a path, a rollout that reaches its end leaves nothing to find.
    let past_scan_m = (reach.scanned_m + reach.grid_m).min(
        task.length_m()
            .map_or(f64::INFINITY, |length| length - ARRIVAL_M),
    );
    let enough_m = past_scan_m - config.stop_within_m;
    let mut search = Search::new(context, task, config.budget_steps, enough_m);
    search.try_start(&seed, &mut tails[0]);
    // Computed once for both passes (none needed once a rollout has arrived).
    let chains = if search.arrived() {
        Vec::new()
    } else {
        witness_chains(
            context.robot,
            task,
            &context.rollout.constraints,
            context.reach,
            reach,
            config.chain_jump_rad,
        )
    };
    let first = Breadth::of(config, 1);
    search.pass(reach, &chains, 0, first, &mut tails);
    // Whether the longest rollout still ends below `share` × the bound.
    let short_of = |search: &Search, share: f64| search.longest_m() < share * reach.reachable_m;
    if config.widened_budget_steps > 0 && short_of(&search, SHORTFALL_SHARE) && !search.arrived() {
        search.budget += config.widened_budget_steps;
        let wide = Breadth::of(config, config.widened_breadth);
        search.pass(reach, &chains, first.chains, wide, &mut tails);
    }
    if !config.far_end_shares.is_empty() && short_of(&search, SHORTFALL_SHARE) && !search.arrived()
    {
        search.far_end(reach, &mut tails);
    }
    if config.beam_width > 0 && short_of(&search, config.beam_below_share) && !search.arrived() {
        search.beam();
    }
    let best = search.leaders.swap_remove(0);
    (best.seed, best.trajectory)
}

impl Search<'_> {
    /// One pass of the search at `breadth`: the scan's `chains` from `first_chain` up to
    /// `breadth.chains` followed from `p0` ([`Search::track`]); then the candidate starts not
    /// rolled out yet ranked by rollouts of the search's classical controller, the best
    /// [`SearchConfig::finalists`] rolled out by the requested controller, and the longest
    /// rollouts of the best starts repaired by detours near their ends; each stage only while
    /// the search is not done.
    fn pass(
        &mut self,
        reach: &Reach,
        chains: &[Vec<JointVector>],
        first_chain: usize,
        breadth: Breadth,
        tails: &mut [Executor; 2],
    ) {
        let context = self.context;
        for chain in chains.iter().take(breadth.chains).skip(first_chain) {
            if let Some(reference) = Reference::along_grid(chain, reach.grid_m) {
                self.track(chain[0], &reference, CHAIN_SOURCE, tails);
            }
        }
        let candidates = if self.done() {
            Vec::new()
        } else {
            candidates(context, self.task, &self.tried, breadth)
        };
        let mut ranked: Vec<(usize, f64)> = Vec::new();
        for (index, candidate) in candidates.iter().enumerate() {
            if self.done() {
                break;
            }
            let length = self.try_start(&candidate.seed(), &mut tails[1]);
            ranked.push((index, length));
        }
        // Longest first; equal lengths keep the candidates' order.
        ranked.sort_by(|a, b| b.1.total_cmp(&a.1));
        for &(index, _) in ranked.iter().take(context.config.finalists) {
            if self.done() {
                break;
            }
            self.try_start(&candidates[index].seed(), &mut tails[0]);
        }
        self.repair(tails);
    }

    /// The beam stage (`crate::beam`) from the leaders' starts and every start rolled out,
    /// its motion offered like any rollout. It runs last: its motion keeps no actions to
    /// replay, so no repair may follow it.
    fn beam(&mut self) {
        let context = self.context;
        let mut starts: Vec<Seed> = self.leaders.iter().map(|b| b.seed.clone()).collect();
        for seed in &self.tried {
            if starts.iter().all(|s| s.q != seed.q) {
                starts.push(seed.clone());
            }
        }
        let configurations: Vec<JointVector> = starts.iter().map(|s| s.q).collect();
        let mut controller = ClassicalController::new(context.config.classical_gains.clone());
        let limits = BeamLimits {
            width: context.config.beam_width,
            budget_steps: context.config.beam_budget_steps,
            enough_m: self.enough_m,
        };
        let (plan, spent) = beam_search(
            context.robot,
            self.task,
            context.rollout,
            &configurations,
            &mut controller,
            limits,
            context.stop,
        );
        self.spent += spent;
        if let Some(plan) = plan {
            self.offer(Best {
                seed: starts[plan.start].clone(),
                trajectory: plan.trajectory,
                issued: Vec::new(),
            });
        }
    }

    /// The far-end stage: the line asked from its far side. First, from each share of the
    /// scan's grid points ([`SearchConfig::far_end_shares`]) beyond the longest rollout, the
    /// search's first pass plans the motion back to `p0` ([`Search::searched_back`]); then,
    /// from the points beyond the longest rollout that gap-eval asks from
    /// (`crate::far_end::probe_starts`), the whole planner does (`Planner::motion_back`).
    /// Each motion back that gets past `p0`, read forwards, is a motion from `p0` to where it
    /// started ([`Search::take_motion_back`]). While the probes take the longest rollout
    /// further, the line beyond its new end is asked in turn: the stage ends where no motion
    /// back from gap-eval's points beyond the plan's end passes `p0`.
    fn far_end(&mut self, reach: &Reach, tails: &mut [Executor; 2]) {
        let context = self.context;
        // From the shares, the search's first pass alone on the scan read backwards: no
        // widened pass, beam or far end.
        let first_pass = SearchConfig {
            widened_budget_steps: 0,
            beam_width: 0,
            far_end_shares: Vec::new(),
            ..context.config.clone()
        };
        for &share in &context.config.far_end_shares {
            let far = ((reach.witnesses.len().saturating_sub(1)) as f64 * share) as usize;
            let s_far_m = far as f64 * reach.grid_m;
            if s_far_m <= self.longest_m() {
                continue;
            }
            if let Some(back) = self.searched_back(reach, far, &first_pass, &tails[0]) {
                self.take_motion_back(&back, s_far_m, tails);
            }
        }
        // From gap-eval's points, the whole planner's motion back, asked again beyond each new
        // end.
        let mut asked: Vec<f64> = Vec::new();
        loop {
            let end_m = self.longest_m();
            for from_m in probe_starts(end_m, reach) {
                if asked.contains(&from_m) {
                    continue;
                }
                if (context.stop)() || self.arrived() {
                    return;
                }
                asked.push(from_m);
                if let Some(back) = (context.motion_back)(self.task, from_m) {
                    self.take_motion_back(&back, from_m, tails);
                }
            }
            if self.longest_m() <= end_m {
                return;
            }
        }
    }

    /// `back`, a motion planned back from `s_far_m` along the line, where it gets back past
    /// `p0`: offered read forwards ([`Search::offer_read_forwards`]) and followed from `p0`
    /// ([`Search::track`]), with a budget of [`SearchConfig::budget_steps`] for its rollouts.
    fn take_motion_back(&mut self, back: &Trajectory, s_far_m: f64, tails: &mut [Executor; 2]) {
        if back.path_length_m < s_far_m {
            return;
        }
        self.budget = self.budget.max(self.spent) + self.context.config.budget_steps;
        self.offer_read_forwards(back, s_far_m, tails);
        if let Some((start, reference)) = self.forward_start(back, s_far_m) {
            self.track(start, &reference, FAR_END_SOURCE, tails);
        }
    }

    /// The motion the search's first pass (`config`, `finalist` its requested controller)
    /// plans on the reversed task from the scan's grid point `far` back to `p0`, the scan read
    /// backwards its scan and its configuration there its first start (`crate::far_end`).
    fn searched_back(
        &self,
        reach: &Reach,
        far: usize,
        config: &SearchConfig,
        finalist: &Executor,
    ) -> Option<Trajectory> {
        let context = self.context;
        let s_far_m = far as f64 * reach.grid_m;
        let task = reversed_task(context.robot, self.task, s_far_m)?;
        let scan = reversed_reach(reach, far)?;
        let mut rollout = context.rollout.clone();
        rollout.constraints.work_surface =
            reversed_surface(&rollout.constraints.work_surface, s_far_m);
        let backward_context = SearchContext {
            rollout: &rollout,
            config,
            ..*context
        };
        let seed = Seed {
            q: scan.witnesses[0],
            source: FAR_END_SOURCE,
            projection_iterations: None,
        };
        let (_, back) = search(&backward_context, &task, seed, finalist.clone(), &scan);
        Some(back)
    }

    /// `back`, a motion planned back from `s_far_m` past `p0`, read forwards
    /// (`crate::far_end::read_forwards`) and each tail going on from where it started: offered
    /// like any rollout, its actions not kept (nothing replays it).
    fn offer_read_forwards(&mut self, back: &Trajectory, s_far_m: f64, tails: &mut [Executor; 2]) {
        let context = self.context;
        let Some((seed, prefix)) =
            read_forwards(context.robot, self.task, back, s_far_m, context.rollout)
        else {
            return;
        };
        let seed = Seed {
            q: seed,
            source: FAR_END_SOURCE,
            projection_iterations: None,
        };
        // The motion goes on from the configuration the motion back started at, a step after
        // the last one read forwards, as long as one rollout may.
        let step_s = back.steps[1].time_s - back.steps[0].time_s;
        let onward_from_s = prefix.last().map_or(0.0, |step| step.time_s) + step_s;
        let mut rollout = context.rollout.clone();
        rollout.max_steps = rollout.max_steps.saturating_sub(prefix.len()).max(1);
        for tail in tails.iter_mut() {
            if self.done() {
                return;
            }
            let episode = Episode::start(context.robot, self.task, &back.steps[0].q, &rollout);
            let mut branch = Branch {
                lead: None,
                tail,
                issued: Vec::new(),
            };
            let onward = continue_rollout(episode, &mut branch);
            self.spent += steps_evaluated(&onward);
            let mut steps = prefix.clone();
            steps.extend(onward.steps.into_iter().map(|step| StepRecord {
                time_s: onward_from_s + step.time_s,
                ..step
            }));
            self.offer(Best {
                seed: seed.clone(),
                trajectory: Trajectory { steps, ..onward },
                issued: Vec::new(),
            });
        }
    }

    /// The reference `back`, a motion planned back from `s_far_m` past `p0`, gives read
    /// forwards (`crate::far_end::forward_reference`), and its configuration at `p0` put on
    /// `p0` with its own tool axis; `None` where it does not get back to `p0`.
    fn forward_start(&self, back: &Trajectory, s_far_m: f64) -> Option<(JointVector, Reference)> {
        let robot = self.context.robot;
        let reference = forward_reference(self.task, back, s_far_m)?;
        let at_p0 = reference.at(0.0)?;
        let target = PoseTarget {
            position: self.task.p0,
            tool_axis: robot.forward(&at_p0).tool_axis(),
            roll_axis: None,
        };
        let (start, _) =
            project_to_pose(robot, &at_p0, &target, &ProjectionConfig::default()).ok()?;
        Some((start, reference))
    }

    /// Follows `reference` from `q`, a configuration on `p0`, with each tail taking over where
    /// it ends; the rollouts' start is named `source`.
    fn track(
        &mut self,
        q: JointVector,
        reference: &Reference,
        source: &'static str,
        tails: &mut [Executor],
    ) {
        let context = self.context;
        let kinematics = context.robot.forward(&q);
        if first_violation(
            context.robot,
            self.task,
            &kinematics,
            &context.rollout.constraints,
        )
        .is_some()
        {
            return;
        }
        let seed = Seed {
            q,
            source,
            projection_iterations: None,
        };
        for tail in tails.iter_mut() {
            if self.done() {
                return;
            }
            let episode = Episode::start(context.robot, self.task, &q, context.rollout);
            self.try_branch(&seed, episode, &[], Some(Lead::Track(reference)), tail);
        }
    }
}

/// The task's start pose: the TCP on `p0`, the tool axis along `n`.
fn start_pose(task: &Task) -> PoseTarget {
    PoseTarget {
        position: task.p0,
        tool_axis: task.n,
        roll_axis: None,
    }
}

impl Candidate {
    fn seed(&self) -> Seed {
        Seed {
            q: self.q,
            source: self.source,
            projection_iterations: None,
        }
    }
}

/// The distinct valid starts on the start pose other than `tried` (the seeds already rolled
/// out), drawn at `breadth`, in the fixed order of the module documentation.
fn candidates(
    context: &SearchContext<'_>,
    task: &Task,
    tried: &[Seed],
    breadth: Breadth,
) -> Vec<Candidate> {
    let robot = context.robot;
    let constraints = &context.rollout.constraints;
    let distinct_rad = context.config.distinct_rad;
    let mut found: Vec<Candidate> = Vec::new();
    let mut offer = |q: JointVector, source: &'static str| {
        let kinematics = robot.forward(&q);
        let valid = first_violation(robot, task, &kinematics, constraints).is_none();
        let distinct = tried.iter().all(|t| (t.q - q).amax() >= distinct_rad)
            && found.iter().all(|c| (c.q - q).amax() >= distinct_rad);
        if valid && distinct {
            found.push(Candidate { q, source });
        }
    };
    let projection = ProjectionConfig::default();
    let target = start_pose(task);
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
        && breadth.dp_samples > 0
        && let Ok(samples) = seeder.candidates(
            robot,
            task,
            breadth.dp_samples,
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
        restarts: breadth.ik_restarts,
        ..IkConfig::default()
    };
    let mut rng = ChaCha8Rng::seed_from_u64(context.config.seed);
    for q in cone_ik_solutions(robot, &task.p0, &task.n, &ik, &mut rng) {
        offer(q, "ik");
    }
    found
}
