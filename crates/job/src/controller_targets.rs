//! The targets a program for a robot's own controller is written through, chosen from a job's
//! plan whatever the controller's language (a Universal Robots program, an ABB RAPID module):
//! the controller moves the tool itself, with its own kinematics and corner blending, so the
//! targets are chosen such that what it interpolates between them stays with the plan.
//!
//! * A stroke part: the poses of some of the plan's configurations, each straight line between
//!   two of them and each corner's path within [`CHORD_SHARE`] of the stroke's line tolerance,
//!   its tool axis within the cone, and no joint of the plan turning more than
//!   [`MAX_TARGET_TURN_RAD`] between two targets (so a controller that solves each pose from
//!   the configuration it stands at follows the plan's branch); with the corner radius at
//!   each inner target (a blend's or a zone's) and the plan's tool speed into each.
//! * A move between strokes: the plan's joint vertices where each edge is free, else its samples
//!   thinned to free edges within [`MOVE_DEVIATION_RAD`]; the lift and the set-down straight
//!   lines where the tool keeps its orientation; each joint-move corner blended within a radius
//!   whose joint-space triangle is free.

use emg_control::{Task, tool_angle_deg};
use emg_kinematics::{JointVector, Robot, Vec3};
use nalgebra::{Matrix3, Rotation3, UnitQuaternion};

use crate::free_space::FreeSpace;
use crate::program::{JobFile, SegmentKind};
use crate::reach::WristReach;

/// Share of the line tolerance that the path the controller interpolates (each straight line
/// between two targets of a stroke, each corner's path) may lie from the stroke: the rest is
/// left to the controller's tracking.
pub const CHORD_SHARE: f64 = 0.9;
/// Points of a corner's path checked against the stroke.
const CORNER_POINTS: usize = 16;
/// Halvings of a corner's radius tried before the corner is left sharp (the tool stops there).
const BLEND_HALVINGS: usize = 12;
/// A corner's radius is at most this share of the shorter of the two lines it joins, so that no
/// two corners overlap and none reaches half a line.
pub const BLEND_LENGTH_SHARE: f64 = 0.45;
/// Most any joint of the plan turns between two targets of a stroke (rad).
pub const MAX_TARGET_TURN_RAD: f64 = 0.1;
/// Largest distance (rad) of the plan's path from a joint move's edge where a move's own
/// polyline is not free and its samples are thinned instead.
pub const MOVE_DEVIATION_RAD: f64 = 0.01;
/// An edge off a stroke's end or onto a stroke's start is a straight line where the tool turns
/// less than this along it (rad).
pub const LIFT_TURN_RAD: f64 = 0.01;
/// A joint move's corner radius (m, the TCP's distance from the corner where the blend begins
/// and ends) is at most this share of the TCP's straight distance to either neighbouring
/// vertex.
pub const JOINT_BLEND_LENGTH_SHARE: f64 = 0.4;
/// The largest corner radius of a joint move (m).
pub const MAX_JOINT_BLEND_M: f64 = 0.05;
/// The smallest corner radius written (m): below it the corner is left sharp.
pub const MIN_BLEND_M: f64 = 1e-4;
/// Step (rad, the joint moving most) at which an edge is scanned for where the TCP comes
/// within a corner radius of its end.
const SCAN_STEP_RAD: f64 = 0.005;

/// A pose of the tool: position (m) and orientation.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Pose {
    pub(crate) position: Vec3,
    pub(crate) rotation: UnitQuaternion<f64>,
}

impl Pose {
    /// The TCP pose of `q`.
    pub(crate) fn of(robot: &Robot, q: &JointVector) -> Self {
        let kinematics = robot.forward(q);
        Self::from_matrix(kinematics.tcp(), kinematics.tcp_rotation())
    }

    /// The pose at `position` turned by `rotation`.
    pub(crate) fn from_matrix(position: Vec3, rotation: &Matrix3<f64>) -> Self {
        Self {
            position,
            rotation: UnitQuaternion::from_rotation_matrix(&Rotation3::from_matrix(rotation)),
        }
    }
}

