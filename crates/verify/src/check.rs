//! The step-by-step re-check of a recorded motion.

use crate::model::{ReferenceModel, angle_deg, within};
use crate::record::{Blame, Bounds, Ending, Joints, Line, Recording};

/// Numerical slack when comparing recomputed values with recorded ones and with bounds.
const SLACK: f64 = 1e-9;

/// Slack of angles (degrees).
const ANGLE_SLACK_DEG: f64 = 1e-6;

/// How far short (m) of its path's end a motion that claims to have reached it may stop.
const PATH_END_SLACK_M: f64 = 2e-4;

/// Which check a recorded motion fails.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum FailedCheck {
    /// The recording holds no point at all.
    Empty,
    /// Joint `joint` (1-based) is outside its position limits.
    JointLimit {
        /// 1-based joint number.
        joint: usize,
    },
    /// The recorded TCP is not where the checker's forward kinematics puts it.
    RecordedTcp,
    /// The recorded tool angle is not the checker's.
    RecordedToolAngle,
    /// The TCP is farther from the line than the tolerance.
    LineTolerance,
    /// The tool axis is outside the cone around `n`.
    ToolCone,
    /// Two capsules of the arm are closer than the margin.
    SelfCollision,
    /// A capsule of the arm is nearer an obstacle (or, the tool's excepted, the work surface)
    /// than its clearance.
    SceneContact,
    /// Timestamps are not finite or do not increase.
    Timestamps,
    /// Joint `joint` (1-based) moves faster than its share of the velocity limit.
    JointSpeed {
        /// 1-based joint number.
        joint: usize,
    },
    /// The reported path length is not the last point's.
    PathLength,
    /// The claimed ending does not hold: the blamed configuration breaks nothing, or an invalid
    /// start holds more than one point.
    Ending,
}

/// A point of a recording that does not hold up: which one, which check, and by how much.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
#[error("step {step}: {problem}")]
pub struct CheckFailure {
    /// Index of the offending point (the point count for the claimed ending).
    pub step: usize,
    /// The check that fails.
    pub check: FailedCheck,
    /// What is wrong, with the numbers.
    pub problem: String,
}

