//! The step-by-step re-check of a recorded motion.

use nalgebra::Vector3;

use crate::model::{Placement, ReferenceModel, Scene, angle_deg, within};
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

impl<'a> Points<'a> {
    /// Number of points.
    fn count(&self) -> usize {
        match self {
            Points::Recorded(recording) => recording.steps.len(),
            Points::Samples { q, .. } => q.len(),
        }
    }

    /// How the motion ended: as recorded, or [`Ending::Stopped`] for samples.
    fn ending(&self) -> &'a Ending {
        match self {
            Points::Recorded(recording) => &recording.ending,
            Points::Samples { .. } => &Ending::Stopped,
        }
    }

    /// Time of point `k` (s).
    fn time(&self, k: usize) -> f64 {
        match self {
            Points::Recorded(recording) => recording.steps[k].time_s,
            Points::Samples { time_s, .. } => time_s[k],
        }
    }

    /// Joint positions of point `k` (rad).
    fn joints(&self, k: usize) -> &'a Joints {
        match self {
            Points::Recorded(recording) => &recording.steps[k].q,
            Points::Samples { q, .. } => &q[k],
        }
    }

    /// TCP and tool angle recorded at point `k`: for samples, the checker's own `tcp` and
    /// `angle`.
    fn recorded_pose(&self, k: usize, tcp: Vector3<f64>, angle: f64) -> (Vector3<f64>, f64) {
        match self {
            Points::Recorded(recording) => {
                (recording.steps[k].tcp, recording.steps[k].tool_angle_deg)
            }
            Points::Samples { .. } => (tcp, angle),
        }
    }
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

impl CheckFailure {
    /// The failure of check `check` at point `step`, `problem` saying what is wrong.
    fn at(step: usize, check: FailedCheck, problem: String) -> Self {
        CheckFailure {
            step,
            check,
            problem,
        }
    }
}

/// How many of `count` points the per-point checks cover under `ending`: none for an invalid
/// start, which must hold exactly one point, else all; an empty motion fails.
fn checked_steps(count: usize, ending: &Ending) -> Result<usize, CheckFailure> {
    if count == 0 {
        return Err(CheckFailure::at(
            0,
            FailedCheck::Empty,
            "the trajectory holds no step, not even its seed".into(),
        ));
    }
    match ending {
        Ending::InvalidStart { .. } if count != 1 => Err(CheckFailure::at(
            1,
            FailedCheck::Ending,
            format!("an invalid start must hold only the seed, found {count} steps"),
        )),
        Ending::InvalidStart { .. } => Ok(0),
        _ => Ok(count),
    }
}

/// A check's walk through its points, one at a time: the bounds it holds them to, the
/// checker's placement of the current point, and what it has measured so far.
struct PointWalk<'c> {
    /// The checker's robot.
    model: &'c ReferenceModel,
    /// The task's line or path.
    line: &'c Line,
    /// The points walked.
    points: Points<'c>,
    /// The bounds every checked point must hold.
    bounds: &'c Bounds,
    /// The obstacles and work surface of `bounds`, placed along `line`.
    scene: Scene<'c>,
    /// Joint position limits (rad).
    limits: Vec<(f64, f64)>,
    /// Joint velocity limits (rad/s).
    velocity_limits: Vec<f64>,
    /// The current point placed by the checker's forward kinematics.
    placement: Placement,
    /// Each point's progress so far, followed from the start.
    progress: Vec<f64>,
    /// Largest distance of a TCP from the line or path so far (m).
    max_line_deviation_m: f64,
    /// Largest tool angle from `n` so far (degrees).
    max_tool_angle_deg: f64,
    /// Smallest clearance so far, with the index of its capsule pair.
    min_clearance: (f64, Option<usize>),
}

impl<'c> PointWalk<'c> {
    /// A walk through `points` of `line` under `bounds`, nothing measured yet.
    fn new(
        model: &'c ReferenceModel,
        line: &'c Line,
        points: Points<'c>,
        bounds: &'c Bounds,
    ) -> Self {
        let count = points.count();
        PointWalk {
            model,
            line,
            points,
            bounds,
            scene: Scene::new(line, bounds),
            limits: model.limits(),
            velocity_limits: model.velocity_limits(),
            placement: model.placement(),
            progress: Vec::with_capacity(count),
            max_line_deviation_m: 0.0,
            max_tool_angle_deg: 0.0,
            min_clearance: (f64::INFINITY, None),
        }
    }

