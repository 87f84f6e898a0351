//! The planner: a robot, its models and one configuration; plans a task or many.

use emg_control::{Task, Trajectory, rollout};
use emg_kinematics::{JointVector, Robot};
use rayon::prelude::*;
use serde::{Deserialize, Serialize};

use crate::config::{ConfigError, PlannerConfig};
use crate::controller::{ControllerKind, Executor, ExecutorError};
use crate::far_end::{reversed_surface, reversed_task};
use crate::models::Models;
use crate::parse::ParseError;
use crate::reach::{
    BoundNote, Reach, SHORTFALL_SHARE, StartBlockers, far_end_chains, reach, shortfall,
    start_blockers,
};
use crate::search::{SearchContext, search};
use crate::seed::{SCAN_SOURCE, Seed, SeedError, SeedSource, prepare_seed};

/// What to plan with: the planner, the seed source (`None` picks `dp` when the seeder is
/// loaded, else `generating` when the task has a `q0_seed`, else `home`) and the controller.
#[derive(Clone, Debug, PartialEq)]
pub struct PlanRequest {
    /// How the plan is made.
    pub planner: PlannerKind,
    /// Seed source; `None` chooses as described above. The search planner tries a requested
    /// seed first among its candidates.
    pub seed: Option<SeedSource>,
    /// The null-space controller that rolls out from the seed (the search's finalists).
    pub controller: ControllerKind,
}

impl Default for PlanRequest {
    /// What `emg plan` and Python run: the search ([`PlannerKind::Search`]) from the default
    /// seed, with the hybrid controller.
    fn default() -> Self {
        Self {
            planner: PlannerKind::Search,
            ..Self::pipeline()
        }
    }
}

impl PlanRequest {
    /// The paper's full pipeline: one DP seed (when loaded) and one rollout of the hybrid
    /// controller.
    pub fn pipeline() -> Self {
        Self {
            planner: PlannerKind::Controller,
            seed: None,
            controller: ControllerKind::Hybrid,
        }
    }
}

/// How a plan is made.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum PlannerKind {
    /// The paper's pipeline: one seed, one rollout of the controller (Sec. 4).
    #[default]
    Controller,
    /// Many starts ranked by rollouts within a step budget (`crate::search`).
    Search,
}

impl PlannerKind {
    /// Both planners.
    pub const ALL: [PlannerKind; 2] = [Self::Controller, Self::Search];

    /// Lower-case name used in files and command lines.
    pub fn name(self) -> &'static str {
        match self {
            Self::Controller => "controller",
            Self::Search => "search",
        }
    }
}

impl std::fmt::Display for PlannerKind {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.name())
    }
}

impl std::str::FromStr for PlannerKind {
    type Err = ParseError;

    fn from_str(value: &str) -> Result<Self, Self::Err> {
        Self::ALL
            .into_iter()
            .find(|kind| kind.name() == value)
            .ok_or_else(|| ParseError::Planner(value.to_string()))
    }
}

/// Random IK restarts of the continuity test a short plan's note reports
/// ([`Planner::bound_note`]).
pub const CONTINUITY_RESTARTS: usize = 32;

/// A planned task: the seed it started from and the rollout.
#[derive(Clone, Debug, PartialEq)]
pub struct Plan {
    /// The seed actually used (after projection).
    pub seed: Seed,
    /// The rollout from that seed; every step holds every constraint.
    pub trajectory: Trajectory,
    /// The task's reachability bound, witnessed by the plan, when the planner computed it (the
    /// search does, to guide and end its search); else [`Planner::reach_of`] computes it.
    pub reach: Option<Reach>,
}