/// The path a controller's tool takes through a target it does not stop at, starting where the
/// tool comes within the corner's radius of it on the line in and ending as far along the line
/// out, the orientation slerped between the lines' at those two points.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum Corner {
    /// A circular arc tangent to both lines (URScript's `movep` blend).
    Arc,
    /// The parabola tangent to both lines there: the quadratic Bézier curve with the target as
    /// its middle control point, inside the triangle of the two ends and the target (ABB's
    /// corner path through a zone).
    Parabola,
}

impl Corner {
    /// The poses along the corner of `radius` at `b` between the lines `a`–`b` and `b`–`c`:
    /// [`CORNER_POINTS`] + 1 poses, both ends included (just those two where the lines run
    /// straight on).
    pub(crate) fn path(self, [a, b, c]: [&Pose; 3], radius: f64) -> Vec<Pose> {
        match self {
            Self::Arc => blend_arc([a, b, c], radius),
            Self::Parabola => corner_parabola([a, b, c], radius),
        }
    }
}

/// One segment of a job's program as a controller's program is written from it: a comment
/// line's text saying what it is, and the segment.
pub(crate) enum Step<'a> {
    /// A stroke part: its samples' configurations along its task.
    Stroke {
        comment: String,
        qs: &'a [JointVector],
        task: &'a Task,
    },
    /// A move between strokes (a lift, a set-down, a move): its joint vertices and samples,
    /// whether it starts at a stroke's end and whether it ends at a stroke's start.
    Move {
        comment: String,
        vertices: Vec<JointVector>,
        qs: &'a [JointVector],
        off_stroke: bool,
        onto_stroke: bool,
    },
}

/// The configurations of every sample of each segment of `file`.
pub(crate) fn segment_configurations(file: &JobFile) -> Vec<Vec<JointVector>> {
    file.segments
        .iter()
        .map(|segment| {
            file.segment_samples(segment)
                .iter()
                .map(|sample| sample.q)
                .collect()
        })
        .collect()
}

/// Each segment of `file` (whose samples' configurations are `samples`, from
/// [`segment_configurations`]) as a [`Step`] for `robot`, in order, to `visit`; the index of a
/// stroke segment without its task, where one is.
pub(crate) fn walk<'a>(
    file: &'a JobFile,
    robot: &Robot,
    samples: &'a [Vec<JointVector>],
    mut visit: impl FnMut(Step<'a>),
) -> Result<(), usize> {
    let is_stroke = |index: usize| {
        file.segments
            .get(index)
            .is_some_and(|s| matches!(s.kind, SegmentKind::Stroke { .. }))
    };
    for (index, (segment, qs)) in file.segments.iter().zip(samples).enumerate() {
        let duration = segment.end_s - segment.start_s;
        match segment.kind {
            SegmentKind::Stroke {
                stroke,
                part,
                from_s,
                backward,
            } => {
                let task = segment.task.as_ref().ok_or(index)?;
                let way = if backward {
                    " back toward its start"
                } else {
                    ""
                };
                visit(Step::Stroke {
                    comment: format!(
                        "stroke {stroke}, part {part}: from {from_s:.4} m along it{way}, \
                         {duration:.3} s"
                    ),
                    qs,
                    task,
                });
            }
            kind => {
                let what = match kind {
                    SegmentKind::Retreat => "lift",
                    SegmentKind::Approach => "set-down",
                    _ => "move",
                };
                visit(Step::Move {
                    comment: format!("{what}: {duration:.3} s in the plan"),
                    vertices: segment
                        .vertices
                        .iter()
                        .map(|v| robot.joint_vector(v))
                        .collect(),
                    qs,
                    off_stroke: index > 0 && is_stroke(index - 1),
                    onto_stroke: is_stroke(index + 1),
                });
            }
        }
    }
    Ok(())
}