impl ReferenceModel {
    /// Verifies every point of `recording` against `bounds` and its own records: joint limits,
    /// TCP and tool angle as recorded, line tolerance, tool cone, no self-collision, the
    /// clearance of every obstacle and of the work surface (when `bounds` hold them), increasing
    /// timestamps, joint speeds within the velocity limits (when `bounds` enforce them), the
    /// reported path length, and that a rejected configuration really breaks the constraint it
    /// is blamed on.
    pub fn check_recording(
        &self,
        line: &Line,
        recording: &Recording,
        bounds: &Bounds,
    ) -> Result<(), CheckFailure> {
        let limits = self.limits();
        let velocity_limits = self.velocity_limits();
        let fail = |step: usize, check: FailedCheck, problem: String| {
            Err(CheckFailure {
                step,
                check,
                problem,
            })
        };
        let steps = &recording.steps;
        if steps.is_empty() {
            return fail(
                0,
                FailedCheck::Empty,
                "the trajectory holds no step, not even its seed".into(),
            );
        }
        let valid_steps = match recording.ending {
            Ending::InvalidStart { .. } if steps.len() != 1 => {
                return fail(
                    1,
                    FailedCheck::Ending,
                    format!(
                        "an invalid start must hold only the seed, found {} steps",
                        steps.len()
                    ),
                );
            }
            Ending::InvalidStart { .. } => 0,
            _ => steps.len(),
        };
        for (k, step) in steps.iter().enumerate().take(valid_steps) {
            let q = &step.q;
            for (i, (lo, hi)) in limits.iter().enumerate() {
                if !(q[i] >= *lo && q[i] <= *hi) {
                    return fail(
                        k,
                        FailedCheck::JointLimit { joint: i + 1 },
                        format!("joint {} = {} outside [{lo}, {hi}]", i + 1, q[i]),
                    );
                }
            }
            let (tcp, z) = self.tcp_pose(q);
            if !within((tcp - step.tcp).norm(), SLACK) {
                return fail(
                    k,
                    FailedCheck::RecordedTcp,
                    format!("recorded TCP {:?} but FK gives {:?}", step.tcp, tcp),
                );
            }
            let lateral = line.distance(&tcp);
            if !within(lateral, bounds.line_tolerance_m + SLACK) {
                return fail(
                    k,
                    FailedCheck::LineTolerance,
                    format!("TCP {lateral} m off the line"),
                );
            }
            let angle = angle_deg(&z, &line.n);
            if !within(angle, bounds.theta_max_deg + ANGLE_SLACK_DEG) {
                return fail(
                    k,
                    FailedCheck::ToolCone,
                    format!("tool axis {angle}° from n"),
                );
            }
            if !within((angle - step.tool_angle_deg).abs(), ANGLE_SLACK_DEG) {
                return fail(
                    k,
                    FailedCheck::RecordedToolAngle,
                    format!(
                        "recorded tool angle {} but FK gives {angle}",
                        step.tool_angle_deg
                    ),
                );
            }
            let (gap, a, b) = self.min_clearance(q);
            if !within(bounds.collision_margin_m - SLACK, gap) {
                return fail(
                    k,
                    FailedCheck::SelfCollision,
                    format!("{a} and {b} collide (clearance {:.2} mm)", gap * 1e3),
                );
            }
            if let Some((margin, link, obstacle)) = self.scene_margin(q, line, bounds)
                && !within(-SLACK, margin)
            {
                return fail(
                    k,
                    FailedCheck::SceneContact,
                    format!(
                        "{link} is {:.2} mm inside the clearance of the {obstacle}",
                        -margin * 1e3
                    ),
                );
            }
            if !step.time_s.is_finite() {
                return fail(
                    k,
                    FailedCheck::Timestamps,
                    format!("timestamp {} is not finite", step.time_s),
                );
            }
            if k > 0 {
                let previous = &steps[k - 1];
                if within(step.time_s, previous.time_s) {
                    return fail(
                        k,
                        FailedCheck::Timestamps,
                        "timestamps do not increase".into(),
                    );
                }
                if let Some(fraction) = bounds.velocity_limit_fraction {
                    let elapsed = step.time_s - previous.time_s;
                    for (i, limit) in velocity_limits.iter().enumerate() {
                        let speed = (step.q[i] - previous.q[i]).abs() / elapsed;
                        let allowed = fraction * limit;
                        if !within(speed, allowed * (1.0 + SLACK)) {
                            return fail(
                                k,
                                FailedCheck::JointSpeed { joint: i + 1 },
                                format!(
                                    "joint {} moves at {speed} rad/s, above {allowed} rad/s",
                                    i + 1
                                ),
                            );
                        }
                    }
                }
            }
        }
        let length = line.reached(steps.iter().map(|step| step.tcp));
        if let (Ending::Completed, Some(path_length)) = (&recording.ending, line.path_length())
            && !within(path_length - PATH_END_SLACK_M, length)
        {
            return fail(
                steps.len() - 1,
                FailedCheck::Ending,
                format!("claims the end of the path ({path_length} m) but reaches {length} m"),
            );
        }
        if !within((length - recording.path_length_m).abs(), SLACK) {
            return fail(
                steps.len() - 1,
                FailedCheck::PathLength,
                format!(
                    "reported path length {} but the last step gives {length}",
                    recording.path_length_m
                ),
            );
        }
        let blamed = match &recording.ending {
            Ending::Rejected { blame, rejected_q } => Some((blame, *rejected_q)),
            Ending::InvalidStart { blame } => Some((blame, steps[0].q)),
            Ending::Stopped | Ending::Completed => None,
        };
        if let Some((blame, q)) = blamed
            && !self.breaks(line, &q, blame, bounds)
        {
            return fail(
                steps.len(),
                FailedCheck::Ending,
                format!("the final configuration does not break {blame:?}"),
            );
        }
        Ok(())
    }

    /// Whether configuration `q` breaks the constraint named by `blame`.
    fn breaks(&self, line: &Line, q: &Joints, blame: &Blame, bounds: &Bounds) -> bool {
        let (tcp, z) = self.tcp_pose(q);
        match blame {
            // NaN breaks every bound (as in the rollout); a joint number out of range breaks none.
            Blame::JointLimit { joint } => {
                match joint
                    .checked_sub(1)
                    .and_then(|i| self.limits().get(i).copied().zip(q.get(i)))
                {
                    Some(((lo, hi), value)) => !(*value >= lo && *value <= hi),
                    None => false,
                }
            }
            Blame::LineTolerance => !within(line.distance(&tcp), bounds.line_tolerance_m - SLACK),
            Blame::ToolCone => !within(
                angle_deg(&z, &line.n),
                bounds.theta_max_deg - ANGLE_SLACK_DEG,
            ),
            Blame::SelfCollision => self.min_clearance(q).0 < bounds.collision_margin_m + SLACK,
            Blame::SceneContact => self
                .scene_margin(q, line, bounds)
                .is_some_and(|(margin, ..)| !within(SLACK, margin)),
        }
    }
}
