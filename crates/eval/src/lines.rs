//! A polyline stroke planned the way a line-only planner makes a user plan it: each straight
//! segment on its own, as a line task from scratch, with the arm stopping at every corner and
//! free to start the next line on another self-motion branch.

use emg_control::{ARRIVAL_M, Task};
use emg_planner::{PlanError, PlanRequest, Planner};
use serde::{Deserialize, Serialize};

/// Largest joint change (rad) between where one line's plan reaches its corner and where the
/// next line's plan starts that counts as the same configuration (the search's own
/// `distinct_rad`); a larger one means the arm leaves the stroke to reconfigure.
pub const SAME_CONFIGURATION_RAD: f64 = 0.05;

/// How far a stroke gets one line at a time.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct LinesOutcome {
    /// Length drawn line after line until the first line that does not reach its corner
    /// (that line's part included), reconfigurations allowed (m).
    pub drawn_m: f64,
    /// Length drawn before the first reconfiguration or the first incomplete line (m): what the
    /// arm draws without leaving the stroke.
    pub continuous_m: f64,
    /// Corners at which the next line's plan starts on another configuration.
    pub reconfigurations: usize,
}

/// `task`'s path (straight segments only) planned one line at a time with `request`: segment
/// `i` as the line from its start along its direction on the path's surface, its plan cut at
/// the segment's length. `None` when the path holds an arc.
pub fn lines_one_at_a_time(
    planner: &Planner,
    task: &Task,
    request: &PlanRequest,
) -> Option<Result<LinesOutcome, PlanError>> {
    let path = task.path.as_ref()?;
    let mut lines = Vec::new();
    for piece in path.pieces() {
        let (start, end, None) = piece.outline() else {
            return None;
        };
        lines.push((start, (end - start) / piece.length_m, piece.length_m));
    }
    Some(plan_lines(planner, task, request, &lines))
}

/// Plans `lines` (start, unit direction, length) in turn (see [`lines_one_at_a_time`]).
fn plan_lines(
    planner: &Planner,
    task: &Task,
    request: &PlanRequest,
    lines: &[(emg_kinematics::Vec3, emg_kinematics::Vec3, f64)],
) -> Result<LinesOutcome, PlanError> {
    let mut outcome = LinesOutcome {
        drawn_m: 0.0,
        continuous_m: 0.0,
        reconfigurations: 0,
    };
    let mut continuous = true;
    let mut corner_q: Option<emg_kinematics::JointVector> = None;
    for &(start, direction, length) in lines {
        // A line whose start lies beyond the arm's reach cannot be planned: the stroke ends.
        let Ok(line) = Task::new(planner.robot(), start, direction, task.n, None) else {
            break;
        };
        // Nor one whose start no seed can be prepared at.
        let plan = match planner.plan(&line, request) {
            Ok(plan) => plan,
            Err(PlanError::Seed(_)) => break,
            Err(error) => return Err(error),
        };
        if let Some(previous) = corner_q {
            let jump = (plan.seed.q - previous).amax();
            if jump > SAME_CONFIGURATION_RAD {
                outcome.reconfigurations += 1;
                continuous = false;
            }
        }
        let reached = plan.trajectory.path_length_m.clamp(0.0, length);
        outcome.drawn_m += reached;
        if continuous {
            outcome.continuous_m += reached;
        }
        if reached < length - ARRIVAL_M {
            break;
        }
        corner_q = plan
            .trajectory
            .steps
            .iter()
            .find(|step| line.progress(&step.tcp) >= length - ARRIVAL_M)
            .map(|step| step.q);
    }
    Ok(outcome)
}
