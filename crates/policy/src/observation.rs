//! The observation of the learned controller (SPEC §4, Eq. 6): 31 values on an arm of seven
//! joints, `3n + 10` on an arm of `n`.

use emg_control::StepContext;
use emg_kinematics::MAX_DOF;

/// Length of the observation vector of an arm of seven joints, the longest.
pub const OBSERVATION_DIM: usize = 3 * MAX_DOF + 10;

/// Length of the action vector of an arm of seven joints, the longest: coordinates in the
/// null-space basis `B(q)` (Eq. 7).
pub const ACTION_DIM: usize = MAX_DOF - 3;

/// The observation and action lengths of the learned controller of an arm of `n` joints.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct PolicyDims {
    /// Observation length `3n + 10` (at most [`OBSERVATION_DIM`]).
    pub observation: usize,
    /// Action length `n − 3`, the null space's dimension (at most [`ACTION_DIM`]).
    pub action: usize,
}

impl PolicyDims {
    /// The lengths for an arm of `joints` joints (6 or 7; other counts, which a weights file
    /// refuses, saturate instead of overflowing).
    pub fn for_joints(joints: usize) -> Self {
        Self {
            observation: joints.saturating_mul(3).saturating_add(10),
            action: joints.saturating_sub(3),
        }
    }
}

/// Writes the observation of `context` (Eq. 6) into the first `3n + 10` entries of `out`, in
/// this order: `q̄` (n), `q̄²` (n), `d` (3), `n` (3), `z` (3), `z·n` (1), `z × n` (3), previous
/// action (n − 3); the entries after them are zero.
///
/// `q̄ = (q − q_mid)/q_half` is the normalised configuration, `z` the tool axis, `d` and `n`
/// the task's direction and normal; the previous action is zero at reset.
pub fn observe(context: &StepContext<'_>, out: &mut [f32; OBSERVATION_DIM]) {
    let joints = context.robot.dof();
    let q = &context.q_normalised.as_slice()[..joints];
    let task = context.task;
    let z = context.kinematics.tool_axis();
    let cross = z.cross(&task.n);
    let values = q
        .iter()
        .copied()
        .chain(q.iter().map(|v| v * v))
        .chain(task.d.iter().copied())
        .chain(task.n.iter().copied())
        .chain(z.iter().copied())
        .chain(std::iter::once(z.dot(&task.n)))
        .chain(cross.iter().copied())
        .chain(
            context.previous_action.as_slice()[..joints - 3]
                .iter()
                .copied(),
        )
        .chain(std::iter::repeat(0.0));
    for (slot, value) in out.iter_mut().zip(values) {
        *slot = value as f32;
    }
}
