//! The DP training pairs: `(c = [p0, d, n], q̄)` for every label of every training task, with the
//! FR3's mirror symmetry (SPEC §6).

use emg_control::Task;
use emg_kinematics::{DOF, Robot};
use emg_seeding::LabelSet;

use crate::seed::{CONDITION_DIM, condition_of};
use crate::train::{Mirror, TrainError, TrainingSet};

/// Sign flips of the xz-plane mirror: the y components of `p0`, `d`, `n` …
pub const MIRROR_CONDITION_SIGNS: [f32; CONDITION_DIM] =
    [1.0, -1.0, 1.0, 1.0, -1.0, 1.0, 1.0, -1.0, 1.0];
/// … and joints 1, 3, 5, 7.
pub const MIRROR_JOINT_SIGNS: [f32; DOF] = [-1.0, 1.0, -1.0, 1.0, -1.0, 1.0, -1.0];

/// The training set of `labels` over `tasks` (the task set the labels index): every label's `q`
/// normalised to `[−1, 1]` by the joint limits, paired with its task's condition; with the
/// mirror augmentation, which needs symmetric limits on the mirrored joints (so that the flip
/// holds in normalised coordinates too).
pub fn training_set(
    robot: &Robot,
    tasks: &[Task],
    labels: &LabelSet,
    name: &str,
) -> Result<TrainingSet, TrainError> {
    let limits = robot.limits();
    for (j, sign) in MIRROR_JOINT_SIGNS.iter().enumerate() {
        if *sign < 0.0 && limits.mid()[j].abs() > 1e-9 {
            return Err(TrainError::BadData {
                field: "robot",
                problem: format!(
                    "joint {} has asymmetric limits; the mirror augmentation needs them symmetric",
                    j + 1
                ),
            });
        }
    }
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
            samples.extend(robot.limits().normalise(&label.q).iter().map(|v| *v as f32));
        }
    }
    TrainingSet::new(conditions, samples, CONDITION_DIM, DOF, name)?.with_mirror(Mirror {
        condition_signs: MIRROR_CONDITION_SIGNS.to_vec(),
        sample_signs: MIRROR_JOINT_SIGNS.to_vec(),
    })
}
