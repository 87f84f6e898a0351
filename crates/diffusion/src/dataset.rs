//! The DP training pairs: `(c = [p0, d, n], q̄)` for every label of every training task, with the
//! xz-plane mirror augmentation (SPEC §6) when the robot has that symmetry.

use emg_control::Task;
use emg_kinematics::{JointVector, MAX_DOF, Robot, Vec3};
use emg_seeding::LabelSet;

use crate::seed::{CONDITION_DIM, condition_of};
use crate::train::{Mirror, TrainError, TrainingSet};

/// Sign flips of the xz-plane mirror: the y components of `p0`, `d`, `n` …
pub const MIRROR_CONDITION_SIGNS: [f32; CONDITION_DIM] =
    [1.0, -1.0, 1.0, 1.0, -1.0, 1.0, 1.0, -1.0, 1.0];
/// … and joints 1, 3, 5, 7.
pub const MIRROR_JOINT_SIGNS: [f32; MAX_DOF] = [-1.0, 1.0, -1.0, 1.0, -1.0, 1.0, -1.0];

/// Configurations on which [`has_mirror_symmetry`] compares a pose with its mirror image.
const SYMMETRY_PROBES: usize = 64;

/// Whether flipping joints 1, 3, 5, 7 mirrors the arm in the base's xz-plane: the mirrored joints'
/// limits are symmetric about 0 (so that the flip holds in normalised coordinates too), and on
/// [`SYMMETRY_PROBES`] configurations spread over the limits the flipped configuration puts the TCP
/// and the tool axis at the mirror images (y negated) of the original's. True for the FR3 and the
/// iiwa 14; any other arm is checked rather than assumed.
pub fn has_mirror_symmetry(robot: &Robot) -> bool {
    let limits = robot.limits();
    let flipped: Vec<usize> = (0..MAX_DOF)
        .filter(|&j| MIRROR_JOINT_SIGNS[j] < 0.0)
        .collect();
    if flipped.iter().any(|&j| limits.mid()[j].abs() > 1e-9) {
        return false;
    }
    let mirror = |v: Vec3| Vec3::new(v.x, -v.y, v.z);
    (0..SYMMETRY_PROBES).all(|k| {
        // A deterministic spread: joint j at fraction frac((k + 1)·φ_j) of its range.
        let q = robot.configuration_from_fn(|j| {
            let fraction = ((k + 1) as f64 * (0.618_033_988_75 + 0.1 * j as f64)).fract();
            limits.lower[j] + fraction * (limits.upper[j] - limits.lower[j])
        });
        let q_mirrored = q.component_mul(&JointVector::from_fn(|j, _| {
            f64::from(MIRROR_JOINT_SIGNS[j])
        }));
        let (a, b) = (robot.forward(&q), robot.forward(&q_mirrored));
        (mirror(a.tcp()) - b.tcp()).norm() < 1e-9
            && (mirror(a.tool_axis()) - b.tool_axis()).norm() < 1e-9
    })
}

/// The training set of `labels` over `tasks` (the task set the labels index): every label's `q`
/// normalised to `[−1, 1]` by the joint limits, paired with its task's condition; with the
/// mirror augmentation when the robot [has the symmetry](has_mirror_symmetry).
pub fn training_set(
    robot: &Robot,
    tasks: &[Task],
    labels: &LabelSet,
    name: &str,
) -> Result<TrainingSet, TrainError> {
    let (mut conditions, mut samples) = (Vec::new(), Vec::new());
    for entry in labels.tasks() {
        let task = tasks
            .get(entry.task_index as usize)
            .ok_or_else(|| TrainError::BadData {
                field: "task_index",
                problem: format!(
                    "{} is past the {} tasks of the task set",
                    entry.task_index,
                    tasks.len()
                ),
            })?;
        let condition = condition_of(task);
        for label in &entry.labels {
            conditions.extend_from_slice(&condition);
            let normalised = robot.limits().normalise(&label.q);
            samples.extend(robot.joints_of(&normalised).iter().map(|v| *v as f32));
        }
    }
    let set = TrainingSet::new(conditions, samples, CONDITION_DIM, robot.dof(), name)?;
    if !has_mirror_symmetry(robot) {
        return Ok(set);
    }
    set.with_mirror(Mirror {
        condition_signs: MIRROR_CONDITION_SIGNS.to_vec(),
        sample_signs: MIRROR_JOINT_SIGNS[..robot.dof()].to_vec(),
    })
}
