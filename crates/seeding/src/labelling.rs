//! Labelling one task: candidates across branches → classical rollout scores → stability under
//! small task perturbations → the top `K'` (Sec. 4.1, SPEC §7).

use emg_control::{ClassicalController, Task, rollout};
use emg_kinematics::{JointVector, PoseTarget, Robot, Vec3, project_to_pose, rotation_about};
use rand::{RngExt, SeedableRng};
use rand_chacha::ChaCha8Rng;
use serde::{Deserialize, Serialize};

use crate::branch::sample_branches;
use crate::config::LabelConfig;
use crate::ik::cone_ik_solutions;
use crate::labels::{Label, TaskLabels};

/// What labelling one task found besides its labels (for the labelling report).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct TaskStats {
    /// Index of the task in its task set.
    pub task_index: u32,
    /// Distinct self-motion branches among the candidates.
    pub branches: u32,
    /// Candidates scored by a rollout (IK solutions, projected `q0_seed`, walk samples).
    pub candidates: u32,
    /// Classical path length from the unprojected `q0_seed` (m; 0 without one).
    pub seed_length_m: f64,
    /// Longest classical path length over all candidates (m), stable or not.
    pub best_length_m: f64,
}

/// The labels of `task` (task `task_index` of its set) and what was found on the way.
/// Deterministic: every random draw comes from `config.seed`, stream `task_index`.
pub fn label_task(
    robot: &Robot,
    task: &Task,
    task_index: u32,
    config: &LabelConfig,
) -> (TaskLabels, TaskStats) {
    let mut rng = ChaCha8Rng::seed_from_u64(config.seed);
    rng.set_stream(u64::from(task_index));
    let target = PoseTarget {
        position: task.p0,
        tool_axis: task.n,
        roll_axis: None,
    };
    let mut starts = cone_ik_solutions(robot, &task.p0, &task.n, &config.ik, &mut rng);
    if let Some(seed) = task.q0_seed {
        starts.insert(0, seed);
    }
    let mut exact: Vec<JointVector> = Vec::with_capacity(starts.len());
    for start in &starts {
        let Ok((q, _)) = project_to_pose(robot, start, &target, &config.projection) else {
            continue;
        };
        let valid = robot.limits().first_violation(&q, 0.0).is_none()
            && robot.first_collision(&robot.forward(&q), 0.0).is_none();
        if valid && exact.iter().all(|e| (e - q).amax() >= config.ik.dedup_rad) {
            exact.push(q);
        }
    }
    let samples = sample_branches(robot, &exact, &target, &config.branch, &config.projection);
    let score = |task: &Task, q: &JointVector| {
        let mut controller = ClassicalController::new(config.gains.clone());
        rollout(robot, task, q, &mut controller, &config.rollout).path_length_m
    };
    let mut scored: Vec<(f64, usize)> = samples
        .configurations
        .iter()
        .enumerate()
        .map(|(i, (q, _))| (score(task, q), i))
        .collect();
    let best_length_m = scored.iter().map(|(l, _)| *l).fold(0.0, f64::max);
    scored.retain(|(length, _)| *length >= config.min_length_m);
    scored.sort_by(|a, b| b.0.total_cmp(&a.0).then(a.1.cmp(&b.1)));

    let perturbed = perturbed_tasks(robot, task, config, &mut rng);
    let mut labels: Vec<Label> = Vec::with_capacity(config.max_labels);
    for (length, i) in scored {
        if labels.len() == config.max_labels {
            break;
        }
        let (q, branch) = samples.configurations[i];
        if labels.iter().any(|l| (l.q - q).amax() < config.dedup_rad) {
            continue;
        }
        let stability_m = perturbed
            .iter()
            .map(|p| {
                let moved = PoseTarget {
                    position: p.p0,
                    tool_axis: p.n,
                    roll_axis: None,
                };
                project_to_pose(robot, &q, &moved, &config.projection)
                    .map_or(length, |(q, _)| (score(p, &q) - length).abs())
            })
            .fold(0.0, f64::max);
        let tolerance = config
            .stability
            .stable_abs_m
            .max(config.stability.stable_fraction * length);
        if stability_m <= tolerance {
            labels.push(Label::stored(q, length, branch, stability_m));
        }
    }
    let seed_length_m = task.q0_seed.map_or(0.0, |seed| score(task, &seed));
    let stats = TaskStats {
        task_index,
        branches: samples.branch_count,
        candidates: samples.configurations.len() as u32,
        seed_length_m,
        best_length_m,
    };
    (TaskLabels { task_index, labels }, stats)
}

/// The perturbed tasks of the stability test: `p0` moved by `position_m` in a random direction,
/// `n` and `d` turned together by `angle_deg` about a random axis ⟂ `n`.
fn perturbed_tasks(
    robot: &Robot,
    task: &Task,
    config: &LabelConfig,
    rng: &mut ChaCha8Rng,
) -> Vec<Task> {
    let cfg = &config.stability;
    (0..cfg.perturbations)
        .filter_map(|_| {
            let shift = random_unit(rng) * cfg.position_m;
            let axis = random_unit(rng);
            let axis = (axis - task.n * axis.dot(&task.n)).normalize();
            let turn = rotation_about(&axis, cfg.angle_deg.to_radians());
            Task::new(robot, task.p0 + shift, turn * task.d, turn * task.n, None).ok()
        })
        .collect()
}

fn random_unit(rng: &mut ChaCha8Rng) -> Vec3 {
    loop {
        let v = Vec3::new(
            rng.random_range(-1.0..1.0),
            rng.random_range(-1.0..1.0),
            rng.random_range(-1.0..1.0),
        );
        let norm = v.norm();
        if norm > 1e-3 && norm <= 1.0 {
            return v / norm;
        }
    }
}
