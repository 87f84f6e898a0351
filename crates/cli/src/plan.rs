//! Planning one task: seed it, build the requested controller and run the shared rollout.

use anyhow::Result;
use emg_control::{Task, Trajectory, rollout};
use emg_diffusion::DpSeeder;
use emg_hybrid::Executor;
use emg_kinematics::Robot;
use emg_policy::RlController;

use crate::args::{ControllerKind, SeedRequest};
use crate::seed::{Seed, prepare_seed};
use crate::settings::Settings;

/// A planned task: the seed it started from and the rollout.
#[derive(Debug)]
pub struct Plan {
    /// The seed actually used (after projection).
    pub seed: Seed,
    /// The rollout from that seed.
    pub trajectory: Trajectory,
}

/// Seeds `task` and rolls out a fresh controller of `kind` from that seed.
pub fn plan_task(
    robot: &Robot,
    task: &Task,
    seed: Option<&SeedRequest>,
    dp: Option<&DpSeeder>,
    kind: ControllerKind,
    policy: Option<&RlController>,
    settings: &Settings,
) -> Result<Plan> {
    let seed = prepare_seed(robot, task, seed, &settings.rollout.constraints, dp)?;
    let mut controller = Executor::new(kind.kind(), policy, &settings.executor())?;
    let trajectory = rollout(robot, task, &seed.q, &mut controller, &settings.rollout);
    Ok(Plan { seed, trajectory })
}