/// How a program's targets are chosen for one job: its arm and space, the stroke's tolerances,
/// the plan's rate and tool speed, and the controller's corner path.
pub(crate) struct TargetRules<'a> {
    pub(crate) robot: &'a Robot,
    pub(crate) free: &'a FreeSpace<'a>,
    /// The strokes' line tolerance (m).
    pub(crate) tolerance: f64,
    /// The tool's cone about the part's normal (degrees).
    pub(crate) cone_deg: f64,
    /// The plan's sampling rate (Hz).
    pub(crate) rate_hz: f64,
    /// The plan's tool speed (m/s).
    pub(crate) tool_speed: f64,
    pub(crate) corner: Corner,
    /// How far the arm reaches, where every point of the controller's path is held within it.
    pub(crate) reach: Option<WristReach>,
}

impl<'a> TargetRules<'a> {
    /// The rules of `file`'s program on `robot` in the space `free`: the job's tolerances, rate
    /// and tool speed, the controller's `corner` path, and its `reach` where it holds every
    /// point of its path within one.
    pub(crate) fn for_job(
        file: &JobFile,
        (robot, free): (&'a Robot, &'a FreeSpace<'a>),
        corner: Corner,
        reach: Option<WristReach>,
    ) -> Self {
        Self {
            robot,
            free,
            tolerance: file.constraints.line_tolerance_m,
            cone_deg: file.constraints.theta_max_deg,
            rate_hz: file.rate_hz,
            tool_speed: file.limits.tool_speed_m_per_s,
            corner,
            reach,
        }
    }
}

/// What a controller's program says for each step of a job, as an industrial controller's
/// writer (RAPID, KRL) says it.
pub(crate) trait StepWriter {
    /// The rules its targets are chosen by.
    fn rules(&self) -> &TargetRules<'_>;
    /// A comment line.
    fn comment(&mut self, text: &str);
    /// A stroke part whose samples are `qs`, along `task`, from rest on its start.
    fn stroke(&mut self, qs: &[JointVector], task: &Task);
    /// A straight move of the tool to the pose of `q` at `speed` (m/s), stopping there.
    fn straight_move(&mut self, q: &JointVector, speed: f64);
    /// A joint move to `q`, its corner radius `radius` (m) there.
    fn joint_move(&mut self, q: &JointVector, radius: f64);
}

/// Each segment of `file` (its samples' configurations `samples`) written by `writer`: a
/// comment, then a stroke part, or a move's targets ([`TargetRules::free_move`]); the index of a
/// stroke segment without its task, where one is.
pub(crate) fn write_steps(
    file: &JobFile,
    robot: &Robot,
    samples: &[Vec<JointVector>],
    writer: &mut impl StepWriter,
) -> Result<(), usize> {
    walk(file, robot, samples, |step| match step {
        Step::Stroke { comment, qs, task } => {
            writer.comment(&comment);
            writer.stroke(qs, task);
        }
        Step::Move {
            comment,
            vertices,
            qs,
            off_stroke,
            onto_stroke,
        } => {
            writer.comment(&comment);
            let targets = writer
                .rules()
                .free_move(&vertices, qs, off_stroke, onto_stroke);
            let speed = writer.rules().tool_speed;
            for target in targets {
                if target.straight {
                    writer.straight_move(&target.q, speed);
                } else {
                    writer.joint_move(&target.q, target.radius);
                }
            }
        }
    })
}

/// A stroke part's targets: the pose of each of the plan's samples, the samples kept as
/// targets (the first and the last among them), the corner radius at each kept sample (0 at
/// the two ends and where the corner stays sharp), and the tool speed into each (none into the
/// first).
pub(crate) struct StrokeRun {
    pub(crate) poses: Vec<Pose>,
    pub(crate) kept: Vec<usize>,
    /// Per kept sample (m).
    pub(crate) radii: Vec<f64>,
    /// Per kept sample (m/s): the plan's fastest tool speed on the way to it, at most the tool
    /// speed; 0 for the first.
    pub(crate) speeds: Vec<f64>,
    /// The largest distance (m) from the stroke of the straight lines between the targets.
    pub(crate) worst_chord_m: f64,
}

/// One target of a move between strokes.
pub(crate) struct FreeTarget {
    pub(crate) q: JointVector,
    /// Reached by a straight line of the tool (a lift or a set-down), else by a joint move.
    pub(crate) straight: bool,
    /// The corner radius (m) at it: 0 where the tool stops there.
    pub(crate) radius: f64,
}

/// Whether a TCP pose is within the arm's reach, given a configuration of the plan near it.
type Reachable<'a> = &'a dyn Fn(&Pose, &JointVector) -> bool;

impl TargetRules<'_> {
    /// The targets of the stroke part whose samples are `qs`, along `task`.
    pub(crate) fn stroke(&self, qs: &[JointVector], task: &Task) -> StrokeRun {
        let poses: Vec<Pose> = qs.iter().map(|q| Pose::of(self.robot, q)).collect();
        // Each sample's progress along the task, followed from its start as a reader follows
        // the program's poses.
        let mut s = 0.0;
        let progress: Vec<f64> = poses
            .iter()
            .map(|pose| {
                s = task.along(&pose.position, s).s_m;
                s
            })
            .collect();
        let reachable = |pose: &Pose, near: &JointVector| {
            self.reach
                .is_none_or(|reach| reach.holds(self.robot, (&pose.position, &pose.rotation), near))
        };
        let (kept, worst_chord_m) = stroke_targets(
            &poses,
            &progress,
            qs,
            task,
            (self.tolerance, self.cone_deg),
            &reachable,
        );
        let radii = (0..kept.len())
            .map(|n| {
                if n == 0 || n + 1 == kept.len() {
                    return 0.0;
                }
                let (i, j, m) = (kept[n - 1], kept[n], kept[n + 1]);
                blend_radius(
                    [&poses[i], &poses[j], &poses[m]],
                    [progress[i], progress[j]],
                    task,
                    (self.tolerance, self.cone_deg),
                    (self.corner, &reachable, &qs[j]),
                )
            })
            .collect();
        let speeds = (0..kept.len())
            .map(|n| {
                if n == 0 {
                    return 0.0;
                }
                poses[kept[n - 1]..=kept[n]]
                    .windows(2)
                    .map(|w| (w[1].position - w[0].position).norm() * self.rate_hz)
                    .fold(0.0, f64::max)
                    .min(self.tool_speed)
                    .max(1e-4)
            })
            .collect();
        StrokeRun {
            poses,
            kept,
            radii,
            speeds,
            worst_chord_m,
        }
    }