    /// Measures point `k` and, when it is `checked`, verifies it: joint limits before it is
    /// placed, its pose and clearances, then its timing.
    fn step(&mut self, k: usize, checked: bool) -> Result<(), CheckFailure> {
        let q = self.points.joints(k);
        if checked {
            self.check_joint_limits(k, q)?;
        }
        let (tcp, lateral, angle, clearance) = self.measure(q);
        if !checked {
            return Ok(());
        }
        self.check_pose(k, tcp, lateral, angle, clearance)?;
        self.check_timing(k, q)
    }

    /// Fails when a joint of point `k` at `q` is outside its position limits (NaN included).
    fn check_joint_limits(&self, k: usize, q: &Joints) -> Result<(), CheckFailure> {
        for (i, (lo, hi)) in self.limits.iter().enumerate() {
            if !(q[i] >= *lo && q[i] <= *hi) {
                return Err(CheckFailure::at(
                    k,
                    FailedCheck::JointLimit { joint: i + 1 },
                    format!("joint {} = {} outside [{lo}, {hi}]", i + 1, q[i]),
                ));
            }
        }
        Ok(())
    }

    /// Places `q`, follows its TCP along the line and records the measures; returns the TCP,
    /// its distance from the line, the tool angle (degrees) and the self-clearance.
    fn measure(&mut self, q: &Joints) -> (Vector3<f64>, f64, f64, (f64, Option<usize>)) {
        self.model.place(q, &mut self.placement);
        let (tcp, z) = self.placement.tcp_pose();
        let (s, lateral) = self
            .line
            .follow(&tcp, self.progress.last().copied().unwrap_or(0.0));
        self.progress.push(s);
        let angle = angle_deg(&z, &self.line.n);
        let clearance = self.model.placed_clearance(&self.placement);
        self.max_line_deviation_m = self.max_line_deviation_m.max(lateral);
        self.max_tool_angle_deg = self.max_tool_angle_deg.max(angle);
        if clearance.0 < self.min_clearance.0 {
            self.min_clearance = clearance;
        }
        (tcp, lateral, angle, clearance)
    }

    /// Verifies the placed point `k`: TCP as recorded, line tolerance, tool cone, tool angle
    /// as recorded, no self-collision and the clearance of the scene.
    fn check_pose(
        &self,
        k: usize,
        tcp: Vector3<f64>,
        lateral: f64,
        angle: f64,
        clearance: (f64, Option<usize>),
    ) -> Result<(), CheckFailure> {
        let bounds = self.bounds;
        let (recorded_tcp, recorded_angle) = self.points.recorded_pose(k, tcp, angle);
        if !within((tcp - recorded_tcp).norm(), SLACK) {
            return Err(CheckFailure::at(
                k,
                FailedCheck::RecordedTcp,
                format!("recorded TCP {recorded_tcp:?} but FK gives {tcp:?}"),
            ));
        }
        if !within(lateral, bounds.line_tolerance_m + SLACK) {
            return Err(CheckFailure::at(
                k,
                FailedCheck::LineTolerance,
                format!("TCP {lateral} m off the line"),
            ));
        }
        if !within(angle, bounds.theta_max_deg + ANGLE_SLACK_DEG) {
            return Err(CheckFailure::at(
                k,
                FailedCheck::ToolCone,
                format!("tool axis {angle}° from n"),
            ));
        }
        if !within((angle - recorded_angle).abs(), ANGLE_SLACK_DEG) {
            return Err(CheckFailure::at(
                k,
                FailedCheck::RecordedToolAngle,
                format!("recorded tool angle {recorded_angle} but FK gives {angle}"),
            ));
        }
        if !within(bounds.collision_margin_m - SLACK, clearance.0) {
            let (gap, a, b) = self.model.clearance_names(clearance);
            return Err(CheckFailure::at(
                k,
                FailedCheck::SelfCollision,
                format!("{a} and {b} collide (clearance {:.2} mm)", gap * 1e3),
            ));
        }
        self.check_scene(k)
    }

    /// Fails when a capsule of the placed point `k` is inside the clearance of an obstacle or
    /// of the work surface.
    fn check_scene(&self, k: usize) -> Result<(), CheckFailure> {
        // Every margin's lower bound at least zero: no margin is below −SLACK, and the
        // margins need not be measured.
        if !self.model.scene_clear(&self.placement, &self.scene)
            && let Some((margin, link, obstacle)) =
                self.model.placed_scene_margin(&self.placement, &self.scene)
            && !within(-SLACK, margin)
        {
            return Err(CheckFailure::at(
                k,
                FailedCheck::SceneContact,
                format!(
                    "{link} is {:.2} mm inside the clearance of the {obstacle}",
                    -margin * 1e3
                ),
            ));
        }
        Ok(())
    }

