//! Planning one task: seed it, build the requested controller and run the shared rollout.

use anyhow::{Context, Result};
use emg_control::{ClassicalController, NullSpaceController, Task, Trajectory, rollout};
use emg_diffusion::DpSeeder;
use emg_kinematics::Robot;
use emg_policy::{PlainPolicy, RlController};

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

/// The controller named on the command line, configured from `settings` (`policy`: the loaded
/// weights of `rl`).
pub fn controller(
    kind: ControllerKind,
    settings: &Settings,
    policy: Option<&PlainPolicy>,
) -> Result<Box<dyn NullSpaceController>> {
    Ok(match kind {
        ControllerKind::Classical => Box::new(ClassicalController::new(settings.gains.clone())),
        ControllerKind::Rl => Box::new(RlController::from_policy(
            policy
                .context("--controller rl needs policy weights")?
                .clone(),
        )),
    })
}

/// Seeds `task` and rolls out a fresh controller of `kind` from that seed.
pub fn plan_task(
    robot: &Robot,
    task: &Task,
    seed: Option<&SeedRequest>,
    dp: Option<&DpSeeder>,
    kind: ControllerKind,
    policy: Option<&PlainPolicy>,
    settings: &Settings,
) -> Result<Plan> {
    let seed = prepare_seed(robot, task, seed, &settings.rollout.constraints, dp)?;
    let mut controller = controller(kind, settings, policy)?;
    let trajectory = rollout(robot, task, &seed.q, controller.as_mut(), &settings.rollout);
    Ok(Plan { seed, trajectory })
}