    /// The targets of a move between strokes (or from or to home) through `vertices`, whose
    /// samples are `qs`, the configuration it starts from left out; `off_stroke` where it starts
    /// at a stroke's end, `onto_stroke` where it ends at a stroke's start.
    pub(crate) fn free_move(
        &self,
        vertices: &[JointVector],
        qs: &[JointVector],
        off_stroke: bool,
        onto_stroke: bool,
    ) -> Vec<FreeTarget> {
        let polyline_free = vertices.len() >= 2
            && vertices
                .windows(2)
                .all(|edge| self.free.edge_free(&edge[0], &edge[1]));
        let path: Vec<JointVector> = if polyline_free {
            vertices.to_vec()
        } else {
            thinned_joint_path(self.free, qs)
        };
        let edges = path.len().saturating_sub(1);
        // Whether each edge is a straight lift or set-down, else a joint move.
        let straight: Vec<bool> = path
            .windows(2)
            .enumerate()
            .map(|(k, edge)| {
                let at_surface = (off_stroke && k == 0) || (onto_stroke && k + 1 == edges);
                at_surface && self.turn(&edge[0], &edge[1]) < LIFT_TURN_RAD
            })
            .collect();
        (0..edges)
            .map(|k| {
                let target = path[k + 1];
                // A corner between two joint moves is blended where the triangle it cuts is
                // free.
                let radius = match (straight[k], straight.get(k + 1), path.get(k + 2)) {
                    (false, Some(false), Some(next)) => {
                        self.joint_blend_radius(&path[k], &target, next)
                    }
                    _ => 0.0,
                };
                FreeTarget {
                    q: target,
                    straight: straight[k],
                    radius,
                }
            })
            .collect()
    }

