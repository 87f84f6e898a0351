//! Holding the TCP on its line or path to a cell's tolerance: the Newton correction that the
//! corrected step ([`crate::Tracking::Corrected`]) and the timing's smooth path share.

use emg_kinematics::{DampingConfig, JointVector, Kinematics, Robot, damped_pseudo_inverse};

use crate::task::Task;

/// The share of the line tolerance beyond which a configuration's TCP is corrected onto its line
/// or path, and within which the corrections stop: half the tube stays free for the spline the
/// timing lays between the steps.
pub const CORRECTION_TRIGGER: f64 = 0.5;

/// Damping of the corrections' pseudo-inverse: `λ_max` a twenty-fifth of the step's. Near a
/// singularity, where the step's damping would leave most of an offset in place after every
/// correction, the corrections still converge, moving the joints by about the offset over
/// `σ_min`. (On the FR3's 200 paths of `cargo xtask precision-eval`, `λ_max` 0.01 finished
/// one fewer at 0.1 mm, 0.005 one fewer at 20 mm, 0.0005 as many as 0.002.)
pub const CORRECTION_DAMPING: DampingConfig = DampingConfig {
    sigma_threshold: 0.05,
    lambda_max: 0.002,
};

/// Newton corrections tried at most on one configuration.
pub const MAX_CORRECTIONS: usize = 5;

/// Moves `q`, whose forward kinematics `kinematics` holds, toward the nearest point of the task's
/// line or path (searched near the progress `s_hint`) by Newton corrections `q ← q + J⁺ e`,
/// `e` the TCP's offset to that point, `J⁺` the pseudo-inverse of the Jacobian at the current
/// `q`, damped by [`CORRECTION_DAMPING`] (no allocation). `kinematics` follows `q`. Whether the
/// TCP came within `target_m` of the line or path in at most [`MAX_CORRECTIONS`] corrections.
pub fn correct_onto_task(
    robot: &Robot,
    task: &Task,
    s_hint: f64,
    target_m: f64,
    q: &mut JointVector,
    kinematics: &mut Kinematics,
) -> bool {
    for _ in 0..MAX_CORRECTIONS {
        let offset = task.along(&kinematics.tcp(), s_hint).lateral;
        let pseudo_inverse = damped_pseudo_inverse(kinematics.jacobian(), &CORRECTION_DAMPING);
        *q += pseudo_inverse.matrix * offset;
        robot.forward_into(q, kinematics);
        if task.along(&kinematics.tcp(), s_hint).lateral.norm() <= target_m {
            return true;
        }
    }
    false
}

/// `q` moved onto the task's line or path where its TCP lies more than [`CORRECTION_TRIGGER`]
/// of `tolerance_m` off it ([`correct_onto_task`]); `q` itself where it lies closer or the
/// corrections do not get it there. On a path, the TCP is measured from, and moved toward, the
/// point its progress reaches from `s_hint` ([`Task::along`]): not a nearer stretch of the path
/// it has not reached (the other leg of a reversal, the next turn of a loop).
pub fn onto_task(
    robot: &Robot,
    task: &Task,
    q: &JointVector,
    tolerance_m: f64,
    s_hint: f64,
) -> JointVector {
    let target_m = CORRECTION_TRIGGER * tolerance_m;
    let mut kinematics = robot.forward(q);
    if task.along(&kinematics.tcp(), s_hint).lateral.norm() <= target_m {
        return *q;
    }
    let mut corrected = *q;
    if correct_onto_task(
        robot,
        task,
        s_hint,
        target_m,
        &mut corrected,
        &mut kinematics,
    ) {
        corrected
    } else {
        *q
    }
}
