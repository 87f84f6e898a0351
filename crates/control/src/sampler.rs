//! The task population of SPEC §2: tasks generated from random collision-free configurations.

use emg_kinematics::{Kinematics, Robot, Shape, ToolContact, Vec3, rotation_about};
use rand::{RngExt, SeedableRng};
use rand_chacha::ChaCha8Rng;
use rayon::prelude::*;
use serde::{Deserialize, Serialize};

use crate::classical::ClassicalController;
use crate::config::{ClassicalGains, RolloutConfig};
use crate::rollout::rollout;
use crate::task::Task;

/// Settings of the task population.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct SamplerConfig {
    /// Seed of every random choice.
    pub seed: u64,
    /// Largest tilt of `n` away from the generating tool axis (degrees).
    pub max_tilt_deg: f64,
    /// A task is kept only if the classical controller from `q0_seed` travels this far (m).
    pub min_classical_length_m: f64,
    /// Candidates drawn per parallel batch (does not change the result; 0 counts as 1).
    pub batch_size: usize,
    /// Keep only tasks a cell can pose: the work surface clears every capsule of the arm but
    /// the tool's at `q0_seed` by this much (m) ([`surface_clears`]). `None` (the default)
    /// keeps them all, as the paper's population does (about a quarter of its tasks have the
    /// surface cutting the arm at `q0_seed`). Candidate `i` is otherwise the same either way.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub surface_clearance_m: Option<f64>,
}

impl Default for SamplerConfig {
    fn default() -> Self {
        Self {
            seed: 20_260_101,
            max_tilt_deg: 5.0,
            min_classical_length_m: 0.1,
            batch_size: 4096,
            surface_clearance_m: None,
        }
    }
}

/// Draws tasks in a fixed order of candidate indices; candidate `i` depends only on the seed and
/// `i`, so the result is the same for any number of threads.
pub struct TaskSampler<'a> {
    robot: &'a Robot,
    rollout: &'a RolloutConfig,
    gains: &'a ClassicalGains,
    config: &'a SamplerConfig,
    next_candidate: u64,
}

impl<'a> TaskSampler<'a> {
    /// A sampler starting at candidate 0.
    pub fn new(
        robot: &'a Robot,
        rollout: &'a RolloutConfig,
        gains: &'a ClassicalGains,
        config: &'a SamplerConfig,
    ) -> Self {
        Self {
            robot,
            rollout,
            gains,
            config,
            next_candidate: 0,
        }
    }

    /// Candidates drawn so far.
    pub fn candidates_drawn(&self) -> u64 {
        self.next_candidate
    }

    /// The next `count` accepted tasks among at most `max_candidates` further candidates (fewer
    /// tasks when those are spent first, so that a robot whose population accepts almost
    /// nothing cannot stall the caller); `progress(accepted)` is called after every batch.
    pub fn take(
        &mut self,
        count: usize,
        max_candidates: u64,
        progress: &dyn Fn(usize),
    ) -> Vec<Task> {
        let limit = self.next_candidate.saturating_add(max_candidates);
        let mut tasks = Vec::with_capacity(count);
        while tasks.len() < count && self.next_candidate < limit {
            let first = self.next_candidate;
            let end = first
                .saturating_add(self.config.batch_size.max(1) as u64)
                .min(limit);
            let batch: Vec<Option<Task>> = (first..end)
                .into_par_iter()
                .map(|index| self.accepted_candidate(index))
                .collect();
            for (offset, task) in batch.into_iter().enumerate() {
                if let Some(task) = task {
                    tasks.push(task);
                    if tasks.len() == count {
                        self.next_candidate = first + offset as u64 + 1;
                        break;
                    }
                }
                self.next_candidate = first + offset as u64 + 1;
            }
            progress(tasks.len());
        }
        tasks
    }

    /// Candidate `index` if it passes the classical-length filter.
    fn accepted_candidate(&self, index: u64) -> Option<Task> {
        let task = candidate(self.robot, self.config, index)?;
        let seed = task.q0_seed.expect("sampled tasks keep their seed");
        let mut controller = ClassicalController::new(self.gains.clone());
        let length = rollout(self.robot, &task, &seed, &mut controller, self.rollout).path_length_m;
        (length >= self.config.min_classical_length_m).then_some(task)
    }
}

/// Candidate task `index` of the population, or `None` if its configuration self-collides (or,
/// with [`SamplerConfig::surface_clearance_m`], its work surface comes too close to the arm).
pub fn candidate(robot: &Robot, config: &SamplerConfig, index: u64) -> Option<Task> {
    let mut rng = ChaCha8Rng::seed_from_u64(config.seed);
    rng.set_stream(index);
    let limits = robot.limits();
    let q = robot.configuration_from_fn(|i| rng.random_range(limits.lower[i]..limits.upper[i]));
    let kinematics = robot.forward(&q);
    if robot.first_collision(&kinematics, 0.0).is_some() {
        return None;
    }
    let z = kinematics.tool_axis();
    let tilt = rng.random_range(0.0..=config.max_tilt_deg).to_radians();
    let tilt_axis = perpendicular_direction(&z, rng.random_range(0.0..std::f64::consts::TAU));
    let n = rotation_about(&tilt_axis, tilt) * z;
    let d = perpendicular_direction(&n, rng.random_range(0.0..std::f64::consts::TAU));
    let task = Task::new(robot, kinematics.tcp(), d, n, Some(q)).ok()?;
    match config.surface_clearance_m {
        Some(clearance) if !surface_clears(robot, &task, &kinematics, clearance) => None,
        _ => Some(task),
    }
}

/// Whether the work surface of `task` (the plane through `p0` with normal `n`) keeps at least
/// `clearance` (m) from every capsule of the arm but the tool's, placed at `kinematics`.
pub fn surface_clears(robot: &Robot, task: &Task, kinematics: &Kinematics, clearance: f64) -> bool {
    let surface = Shape::work_surface(&task.p0, &task.n);
    robot
        .first_contact(kinematics, &surface, clearance, ToolContact::Allowed)
        .is_none()
}

/// The unit vector at angle `phi` in a fixed orthonormal frame of the plane ⟂ `axis`.
fn perpendicular_direction(axis: &Vec3, phi: f64) -> Vec3 {
    let helper = if axis.x.abs() < 0.9 {
        Vec3::x()
    } else {
        Vec3::y()
    };
    let e1 = axis.cross(&helper).normalize();
    let e2 = axis.cross(&e1);
    let (sin, cos) = libm::sincos(phi);
    e1 * cos + e2 * sin
}