    /// The corner radius (m) of the joint-move corner `w` between the joint-space edges from
    /// `a` and to `b`: at most [`JOINT_BLEND_LENGTH_SHARE`] of the TCP's distance from `w` to
    /// either and [`MAX_JOINT_BLEND_M`], halved until the joint-space triangle between where
    /// the TCP comes within it of `w` on each edge ([`TargetRules::entering`]) and `w` is free
    /// ([`FreeSpace::triangle_free`]): any blend the controller makes there keeps inside that
    /// triangle. 0 (no blend) where no radius of at least [`MIN_BLEND_M`] is.
    fn joint_blend_radius(&self, a: &JointVector, w: &JointVector, b: &JointVector) -> f64 {
        let tcp = |q: &JointVector| self.robot.forward(q).tcp();
        let corner = tcp(w);
        let mut radius = (JOINT_BLEND_LENGTH_SHARE
            * (tcp(a) - corner).norm().min((tcp(b) - corner).norm()))
        .min(MAX_JOINT_BLEND_M);
        while radius >= MIN_BLEND_M {
            let (entry, exit) = (self.entering(a, w, radius), self.entering(b, w, radius));
            if self.free.triangle_free(&entry, w, &exit) {
                return radius;
            }
            radius /= 2.0;
        }
        0.0
    }

    /// The configuration on the joint-space edge from `from` to `w` one scan step
    /// ([`SCAN_STEP_RAD`]) before the first one scanned whose TCP lies within `radius` of `w`'s:
    /// at or before where a blend of that radius at `w` can begin.
    fn entering(&self, from: &JointVector, w: &JointVector, radius: f64) -> JointVector {
        let corner = self.robot.forward(w).tcp();
        let steps = ((w - from).amax() / SCAN_STEP_RAD).ceil().max(1.0) as usize;
        let at = |k: usize| from + (w - from) * (k as f64 / steps as f64);
        let first = (0..=steps)
            .find(|&k| (self.robot.forward(&at(k)).tcp() - corner).norm() <= radius)
            .unwrap_or(steps);
        at(first.saturating_sub(1))
    }

    /// The angle (rad) the tool turns from `a` to `b`.
    fn turn(&self, a: &JointVector, b: &JointVector) -> f64 {
        let (a, b) = (Pose::of(self.robot, a), Pose::of(self.robot, b));
        a.rotation.angle_to(&b.rotation)
    }
}

/// The largest `j` after `i` (up to `last`) for which `fits(j)`, found by doubling the step
/// then halving it; `i + 1` at least.
fn furthest(i: usize, last: usize, mut fits: impl FnMut(usize) -> bool) -> usize {
    let mut good = i + 1;
    let mut step = 1;
    let mut bad = None;
    while good < last {
        let j = (good + step).min(last);
        if fits(j) {
            good = j;
            step *= 2;
        } else {
            bad = Some(j);
            break;
        }
    }
    if let Some(mut bad) = bad {
        while bad - good > 1 {
            let middle = good + (bad - good) / 2;
            if fits(middle) {
                good = middle;
            } else {
                bad = middle;
            }
        }
    }
    good
}