    /// Verifies the timing of point `k` at `q`: a finite timestamp after the previous one,
    /// and joint speeds from the previous point within their share of the velocity limits.
    fn check_timing(&self, k: usize, q: &Joints) -> Result<(), CheckFailure> {
        let time_s = self.points.time(k);
        if !time_s.is_finite() {
            return Err(CheckFailure::at(
                k,
                FailedCheck::Timestamps,
                format!("timestamp {time_s} is not finite"),
            ));
        }
        if k == 0 {
            return Ok(());
        }
        let previous_time_s = self.points.time(k - 1);
        let previous = self.points.joints(k - 1);
        if within(time_s, previous_time_s) {
            return Err(CheckFailure::at(
                k,
                FailedCheck::Timestamps,
                "timestamps do not increase".into(),
            ));
        }
        if let Some(fraction) = self.bounds.velocity_limit_fraction {
            let elapsed = time_s - previous_time_s;
            for (i, limit) in self.velocity_limits.iter().enumerate() {
                let speed = (q[i] - previous[i]).abs() / elapsed;
                let allowed = fraction * limit;
                if !within(speed, allowed * (1.0 + SLACK)) {
                    return Err(CheckFailure::at(
                        k,
                        FailedCheck::JointSpeed { joint: i + 1 },
                        format!(
                            "joint {} moves at {speed} rad/s, above {allowed} rad/s",
                            i + 1
                        ),
                    ));
                }
            }
        }
        Ok(())
    }

    /// The progress of the last point walked (0 before any).
    fn reached(&self) -> f64 {
        self.progress.last().copied().unwrap_or(0.0)
    }

    /// After all `count` points: a motion claiming the path's end reaches it, and the
    /// reported path length is the last point's.
    fn check_length(&self, count: usize) -> Result<(), CheckFailure> {
        let line = self.line;
        let (length, claimed) = match self.points {
            Points::Recorded(recording) => (
                line.reached(recording.steps.iter().map(|step| step.tcp)),
                recording.path_length_m,
            ),
            // The TCPs are the checker's, and so is the length claimed.
            Points::Samples { .. } => {
                let reached = self.reached();
                (reached, reached)
            }
        };
        if let (Ending::Completed, Some(path_length)) = (self.points.ending(), line.path_length())
            && !within(path_length - PATH_END_SLACK_M, length)
        {
            return Err(CheckFailure::at(
                count - 1,
                FailedCheck::Ending,
                format!("claims the end of the path ({path_length} m) but reaches {length} m"),
            ));
        }
        if !within((length - claimed).abs(), SLACK) {
            return Err(CheckFailure::at(
                count - 1,
                FailedCheck::PathLength,
                format!("reported path length {claimed} but the last step gives {length}"),
            ));
        }
        Ok(())
    }

    /// After all `count` points: the configuration a rejection or an invalid start blames
    /// really breaks the constraint it is blamed on.
    fn check_blame(&self, count: usize) -> Result<(), CheckFailure> {
        let blamed = match self.points.ending() {
            Ending::Rejected { blame, rejected_q } => Some((blame, *rejected_q)),
            Ending::InvalidStart { blame } => Some((blame, *self.points.joints(0))),
            Ending::Stopped | Ending::Completed => None,
        };
        if let Some((blame, q)) = blamed
            && !self
                .model
                .breaks(self.line, &q, blame, self.bounds, self.reached())
        {
            return Err(CheckFailure::at(
                count,
                FailedCheck::Ending,
                format!("the final configuration does not break {blame:?}"),
            ));
        }
        Ok(())
    }

    /// What the walk measured, the smallest clearance named by its links.
    fn measured(self) -> Measured {
        Measured {
            min_clearance: self.model.clearance_names(self.min_clearance),
            progress: self.progress,
            max_line_deviation_m: self.max_line_deviation_m,
            max_tool_angle_deg: self.max_tool_angle_deg,
        }
    }
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
        let mut walk = PointWalk::new(self, line, points, bounds);
        let count = points.count();
        let valid_steps = checked_steps(count, points.ending())?;
        for k in 0..count {
            walk.step(k, k < valid_steps)?;
        }
        walk.check_length(count)?;
        walk.check_blame(count)?;
        Ok(walk.measured())
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