/// Why a task could not be planned.
#[derive(Debug, thiserror::Error)]
pub enum PlanError {
    /// No seed could be prepared.
    #[error(transparent)]
    Seed(#[from] SeedError),
    /// The controller cannot be built (a learned controller without a policy, bad switch
    /// thresholds).
    #[error(transparent)]
    Controller(#[from] ExecutorError),
}

/// Plans extreme straight-line motions for one robot with its models and configuration.
pub struct Planner {
    robot: Robot,
    models: Models,
    config: PlannerConfig,
}

impl Planner {
    /// A planner for `robot` with `models` under `config` (validated: the error names the
    /// field, the value and its allowed range).
    pub fn new(robot: Robot, models: Models, config: PlannerConfig) -> Result<Self, ConfigError> {
        config.validate()?;
        Ok(Self {
            robot,
            models,
            config,
        })
    }

    /// The same robot and models under another `config` (validated as in [`Planner::new`]).
    pub fn with_config(&self, config: PlannerConfig) -> Result<Self, ConfigError> {
        Self::new(self.robot.clone(), self.models.clone(), config)
    }

    /// The same planner with the robot's joints kept within `half_width_rad` of `reference`
    /// where their limits span more than a turn ([`Robot::within`]). `None` where no joint's
    /// limits span more than a turn (nothing would change).
    pub fn within(&self, reference: &JointVector, half_width_rad: f64) -> Option<Self> {
        let robot = self.robot.within(reference, half_width_rad);
        (robot.limits() != self.robot.limits()).then(|| Self {
            robot,
            models: self.models.clone(),
            config: self.config.clone(),
        })
    }

    /// The robot.
    pub fn robot(&self) -> &Robot {
        &self.robot
    }

    /// The loaded models.
    pub fn models(&self) -> &Models {
        &self.models
    }

    /// The configuration every plan uses.
    pub fn config(&self) -> &PlannerConfig {
        &self.config
    }

    /// Seeds `task` as `request` asks and rolls out a fresh controller of `request.controller`
    /// from that seed through the shared rollout loop; for [`PlannerKind::Search`], that
    /// rollout comes first and many other starts are tried within the configured step budget.
    pub fn plan(&self, task: &Task, request: &PlanRequest) -> Result<Plan, PlanError> {
        self.plan_until(task, request, &|| false)
    }

    /// [`Planner::plan`], with the search ending early once `stop` returns true (asked between
    /// its rollouts): what it returns then is the longest rollout found so far, for a caller
    /// that has stopped wanting the plan to discard.
    pub fn plan_until(
        &self,
        task: &Task,
        request: &PlanRequest,
        stop: &(dyn Fn() -> bool + Sync),
    ) -> Result<Plan, PlanError> {
        let executor = self.config.executor();
        let mut controller =
            Executor::new(request.controller, self.models.policy.as_ref(), &executor)?;
        if request.planner == PlannerKind::Search {
            // A seed that cannot be put on the start pose leaves the search its other starts,
            // from the scan's configuration at p0.
            let (seed, mut reach) = match self.seed(task, request) {
                Ok(seed) => {
                    let reach = self.reach(task, &[seed.q]);
                    (seed, reach)
                }
                Err(error @ SeedError::Projection { .. }) => {
                    let reach = self.reach(task, &[]);
                    let q = *reach.witnesses.first().ok_or(error)?;
                    let seed = Seed {
                        q,
                        source: SCAN_SOURCE,
                        projection_iterations: None,
                    };
                    (seed, reach)
                }
                Err(error) => return Err(error.into()),
            };
            let motion_back = |task: &Task, from_m: f64| self.motion_back(task, from_m);
            let context = SearchContext {
                motion_back: &motion_back,
                robot: &self.robot,
                rollout: &self.config.rollout,
                reach: &self.config.reach,
                seeder: self.models.seeder.as_ref(),
                config: &self.config.search,
                stop,
            };
            let (seed, trajectory) = search(&context, task, seed, controller, &reach);
            reach.witness(&trajectory);
            return Ok(Plan {
                seed,
                trajectory,
                reach: Some(reach),
            });
        }
        let seed = self.seed(task, request)?;
        let trajectory = rollout(
            &self.robot,
            task,
            &seed.q,
            &mut controller,
            &self.config.rollout,
        );
        Ok(Plan {
            seed,
            trajectory,
            reach: None,
        })
    }

    /// The motion this planner plans back from `from_m` along `task`'s line: the whole planner
    /// (its seed, its scan, its search) on the reversed task, its work surface seen from there,
    /// its own far-end stage left out (a motion back does not ask for motions back in turn).
    /// `None` on a path task, where the point lies out of reach, or where no motion starts there.
    pub(crate) fn motion_back(&self, task: &Task, from_m: f64) -> Option<Trajectory> {
        let reversed = reversed_task(self.robot(), task, from_m)?;
        let mut config = self.config().clone();
        config.rollout.constraints.work_surface =
            reversed_surface(&config.rollout.constraints.work_surface, from_m);
        config.search.far_end_shares.clear();
        let backward = self.with_config(config).ok()?;
        let plan = backward.plan(&reversed, &PlanRequest::default()).ok()?;
        (plan.trajectory.steps.len() >= 2).then_some(plan.trajectory)
    }

    /// The reachability bound of `task` witnessed by `plan`: the plan's own when it holds one,
    /// else [`Planner::reach`] from the plan's seed, raised to the plan's length.
    pub fn reach_of(&self, task: &Task, plan: &Plan) -> Reach {
        plan.reach.clone().unwrap_or_else(|| {
            let mut reach = self.reach(task, &[plan.seed.q]);
            reach.witness(&plan.trajectory);
            reach
        })
    }

    /// The seed `request` names for `task` ([`prepare_seed`]).
    fn seed(&self, task: &Task, request: &PlanRequest) -> Result<Seed, SeedError> {
        prepare_seed(
            &self.robot,
            task,
            request.seed.as_ref(),
            &self.config.rollout.constraints,
            self.models.seeder.as_ref(),
        )
    }

    /// The reachability bound of `task` under the configured constraints ([`reach`]), with the
    /// task's `q0_seed` and `hints` (e.g. a plan's seed) as warm starts at `p0`.
    pub fn reach(&self, task: &Task, hints: &[JointVector]) -> Reach {
        let mut starts: Vec<JointVector> = hints.to_vec();
        starts.extend(task.q0_seed);
        reach(
            &self.robot,
            task,
            &self.config.rollout.constraints,
            &self.config.reach,
            &starts,
        )
    }

    /// What keeps every configuration at `task`'s start from holding the configured
    /// constraints ([`start_blockers`]): said when a task is refused at its start.
    pub fn start_blockers(&self, task: &Task) -> StartBlockers {
        start_blockers(
            &self.robot,
            task,
            &self.config.rollout.constraints,
            &self.config.reach,
        )
    }

    /// What `plan`'s output says of `task`'s bound: [`Planner::reach_of`], and when the plan
    /// ends below [`SHORTFALL_SHARE`] of it, why ([`shortfall`], with the bound's continuity
    /// test [`far_end_chains`] from [`CONTINUITY_RESTARTS`] restarts).
    pub fn bound_note(&self, task: &Task, plan: &Plan) -> BoundNote {
        let reach = self.reach_of(task, plan);
        let trajectory = &plan.trajectory;
        let joined = (trajectory.path_length_m < SHORTFALL_SHARE * reach.reachable_m).then(|| {
            !far_end_chains(
                &self.robot,
                task,
                &self.config.rollout.constraints,
                &self.config.reach,
                &reach,
                self.config.search.chain_jump_rad,
                CONTINUITY_RESTARTS,
            )
            .is_empty()
        });
        BoundNote {
            reachable_m: reach.reachable_m,
            shortfall: joined.map(|joined| shortfall(trajectory, reach.reachable_m, joined)),
            likely_loose: joined == Some(false),
        }
    }

    /// [`Planner::plan`] of every task, in parallel on the current rayon pool; the results come
    /// in task order and do not depend on the number of threads (every plan is a pure function
    /// of its task).
    pub fn plan_many(&self, tasks: &[Task], request: &PlanRequest) -> Vec<Result<Plan, PlanError>> {
        tasks
            .par_iter()
            .map(|task| self.plan(task, request))
            .collect()
    }
}