/// The indices of the stroke's samples kept as targets (the first and the last among them) and
/// the largest distance from the stroke found on the lines between them: each line within
/// [`CHORD_SHARE`] of the `tolerance` of `task` and its slerped tool axis within `cone_deg` at
/// every sample between its ends (taken at the sample's projection on it) and at its end,
/// measured from the path point reached, the progress followed along the line from the
/// samples' progress (`progress`) at its start as the reader follows it, as well as from the
/// whole path; following the line reaches as far along the stroke as the samples do at its end
/// (a line that cuts a corner short of where the samples turned would leave the reader's
/// progress before the corner); no joint turns more than [`MAX_TARGET_TURN_RAD`] from its
/// start to any sample up to its end; and each point taken is `reachable` (with the sample's
/// configuration as the one near it). The line between two neighbouring samples is followed
/// as the samples are; where even it does not fit, it is kept ([`furthest`]).
pub(crate) fn stroke_targets(
    poses: &[Pose],
    progress: &[f64],
    qs: &[JointVector],
    task: &Task,
    (tolerance, cone_deg): (f64, f64),
    reachable: Reachable<'_>,
) -> (Vec<usize>, f64) {
    let last = poses.len().saturating_sub(1);
    let mut kept = vec![0];
    let mut worst: f64 = 0.0;
    // The largest distance from the stroke of the line from `i` to `j`, if it fits.
    let line = |i: usize, j: usize| -> Option<f64> {
        let (a, b) = (poses[i].position, poses[j].position);
        let chord = b - a;
        let length2 = chord.norm_squared();
        let mut largest: f64 = 0.0;
        let mut s = progress[i];
        for k in i + 1..=j {
            if (qs[k] - qs[i]).amax() > MAX_TARGET_TURN_RAD {
                return None;
            }
            let u = if k == j {
                1.0
            } else if length2 > 0.0 {
                ((poses[k].position - a).dot(&chord) / length2).clamp(0.0, 1.0)
            } else {
                0.0
            };
            let point = a + chord * u;
            let along = task.along(&point, s);
            s = along.s_m;
            let distance = task.distance(&point).max(along.lateral.norm());
            let rotation = poses[i]
                .rotation
                .try_slerp(&poses[j].rotation, u, 1e-12)
                .unwrap_or(poses[i].rotation);
            let axis = rotation * Vec3::z();
            if distance > CHORD_SHARE * tolerance
                || tool_angle_deg(&axis, &task.n) > cone_deg
                || !reachable(
                    &Pose {
                        position: point,
                        rotation,
                    },
                    &qs[k],
                )
            {
                return None;
            }
            largest = largest.max(distance);
        }
        (s >= progress[j] - SAME_PROGRESS_M).then_some(largest)
    };
    let mut i = 0;
    while i < last {
        let j = furthest(i, last, |j| line(i, j).is_some());
        worst = worst.max(line(i, j).unwrap_or(0.0));
        kept.push(j);
        i = j;
    }
    (kept, worst)
}

/// How far (m) following a line between two targets may end behind the samples' progress at
/// its end and still count as reaching it (rounding only).
const SAME_PROGRESS_M: f64 = 1e-9;

