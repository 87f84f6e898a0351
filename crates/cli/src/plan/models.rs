//! The learned models `emg plan` loads: the null-space controller it runs, and the diffusion
//! seeder's and the policy's weights files.

use std::path::{Path, PathBuf};

use anyhow::Result;
use emg_planner::{ControllerKind, SeedSource};

/// The controller: `explicit` (`--controller`), else hybrid when a policy is trained for the
/// robot (`policy`: given with --policy or shipped), else classical.
pub fn controller(explicit: Option<ControllerKind>, policy: Option<&Path>) -> ControllerKind {
    explicit.unwrap_or_else(|| {
        if policy.is_some_and(Path::exists) {
            ControllerKind::Hybrid
        } else {
            ControllerKind::Classical
        }
    })
}

/// The diffusion weights to load: `weights` (`--weights`, or the robot's shipped ones) when the
/// seed may be `dp` and they exist; `--seed dp` without any is an error. `robot_file` names the
/// robot in it.
pub fn diffusion_weights(
    seed: Option<&SeedSource>,
    weights: Option<PathBuf>,
    robot_file: &Path,
) -> Result<Option<PathBuf>> {
    let explicit = matches!(seed, Some(SeedSource::Dp));
    match weights {
        Some(path) if explicit || (seed.is_none() && path.exists()) => Ok(Some(path)),
        None if explicit => anyhow::bail!(
            "--seed dp: no diffusion weights are shipped for robot {0}; pass --weights, or train \
             them with `cargo xtask make-tasks --robot {0}`, `cargo xtask label-seeds --robot {0}` \
             and `cargo xtask train-diffusion --robot {0}`",
            robot_file.display()
        ),
        _ => Ok(None),
    }
}

/// The policy weights of `--controller rl` and `hybrid`: `policy` (`--policy`, else the robot's
/// shipped ones); none for a controller that needs none. `robot_file` names the robot in the
/// error.
pub fn policy_weights(
    controller: ControllerKind,
    policy: Option<PathBuf>,
    robot_file: &Path,
) -> Result<Option<PathBuf>> {
    if !controller.needs_policy() {
        return Ok(None);
    }
    match policy {
        Some(path) => Ok(Some(path)),
        None => anyhow::bail!(
            "--controller {}: no policy is shipped for robot {1}; pass --policy, train one with \
             `cargo xtask make-tasks --robot {1}` and `cargo xtask train-ppo --robot {1}`, or use \
             --controller classical",
            controller,
            robot_file.display()
        ),
    }
}
