//! Choosing the rollout's seed and putting it exactly on the task's start pose.

use anyhow::{Context, Result, bail};
use emg_control::{ConstraintConfig, SEED_POSITION_TOLERANCE_M, Task, tool_angle_deg};
use emg_diffusion::{DpSeedError, DpSeeder, SeedOrigin, SeedWorkspace};
use emg_kinematics::{JointVector, PoseTarget, ProjectionConfig, Robot, project_to_pose};

use crate::args::SeedRequest;

/// A seed ready for the rollout.
#[derive(Clone, Debug)]
pub struct Seed {
    /// The configuration the rollout starts from.
    pub q: JointVector,
    /// `dp`, `generating`, `home` or `given`.
    pub source: &'static str,
    /// Newton iterations spent projecting it onto `(p0, n)`; `None` when it was already there.
    pub projection_iterations: Option<usize>,
}

/// Picks the seed named by `request` (default: `dp` when a diffusion seeder is loaded, else
/// `generating` when the task has a `q0_seed`, else `home`) and, unless it already puts the TCP
/// at `p0` with the tool axis within `theta_max_deg` of `n` and every joint within its limits,
/// Newton-projects it onto the exact pose `(p0, n)`. The DP seed falls back to `q0_seed`
/// (reported as `generating`); by default, a task without one then falls back to `home`.
pub fn prepare_seed(
    robot: &Robot,
    task: &Task,
    request: Option<&SeedRequest>,
    constraints: &ConstraintConfig,
    dp: Option<&DpSeeder>,
) -> Result<Seed> {
    let theta_max_deg = constraints.theta_max_deg;
    let wants_dp = matches!(request, Some(SeedRequest::Dp)) || (request.is_none() && dp.is_some());
    if wants_dp {
        let seeder = dp.context("--seed dp: no diffusion weights loaded (see --weights)")?;
        match seeder.seed(robot, task, constraints, &mut SeedWorkspace::default()) {
            Ok(seed) => {
                let source = match seed.origin {
                    SeedOrigin::Diffusion => "dp",
                    SeedOrigin::Fallback => "generating",
                };
                return Ok(Seed {
                    q: seed.q,
                    source,
                    projection_iterations: None,
                });
            }
            Err(DpSeedError::NoValidSeed { .. }) if request.is_none() => {}
            Err(error) => return Err(error).context("--seed dp"),
        }
    }
    let (q, source) = match request {
        Some(SeedRequest::Dp) => unreachable!("handled above"),
        Some(SeedRequest::Generating) => match task.q0_seed {
            Some(q) => (q, "generating"),
            None => bail!(
                "--seed generating: this task has no generating configuration (q0_seed); \
                 use --seed home or --seed q=v1,...,v7"
            ),
        },
        Some(SeedRequest::Home) => (robot.mid_range(), "home"),
        Some(SeedRequest::Given(q)) => (*q, "given"),
        None => match task.q0_seed {
            Some(q) => (q, "generating"),
            None => (robot.mid_range(), "home"),
        },
    };
    if on_start_pose(robot, task, &q, theta_max_deg) {
        return Ok(Seed {
            q,
            source,
            projection_iterations: None,
        });
    }
    let target = PoseTarget {
        position: task.p0,
        tool_axis: task.n,
        roll_axis: None,
    };
    let (q, iterations) = project_to_pose(robot, &q, &target, &ProjectionConfig::default())
        .with_context(|| {
            format!("cannot project the {source} seed onto the task's start pose (p0, n)")
        })?;
    Ok(Seed {
        q,
        source,
        projection_iterations: Some(iterations),
    })
}

/// Whether `q` is within the joint limits, puts the TCP at `p0` and the tool axis in the cone.
fn on_start_pose(robot: &Robot, task: &Task, q: &JointVector, theta_max_deg: f64) -> bool {
    let kinematics = robot.forward(q);
    robot.limits().first_violation(q, 0.0).is_none()
        && (kinematics.tcp() - task.p0).norm() <= SEED_POSITION_TOLERANCE_M
        && tool_angle_deg(&kinematics.tool_axis(), &task.n) <= theta_max_deg
}