/// The radius of the blend at target `j` between the lines from target `i` and to target `m`
/// (m): at most [`BLEND_LENGTH_SHARE`] of the shorter line, halved until its corner path
/// ([`Corner::path`]) lies within [`CHORD_SHARE`] of the `tolerance` of `task` (measured from the path point
/// reached, followed along the arc from `from_s`, the progress at `a`, and from the whole path)
/// and its tool axis within `cone_deg` of the task's normal, the progress followed to its end
/// reaching `at_b_s`, the samples' progress at `b` (an arc that turns short of a corner the
/// samples came to would leave the reader's progress before it), and every pose `reachable`
/// near the configuration `near` at `b`; 0 (no blend) where no radius tried does.
fn blend_radius(
    [a, b, c]: [&Pose; 3],
    [from_s, at_b_s]: [f64; 2],
    task: &Task,
    (tolerance, cone_deg): (f64, f64),
    (corner, reachable, near): (Corner, Reachable<'_>, &JointVector),
) -> f64 {
    let shorter = (b.position - a.position)
        .norm()
        .min((c.position - b.position).norm());
    let mut radius = BLEND_LENGTH_SHARE * shorter;
    for _ in 0..BLEND_HALVINGS {
        let mut s = from_s;
        let fits = corner.path([a, b, c], radius).iter().all(|pose| {
            let along = task.along(&pose.position, s);
            s = along.s_m;
            task.distance(&pose.position).max(along.lateral.norm()) <= CHORD_SHARE * tolerance
                && tool_angle_deg(&(pose.rotation * Vec3::z()), &task.n) <= cone_deg
                && reachable(pose, near)
        });
        if fits && s >= at_b_s - SAME_PROGRESS_M {
            return radius;
        }
        radius /= 2.0;
    }
    0.0
}

/// The poses along the blend of radius `radius` at `b` between the lines `a`–`b` and `b`–`c`,
/// as `movep` blends: a circular arc tangent to both lines at `radius` from `b`, the orientation
/// slerped between those of the lines at the two tangent points; [`CORNER_POINTS`] + 1 poses,
/// both tangent points included (just those two where the lines run straight on).
fn blend_arc([a, b, c]: [&Pose; 3], radius: f64) -> Vec<Pose> {
    let entry = pose_along(b, a, radius);
    let exit = pose_along(b, c, radius);
    let (into, out) = (
        (b.position - entry.position).normalize(),
        (exit.position - b.position).normalize(),
    );
    let turn = libm::atan2(into.cross(&out).norm(), into.dot(&out));
    let rotation = |t: f64| {
        entry
            .rotation
            .try_slerp(&exit.rotation, t, 1e-12)
            .unwrap_or(entry.rotation)
    };
    if turn < 1e-9 || radius <= 0.0 {
        return vec![entry, exit];
    }
    // The arc's centre lies inside the corner, on its bisector, radius / cos α from `b`.
    let half_opening = (std::f64::consts::PI - turn) / 2.0;
    let bisector = (out - into).normalize();
    let centre = b.position + bisector * (radius / libm::cos(half_opening));
    let (from, to) = (entry.position - centre, exit.position - centre);
    (0..=CORNER_POINTS)
        .map(|k| {
            let t = k as f64 / CORNER_POINTS as f64;
            let position = centre
                + (from * libm::sin((1.0 - t) * turn) + to * libm::sin(t * turn)) / libm::sin(turn);
            Pose {
                position,
                rotation: rotation(t),
            }
        })
        .collect()
}

/// The samples `qs` of a move thinned to the vertices of a joint-space polyline whose every
/// edge is free ([`FreeSpace::edge_free`]) and within [`MOVE_DEVIATION_RAD`] of the samples
/// between its ends (both ends kept; the first sample left out, as the arm stands there).
pub(crate) fn thinned_joint_path(free: &FreeSpace<'_>, qs: &[JointVector]) -> Vec<JointVector> {
    let last = qs.len().saturating_sub(1);
    let fits = |i: usize, j: usize| {
        let chord = qs[j] - qs[i];
        let length2 = chord.norm_squared();
        (i + 1..j).all(|k| {
            let offset = qs[k] - qs[i];
            let u = if length2 > 0.0 {
                (offset.dot(&chord) / length2).clamp(0.0, 1.0)
            } else {
                0.0
            };
            (offset - chord * u).norm() <= MOVE_DEVIATION_RAD
        }) && free.edge_free(&qs[i], &qs[j])
    };
    let mut path = vec![qs[0]];
    let mut i = 0;
    while i < last {
        let j = furthest(i, last, |j| fits(i, j));
        path.push(qs[j]);
        i = j;
    }
    path
}

/// The poses along the parabola through the corner of `radius` at `b` between the lines
/// `a`–`b` and `b`–`c` ([`Corner::Parabola`]): the quadratic Bézier curve from the point
/// `radius` before `b` on the line in, with `b` as its control point, to the point `radius`
/// after it on the line out (tangent to both lines there), the orientation slerped between the
/// lines' at those two points; [`CORNER_POINTS`] + 1 poses, both ends included.
fn corner_parabola([a, b, c]: [&Pose; 3], radius: f64) -> Vec<Pose> {
    let entry = pose_along(b, a, radius);
    let exit = pose_along(b, c, radius);
    (0..=CORNER_POINTS)
        .map(|k| {
            let t = k as f64 / CORNER_POINTS as f64;
            let position = entry.position * ((1.0 - t) * (1.0 - t))
                + b.position * (2.0 * t * (1.0 - t))
                + exit.position * (t * t);
            Pose {
                position,
                rotation: entry
                    .rotation
                    .try_slerp(&exit.rotation, t, 1e-12)
                    .unwrap_or(entry.rotation),
            }
        })
        .collect()
}

/// The pose `distance` from `from` toward `to` on the line between them, its orientation
/// slerped in proportion.
fn pose_along(from: &Pose, to: &Pose, distance: f64) -> Pose {
    let length = (to.position - from.position).norm();
    let u = if length > 0.0 { distance / length } else { 0.0 };
    Pose {
        position: from.position + (to.position - from.position) * u,
        rotation: from
            .rotation
            .try_slerp(&to.rotation, u, 1e-12)
            .unwrap_or(from.rotation),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_furthest_fitting_index_is_found_by_doubling_then_halving() {
        for limit in 1..40 {
            assert_eq!(furthest(0, 37, |j| j <= limit), limit.clamp(1, 37));
        }
        assert_eq!(furthest(5, 6, |_| false), 6);
    }

    fn pose(x: f64, y: f64) -> Pose {
        Pose {
            position: Vec3::new(x, y, 0.0),
            rotation: UnitQuaternion::identity(),
        }
    }

    #[test]
    fn a_blend_is_an_arc_tangent_to_both_lines_at_its_radius() {
        let (a, b) = (pose(-0.01, 0.0), pose(0.0, 0.0));
        for degrees in [10.0_f64, 45.0, 90.0, 135.0] {
            let turn = degrees.to_radians();
            let c = pose(0.02 * libm::cos(turn), 0.02 * libm::sin(turn));
            let arc = Corner::Arc.path([&a, &b, &c], 0.004);
            let (first, last) = (arc[0].position, arc[arc.len() - 1].position);
            assert!(
                (first - Vec3::new(-0.004, 0.0, 0.0)).norm() < 1e-12,
                "{degrees}°"
            );
            assert!((last - c.position * 0.2).norm() < 1e-12, "{degrees}°");
            // Every point equally far from one centre, on the bisector inside the corner.
            let middle = arc[CORNER_POINTS / 2].position;
            let radius_of = |p: Vec3| {
                let half = (std::f64::consts::PI - turn) / 2.0;
                let bisector = ((c.position - b.position).normalize() - Vec3::x()).normalize();
                (p - bisector * (0.004 / libm::cos(half))).norm()
            };
            for point in &arc {
                assert!((radius_of(point.position) - radius_of(first)).abs() < 1e-12);
            }
            assert!(middle.norm() < 0.004, "{degrees}°: the arc cuts the corner");
        }
    }

    #[test]
    fn a_zone_corner_is_a_parabola_inside_the_triangle_tangent_to_both_lines() {
        let (a, b) = (pose(-0.01, 0.0), pose(0.0, 0.0));
        for degrees in [10.0_f64, 45.0, 90.0, 135.0] {
            let turn = degrees.to_radians();
            let out = Vec3::new(libm::cos(turn), libm::sin(turn), 0.0);
            let c = pose(0.02 * out.x, 0.02 * out.y);
            let path = Corner::Parabola.path([&a, &b, &c], 0.004);
            let (entry, exit) = (Vec3::new(-0.004, 0.0, 0.0), out * 0.004);
            assert!((path[0].position - entry).norm() < 1e-12, "{degrees}°");
            assert!(
                (path[CORNER_POINTS].position - exit).norm() < 1e-12,
                "{degrees}°"
            );
            // Tangent to the line in at its start and to the line out at its end.
            let start = (path[1].position - path[0].position).normalize();
            let end = (path[CORNER_POINTS].position - path[CORNER_POINTS - 1].position).normalize();
            assert!(start.dot(&Vec3::x()) > libm::cos(turn / CORNER_POINTS as f64 * 1.01));
            assert!(end.dot(&out) > libm::cos(turn / CORNER_POINTS as f64 * 1.01));
            // Inside the triangle (entry, b, exit): on the inner side of both lines and of the
            // chord, so within `radius` of the target.
            for point in &path {
                assert!(point.position.norm() <= 0.004 + 1e-12, "{degrees}°");
                let chord = exit - entry;
                let side = chord.cross(&(point.position - entry)).z;
                assert!(side <= 1e-15, "{degrees}°: beyond the chord");
            }
        }
    }
}
