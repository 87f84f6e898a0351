//! The 31-value observation of the learned controller (SPEC §4, Eq. 6).

use emg_control::StepContext;

/// Length of the observation vector.
pub const OBSERVATION_DIM: usize = 31;

/// Length of the action vector: coordinates in the null-space basis `B(q)` (Eq. 7).
pub const ACTION_DIM: usize = 4;

/// Writes the observation of `context` (Eq. 6), in this order:
/// `q̄` (7), `q̄²` (7), `d` (3), `n` (3), `z` (3), `z·n` (1), `z × n` (3), previous action (4).
///
/// `q̄ = (q − q_mid)/q_half` is the normalised configuration, `z` the tool axis, `d` and `n`
/// the task's direction and normal; the previous action is zero at reset.
pub fn observe(context: &StepContext<'_>, out: &mut [f32; OBSERVATION_DIM]) {
    let q = &context.q_normalised;
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
        .chain(context.previous_action.iter().copied());
    for (slot, value) in out.iter_mut().zip(values) {
        *slot = value as f32;
    }
}
