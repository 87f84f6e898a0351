//! The heuristic seeds of the paper's Table 2: `q_μ` (directional-manipulability maximising) and
//! `q_jl` (joint-limit centring), by null-space gradient ascent from `q0_seed` with periodic
//! Newton re-projection onto the exact pose. Both stay on the branch of `q0_seed`.

use std::time::{Duration, Instant};

use emg_control::Task;
use emg_kinematics::{
    JointVector, PoseTarget, ProjectionConfig, ProjectionError, Robot, directional_manipulability,
    project_to_pose,
};
use serde::{Deserialize, Serialize};

use crate::config::HeuristicConfig;
use crate::tangent::self_motion_projector;

/// The objective a heuristic seed ascends.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum HeuristicObjective {
    /// `w_d`, the directional manipulability along `d` (SPEC §4): gives `q_μ`.
    Manipulability,
    /// `−mean q̄²`, joint-limit centring: gives `q_jl`.
    JointCentring,
}

/// A heuristic seed and what it cost.
#[derive(Clone, Debug, PartialEq)]
pub struct HeuristicSeed {
    /// The seed, on the exact pose `(p0, n)` within the limits (collision-free whenever the
    /// projected `q0_seed` is: every ascent block is checked).
    pub q: JointVector,
    /// Objective at the projected `q0_seed`.
    pub objective_start: f64,
    /// Objective at the seed (never below `objective_start`).
    pub objective_end: f64,
    /// Wall time to compute it.
    pub generation_time: Duration,
}

/// Why no heuristic seed exists for a task.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum HeuristicError {
    /// The task carries no `q0_seed` to start from.
    #[error("task field 'q0_seed' is missing; the heuristic seeds start from it")]
    MissingSeed,
    /// `q0_seed` could not be projected onto the exact pose.
    #[error("q0_seed could not be projected onto the exact pose: {0}")]
    Projection(#[from] ProjectionError),
}

impl HeuristicObjective {
    /// Objective value and gradient at `q`.
    pub fn evaluate(
        self,
        robot: &Robot,
        task: &Task,
        q: &JointVector,
        cfg: &HeuristicConfig,
    ) -> (f64, JointVector) {
        match self {
            Self::Manipulability => {
                let kin = robot.forward(q);
                directional_manipulability(
                    &kin,
                    &kin.jacobian_gram(),
                    &task.d,
                    cfg.manipulability_damping,
                )
            }
            Self::JointCentring => {
                let limits = robot.limits();
                let normalised = limits.normalise(q);
                let count = normalised.len() as f64;
                let value = -normalised.norm_squared() / count;
                let gradient = normalised
                    .component_div(&limits.half_range())
                    .map(|g| -2.0 * g / count);
                (value, gradient)
            }
        }
    }
}

/// Ascends `objective` in the tangent space of the exact pose `(p0, n)` from `q0_seed`: blocks of
/// `steps_per_block` projected-gradient steps, each block re-projected by Newton and accepted only
/// if it raises the objective and stays collision-free (else the step halves).
pub fn heuristic_seed(
    robot: &Robot,
    task: &Task,
    objective: HeuristicObjective,
    cfg: &HeuristicConfig,
    projection: &ProjectionConfig,
) -> Result<HeuristicSeed, HeuristicError> {
    let started = Instant::now();
    let seed = task.q0_seed.ok_or(HeuristicError::MissingSeed)?;
    let target = PoseTarget {
        position: task.p0,
        tool_axis: task.n,
        roll_axis: None,
    };
    let (mut q, _) = project_to_pose(robot, &seed, &target, projection)?;
    let (objective_start, _) = objective.evaluate(robot, task, &q, cfg);
    let mut value = objective_start;
    let mut step_rad = cfg.step_rad;
    let limits = robot.limits();
    for _ in 0..cfg.blocks {
        if step_rad < cfg.min_step_rad {
            break;
        }
        let mut trial = q;
        for _ in 0..cfg.steps_per_block {
            let (_, gradient) = objective.evaluate(robot, task, &trial, cfg);
            let ascent =
                self_motion_projector(robot, &trial, &target, cfg.projector_damping) * gradient;
            let largest = ascent.amax();
            if largest <= 0.0 {
                break;
            }
            trial += ascent * (step_rad / largest);
        }
        let accepted = project_to_pose(robot, &trial, &target, projection)
            .ok()
            .map(|(projected, _)| projected)
            .filter(|p| limits.first_violation(p, 0.0).is_none())
            .filter(|p| robot.first_collision(&robot.forward(p), 0.0).is_none())
            .map(|p| (p, objective.evaluate(robot, task, &p, cfg).0))
            .filter(|(_, v)| *v > value);
        match accepted {
            Some((p, v)) => (q, value) = (p, v),
            None => step_rad *= 0.5,
        }
    }
    Ok(HeuristicSeed {
        q,
        objective_start,
        objective_end: value,
        generation_time: started.elapsed(),
    })
}
