//! The step-by-step re-check of a recorded motion.

use crate::model::{ReferenceModel, Scene, angle_deg, within};
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

/// The points a check goes through: a recorded motion's, or timed samples whose TCP, tool
/// angle and path length are what the checker's own kinematics give
/// ([`crate::JointSamples::to_recording`] without building it).
#[derive(Clone, Copy)]
pub(crate) enum Points<'a> {
    /// A recorded motion, its records compared with the checker's.
    Recorded(&'a Recording),
    /// Timed joint positions, their motion [`Ending::Stopped`].
    Samples {
        /// Times (s).
        time_s: &'a [f64],
        /// Joint positions (rad).
        q: &'a [Joints],
    },
}

/// What a check measured at every point with the checker's kinematics, for a report.
pub(crate) struct Measured {
    /// Each point's progress along the line or path ([`Line::reached`] follows them).
    pub progress: Vec<f64>,
    /// Largest distance of a TCP from the line or path (m).
    pub max_line_deviation_m: f64,
    /// Largest angle between the tool axis and `n` (degrees).
    pub max_tool_angle_deg: f64,
    /// Smallest clearance between checked capsule pairs (m), with the first pair's links.
    pub min_clearance: (f64, String, String),
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
        self.check_points(line, Points::Recorded(recording), bounds)
            .map(|_| ())
    }

    /// [`Self::check_recording`] of `points`, measuring every point once (one forward
    /// kinematics pass per point for every check and every measure).
    pub(crate) fn check_points(
        &self,
        line: &Line,
        points: Points<'_>,
        bounds: &Bounds,
    ) -> Result<Measured, CheckFailure> {
        let limits = self.limits();
        let velocity_limits = self.velocity_limits();
        let fail = |step: usize, check: FailedCheck, problem: String| {
            Err(CheckFailure {
                step,
                check,
                problem,
            })
        };
        let (count, ending) = match points {
            Points::Recorded(recording) => (recording.steps.len(), &recording.ending),
            Points::Samples { q, .. } => (q.len(), &Ending::Stopped),
        };
        let time = |k: usize| match points {
            Points::Recorded(recording) => recording.steps[k].time_s,
            Points::Samples { time_s, .. } => time_s[k],
        };
        let joints = |k: usize| match points {
            Points::Recorded(recording) => &recording.steps[k].q,
            Points::Samples { q, .. } => &q[k],
        };
        if count == 0 {
            return fail(
                0,
                FailedCheck::Empty,
                "the trajectory holds no step, not even its seed".into(),
            );
        }
        let valid_steps = match ending {
            Ending::InvalidStart { .. } if count != 1 => {
                return fail(
                    1,
                    FailedCheck::Ending,
                    format!("an invalid start must hold only the seed, found {count} steps"),
                );
            }
            Ending::InvalidStart { .. } => 0,
            _ => count,
        };
        let scene = Scene::new(line, bounds);
        let mut placement = self.placement();
        let mut tcps = Vec::with_capacity(count);
        // Each point's progress, followed from the start: its distance from the task is
        // measured there.
        let mut progress = Vec::with_capacity(count);
        let mut max_line_deviation_m = 0.0_f64;
        let mut max_tool_angle_deg = 0.0_f64;
        let mut min_clearance: (f64, Option<usize>) = (f64::INFINITY, None);
        for k in 0..count {
            let q = joints(k);
            let checked = k < valid_steps;
            if checked {
                for (i, (lo, hi)) in limits.iter().enumerate() {
                    if !(q[i] >= *lo && q[i] <= *hi) {
                        return fail(
                            k,
                            FailedCheck::JointLimit { joint: i + 1 },
                            format!("joint {} = {} outside [{lo}, {hi}]", i + 1, q[i]),
                        );
                    }
                }
            }
            self.place(q, &mut placement);
            let (tcp, z) = placement.tcp_pose();
            tcps.push(tcp);
            let (s, lateral) = line.follow(&tcp, progress.last().copied().unwrap_or(0.0));
            progress.push(s);
            let angle = angle_deg(&z, &line.n);
            let clearance = self.placed_clearance(&placement);
            max_line_deviation_m = max_line_deviation_m.max(lateral);
            max_tool_angle_deg = max_tool_angle_deg.max(angle);
            if clearance.0 < min_clearance.0 {
                min_clearance = clearance;
            }
            if !checked {
                continue;
            }
            let (recorded_tcp, recorded_angle) = match points {
                Points::Recorded(recording) => {
                    (recording.steps[k].tcp, recording.steps[k].tool_angle_deg)
                }
                Points::Samples { .. } => (tcp, angle),
            };
            if !within((tcp - recorded_tcp).norm(), SLACK) {
                return fail(
                    k,
                    FailedCheck::RecordedTcp,
                    format!("recorded TCP {recorded_tcp:?} but FK gives {tcp:?}"),
                );
            }
            if !within(lateral, bounds.line_tolerance_m + SLACK) {
                return fail(
                    k,
                    FailedCheck::LineTolerance,
                    format!("TCP {lateral} m off the line"),
                );
            }
            if !within(angle, bounds.theta_max_deg + ANGLE_SLACK_DEG) {
                return fail(
                    k,
                    FailedCheck::ToolCone,
                    format!("tool axis {angle}° from n"),
                );
            }
            if !within((angle - recorded_angle).abs(), ANGLE_SLACK_DEG) {
                return fail(
                    k,
                    FailedCheck::RecordedToolAngle,
                    format!("recorded tool angle {recorded_angle} but FK gives {angle}"),
                );
            }
            if !within(bounds.collision_margin_m - SLACK, clearance.0) {
                let (gap, a, b) = self.clearance_names(clearance);
                return fail(
                    k,
                    FailedCheck::SelfCollision,
                    format!("{a} and {b} collide (clearance {:.2} mm)", gap * 1e3),
                );
            }
            // Every margin's lower bound at least zero: no margin is below −SLACK, and the
            // margins need not be measured.
            if !self.scene_clear(&placement, &scene)
                && let Some((margin, link, obstacle)) = self.placed_scene_margin(&placement, &scene)
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
            let time_s = time(k);
            if !time_s.is_finite() {
                return fail(
                    k,
                    FailedCheck::Timestamps,
                    format!("timestamp {time_s} is not finite"),
                );
            }
            if k > 0 {
                let previous_time_s = time(k - 1);
                let previous = joints(k - 1);
                if within(time_s, previous_time_s) {
                    return fail(
                        k,
                        FailedCheck::Timestamps,
                        "timestamps do not increase".into(),
                    );
                }
                if let Some(fraction) = bounds.velocity_limit_fraction {
                    let elapsed = time_s - previous_time_s;
                    for (i, limit) in velocity_limits.iter().enumerate() {
                        let speed = (q[i] - previous[i]).abs() / elapsed;
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
        let (length, claimed) = match points {
            Points::Recorded(recording) => (
                line.reached(recording.steps.iter().map(|step| step.tcp)),
                recording.path_length_m,
            ),
            // The TCPs are the checker's, and so is the length claimed.
            Points::Samples { .. } => {
                let reached = progress.last().copied().unwrap_or(0.0);
                (reached, reached)
            }
        };
        if let (Ending::Completed, Some(path_length)) = (ending, line.path_length())
            && !within(path_length - PATH_END_SLACK_M, length)
        {
            return fail(
                count - 1,
                FailedCheck::Ending,
                format!("claims the end of the path ({path_length} m) but reaches {length} m"),
            );
        }
        if !within((length - claimed).abs(), SLACK) {
            return fail(
                count - 1,
                FailedCheck::PathLength,
                format!("reported path length {claimed} but the last step gives {length}"),
            );
        }
        let blamed = match ending {
            Ending::Rejected { blame, rejected_q } => Some((blame, *rejected_q)),
            Ending::InvalidStart { blame } => Some((blame, *joints(0))),
            Ending::Stopped | Ending::Completed => None,
        };
        if let Some((blame, q)) = blamed
            && !self.breaks(
                line,
                &q,
                blame,
                bounds,
                progress.last().copied().unwrap_or(0.0),
            )
        {
            return fail(
                count,
                FailedCheck::Ending,
                format!("the final configuration does not break {blame:?}"),
            );
        }
        Ok(Measured {
            progress,
            max_line_deviation_m,
            max_tool_angle_deg,
            min_clearance: self.clearance_names(min_clearance),
        })
    }

    /// Whether configuration `q` breaks the constraint named by `blame`, the motion's last
    /// point having stood `reached` along the task.
    fn breaks(
        &self,
        line: &Line,
        q: &Joints,
        blame: &Blame,
        bounds: &Bounds,
        reached: f64,
    ) -> bool {
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
            Blame::LineTolerance => !within(
                line.follow(&tcp, reached).1,
                bounds.line_tolerance_m - SLACK,
            ),
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
