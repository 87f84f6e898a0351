//! Running one controller over many tasks in parallel, and summarising path lengths.

use std::collections::BTreeMap;

use emg_kinematics::{JointVector, Robot};
use rayon::prelude::*;
use serde::{Deserialize, Serialize};

use emg_control::{NullSpaceController, RolloutConfig, Task, Trajectory, rollout};

/// Runs a fresh controller from `make_controller` on every task from the seed `seed_of(task)`.
/// Results are in task order and independent of the number of threads; `progress()` is called
/// once per finished task.
pub fn rollout_all<C, M, S>(
    robot: &Robot,
    tasks: &[Task],
    seed_of: S,
    make_controller: M,
    config: &RolloutConfig,
    progress: &(dyn Fn() + Sync),
) -> Vec<Trajectory>
where
    C: NullSpaceController,
    M: Fn() -> C + Sync,
    S: Fn(&Task) -> JointVector + Sync,
{
    let seeds: Vec<JointVector> = tasks.iter().map(seed_of).collect();
    rollout_from(robot, tasks, &seeds, make_controller, config, progress)
}

/// Runs a fresh controller from `make_controller` on task `i` from `seeds[i]`, in parallel.
/// Results are in task order and independent of the number of threads; `progress()` is called
/// once per finished task.
pub fn rollout_from<C, M>(
    robot: &Robot,
    tasks: &[Task],
    seeds: &[JointVector],
    make_controller: M,
    config: &RolloutConfig,
    progress: &(dyn Fn() + Sync),
) -> Vec<Trajectory>
where
    C: NullSpaceController,
    M: Fn() -> C + Sync,
{
    assert_eq!(tasks.len(), seeds.len(), "one seed per task");
    tasks
        .par_iter()
        .zip(seeds)
        .map(|(task, seed)| {
            let mut controller = make_controller();
            let trajectory = rollout(robot, task, seed, &mut controller, config);
            progress();
            trajectory
        })
        .collect()
}

/// Mean / standard deviation / min / max of a sample (the columns of the paper's tables).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Summary {
    /// Sample size.
    pub count: usize,
    /// Arithmetic mean.
    pub mean: f64,
    /// Population standard deviation.
    pub std: f64,
    /// Smallest value.
    pub min: f64,
    /// Largest value.
    pub max: f64,
}

impl Summary {
    /// Summary of `values`, summed in order (deterministic); `None` when empty.
    pub fn of(values: &[f64]) -> Option<Self> {
        if values.is_empty() {
            return None;
        }
        let count = values.len();
        let mean = values.iter().sum::<f64>() / count as f64;
        let variance = values.iter().map(|v| (v - mean).powi(2)).sum::<f64>() / count as f64;
        Some(Self {
            count,
            mean,
            std: variance.sqrt(),
            min: values.iter().copied().fold(f64::INFINITY, f64::min),
            max: values.iter().copied().fold(f64::NEG_INFINITY, f64::max),
        })
    }
}

/// How many trajectories ended for each reason (`joint_limit`, `tool_cone`, ...).
pub fn termination_histogram(trajectories: &[Trajectory]) -> BTreeMap<String, usize> {
    let mut histogram = BTreeMap::new();
    for trajectory in trajectories {
        *histogram
            .entry(trajectory.termination.label().to_string())
            .or_insert(0) += 1;
    }
    histogram
}

/// How many trajectories ended at each joint's limit (1-based joint number).
pub fn joint_limit_histogram(trajectories: &[Trajectory]) -> BTreeMap<usize, usize> {
    let mut histogram = BTreeMap::new();
    for trajectory in trajectories {
        if let emg_control::Termination::Violation {
            violation: emg_control::Violation::JointLimit { joint, .. },
            ..
        } = &trajectory.termination
        {
            *histogram.entry(*joint).or_insert(0) += 1;
        }
    }
    histogram
}
