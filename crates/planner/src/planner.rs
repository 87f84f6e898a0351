//! The planner: a robot, its models and one configuration; plans a task or many.

use emg_control::{Task, Trajectory, rollout};
use emg_kinematics::Robot;
use rayon::prelude::*;

use crate::config::{ConfigError, PlannerConfig};
use crate::controller::{ControllerKind, Executor, ExecutorError};
use crate::models::Models;
use crate::seed::{Seed, SeedError, SeedSource, prepare_seed};

/// What to plan with: the seed source (`None` picks `dp` when the seeder is loaded, else
/// `generating` when the task has a `q0_seed`, else `home`) and the controller.
#[derive(Clone, Debug, PartialEq)]
pub struct PlanRequest {
    /// Seed source; `None` chooses as described above.
    pub seed: Option<SeedSource>,
    /// The null-space controller that rolls out from the seed.
    pub controller: ControllerKind,
}

impl Default for PlanRequest {
    /// The paper's full pipeline: the DP seed (when loaded) and the hybrid controller.
    fn default() -> Self {
        Self {
            seed: None,
            controller: ControllerKind::Hybrid,
        }
    }
}

/// A planned task: the seed it started from and the rollout.
#[derive(Clone, Debug, PartialEq)]
pub struct Plan {
    /// The seed actually used (after projection).
    pub seed: Seed,
    /// The rollout from that seed; every step holds every constraint.
    pub trajectory: Trajectory,
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
    /// from that seed through the shared rollout loop.
    pub fn plan(&self, task: &Task, request: &PlanRequest) -> Result<Plan, PlanError> {
        let mut controller = Executor::new(
            request.controller,
            self.models.policy.as_ref(),
            &self.config.executor(),
        )?;
        let seed = prepare_seed(
            &self.robot,
            task,
            request.seed.as_ref(),
            &self.config.rollout.constraints,
            self.models.seeder.as_ref(),
        )?;
        let trajectory = rollout(
            &self.robot,
            task,
            &seed.q,
            &mut controller,
            &self.config.rollout,
        );
        Ok(Plan { seed, trajectory })
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
