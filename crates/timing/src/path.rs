//! The smooth joint path of a planned motion: a natural cubic spline through every
//! [`KNOT_STRIDE`]-th waypoint, on request of the waypoints with their postures evened out
//! (the controller's step-to-step jitter left out, so the joints' accelerations along the path
//! stay low, every TCP kept), each inner one moved a hair inside the joint limits,
//! clear of the arm's own links and inside the tool cone ([`crate::inset`]), parametrised by
//! the distance the TCP travels between waypoints, checked against every task constraint on a
//! dense sampling and refined where it fails.

use emg_control::{ConstraintConfig, Task, Violation, first_violation, onto_task};
use emg_kinematics::{DampingConfig, JointVector, Robot, Vec3, damped_pseudo_inverse};

use crate::inset::{inset, tool_angle_gradient};
use crate::spline::JointSpline;

/// The spline passes through every this many waypoints (and the last).
pub const KNOT_STRIDE: usize = 3;

/// Points checked inside each spline segment (besides its two knots, which are waypoints).
pub const CHECKS_PER_SEGMENT: usize = 16;

/// Knots inserted at most, in all, while refining a path.
pub const MAX_REFINEMENTS: usize = 64;

/// Smallest path-parameter step between waypoints (m): waypoints whose TCPs lie closer than
/// this are a step apart by this much, so the knots increase strictly.
pub const MIN_KNOT_STEP_M: f64 = 1e-6;

/// Smallest path-parameter step per radian of the fastest joint between two waypoints (m/rad):
/// where the arm turns through a singularity while its TCP barely moves (a six-joint arm's
/// wrist), the parameter still advances with the joints, so the spline's joint derivatives per
/// metre of parameter stay bounded and the timing finite. A step of the line speed moves the
/// joints far less than the TCP distance over this, so ordinary steps keep the TCP distance.
pub const KNOT_STEP_M_PER_RAD: f64 = 0.05;

/// A joint path `q(s)` that holds the task's constraints at every checked point.
#[derive(Clone, Debug)]
pub struct SmoothPath {
    /// The spline; `None` for a path of a single configuration (no motion).
    spline: Option<JointSpline>,
    /// The configuration of a path without motion.
    start: JointVector,
    /// Knots added (skipped waypoints put back, chord midpoints) to make the spline hold the
    /// constraints.
    pub refined_knots: usize,
    /// Where the spline had to end early: the waypoint (index into the given waypoints) it ends
    /// at, and the constraint the spline broke beyond it.
    pub cut: Option<(usize, Violation)>,
}

impl SmoothPath {
    /// The smooth path through `waypoints` (each holding the constraints, as a rollout's steps
    /// do), where `even_postures` asks for it their postures evened out first (every TCP kept:
    /// each inner one replaced by the mean `(q[k-1] + 2 q[k] + q[k+1]) / 4`
    /// [`SMOOTHING_ROUNDS`] times, then moved until its TCP lies where the waypoint's did). The
    /// parameter of waypoint `k` is the TCP distance travelled along the polyline of the
    /// waypoints' TCPs (at least [`MIN_KNOT_STEP_M`], and [`KNOT_STEP_M_PER_RAD`] times the
    /// largest joint change, per step); the spline passes through the first, every
    /// [`KNOT_STRIDE`]-th and the last waypoint, each inner one moved
    /// [`JOINT_INSET_RAD`](crate::JOINT_INSET_RAD) inside the joint limits, about its TCP to
    /// [`CLEARANCE_INSET_M`](crate::CLEARANCE_INSET_M) clear of the arm's own links and to
    /// [`CONE_INSET_DEG`](crate::CONE_INSET_DEG) inside the tool cone where it lies closer to
    /// them (when the moved configuration holds every constraint). It is checked at
    /// [`CHECKS_PER_SEGMENT`] points inside each segment, at the joints' turning points and at
    /// the peaks of the tool angle and of the distance from the line or path; a segment that
    /// breaks a constraint gets back the middle waypoint it skipped, or, between consecutive
    /// waypoints, their chord midpoint (moved onto the line or path where it lies more than
    /// half the tolerance off, [`onto_task`], on a path toward the point its progress reaches
    /// from the segment's first knot's) moved likewise as a new knot (when that holds the
    /// constraints and the two lie [`MIN_KNOT_STEP_M`] apart at least twice over, up to
    /// [`MAX_REFINEMENTS`] midpoints in all), else the path ends at the segment's first
    /// waypoint.
    ///
    /// On a path the TCP's distance is measured from the path point its progress has reached
    /// ([`Task::along`]), followed from `from_s` (the first waypoint's progress) knot by knot,
    /// so that no point of the spline counts as on the path by lying near a stretch of it the
    /// motion has not yet reached (the other leg of a reversal).
    ///
    /// # Panics
    ///
    /// If `waypoints` is empty.
    pub fn fit(
        robot: &Robot,
        task: &Task,
        constraints: &ConstraintConfig,
        waypoints: &[JointVector],
        from_s: f64,
        even_postures: bool,
    ) -> Self {
        assert!(!waypoints.is_empty(), "a path needs a waypoint");
        let valid = |q: &JointVector| {
            first_violation(robot, task, &robot.forward(q), constraints).is_none()
        };
        let smoothed_path;
        let waypoints = if even_postures {
            smoothed_path = smoothed(robot, task, constraints, waypoints);
            &smoothed_path[..]
        } else {
            waypoints
        };
        let mut params = Vec::with_capacity(waypoints.len());
        let mut previous = (waypoints[0], robot.forward(&waypoints[0]).tcp());
        let mut s = 0.0;
        for q in waypoints {
            let tcp = robot.forward(q).tcp();
            if !params.is_empty() {
                let joints_m = KNOT_STEP_M_PER_RAD * (q - previous.0).amax();
                s += (tcp - previous.1).norm().max(MIN_KNOT_STEP_M).max(joints_m);
            }
            params.push(s);
            previous = (*q, tcp);
        }
        let last = waypoints.len() - 1;
        // The knots: which given waypoint each is (None for a chord midpoint), parameter, value.
        let mut origin: Vec<Option<usize>> = (0..=last)
            .filter(|k| k % KNOT_STRIDE == 0 || *k == last)
            .map(Some)
            .collect();
        // A knot at an inner waypoint, moved inside the joint limits, clear of the links and
        // inside the cone where that holds every constraint.
        let knot = |k: usize| {
            let q = waypoints[k];
            if k == 0 || k == last {
                return q;
            }
            inset(robot, task, constraints, &q)
                .filter(|turned| *turned == q || valid(turned))
                .unwrap_or(q)
        };
        let mut values: Vec<JointVector> = origin
            .iter()
            .map(|k| knot(k.expect("a waypoint")))
            .collect();
        let mut knots: Vec<f64> = origin
            .iter()
            .map(|k| params[k.expect("a waypoint")])
            .collect();
        let mut refined_knots = 0;
        let mut midpoints = 0;
        let mut cut = None;
        while values.len() >= 2 {
            let spline = JointSpline::natural(knots.clone(), values.clone());
            let Some(Failing {
                segment,
                from_s: segment_s,
                violation,
            }) = first_failing_segment(robot, task, constraints, &spline, from_s)
            else {
                return Self {
                    spline: Some(spline),
                    start: waypoints[0],
                    refined_knots,
                    cut,
                };
            };
            // Put back the middle waypoint the segment skips.
            if let (Some(a), Some(b)) = (origin[segment], origin[segment + 1])
                && b > a + 1
            {
                let middle = (a + b) / 2;
                origin.insert(segment + 1, Some(middle));
                values.insert(segment + 1, knot(middle));
                knots.insert(segment + 1, params[middle]);
                refined_knots += 1;
                continue;
            }
            let splittable = knots[segment + 1] - knots[segment] >= 2.0 * MIN_KNOT_STEP_M;
            let midpoint = (midpoints < MAX_REFINEMENTS && splittable)
                .then(|| (values[segment] + values[segment + 1]) / 2.0)
                .map(|chord| {
                    onto_task(robot, task, &chord, constraints.line_tolerance_m, segment_s)
                })
                .and_then(|chord| inset(robot, task, constraints, &chord))
                .filter(|q| valid(q));
            if let Some(midpoint) = midpoint {
                knots.insert(segment + 1, (knots[segment] + knots[segment + 1]) / 2.0);
                values.insert(segment + 1, midpoint);
                origin.insert(segment + 1, None);
                midpoints += 1;
                refined_knots += 1;
                continue;
            }
            // End at the last given waypoint at or before the failing segment.
            let keep = (0..=segment)
                .rev()
                .find(|&k| origin[k].is_some())
                .expect("the first knot is a waypoint");
            cut = Some((origin[keep].expect("a waypoint"), violation));
            knots.truncate(keep + 1);
            values.truncate(keep + 1);
            origin.truncate(keep + 1);
        }
        Self {
            spline: None,
            start: waypoints[0],
            refined_knots,
            cut,
        }
    }

    /// The spline, unless the path is a single configuration.
    pub fn spline(&self) -> Option<&JointSpline> {
        self.spline.as_ref()
    }

    /// The first configuration of the path.
    pub fn start(&self) -> JointVector {
        self.start
    }
}

/// Rounds of the `(1, 2, 1) / 4` mean a path's waypoints are smoothed by before the spline is
/// fitted through them.
pub const SMOOTHING_ROUNDS: usize = 4;

/// `waypoints` with the controller's step-to-step jitter smoothed out: each inner one replaced
/// by the mean `(q[k-1] + 2 q[k] + q[k+1]) / 4` of its neighbours, [`SMOOTHING_ROUNDS`] times,
/// then moved back until its TCP lies where the waypoint's did ([`moved_to`]); the waypoint
/// itself where that does not converge or breaks a constraint. Only the tool's orientation and
/// the arm's posture are smoothed: every TCP stays where the controller put it.
fn smoothed(
    robot: &Robot,
    task: &Task,
    constraints: &ConstraintConfig,
    waypoints: &[JointVector],
) -> Vec<JointVector> {
    let mut out = waypoints.to_vec();
    if out.len() < 3 {
        return out;
    }
    for _ in 0..SMOOTHING_ROUNDS {
        let before = out.clone();
        for k in 1..out.len() - 1 {
            out[k] = (before[k - 1] + before[k] * 2.0 + before[k + 1]) / 4.0;
        }
    }
    for k in 1..out.len() - 1 {
        let tcp = robot.forward(&waypoints[k]).tcp();
        out[k] = moved_to(robot, &out[k], &tcp)
            .filter(|q| first_violation(robot, task, &robot.forward(q), constraints).is_none())
            .unwrap_or(waypoints[k]);
    }
    out
}

/// Newton steps that move a configuration's TCP onto a point, at most this many.
const MOVE_STEPS: usize = 12;

/// `q` moved by damped least-squares steps until its TCP lies within a nanometre of `target`;
/// `None` where it does not get there in [`MOVE_STEPS`].
fn moved_to(robot: &Robot, q: &JointVector, target: &Vec3) -> Option<JointVector> {
    let mut q = *q;
    let damping = DampingConfig::default();
    for _ in 0..MOVE_STEPS {
        let kinematics = robot.forward(&q);
        let error = target - kinematics.tcp();
        if error.norm() < 1e-9 {
            return Some(q);
        }
        q += damped_pseudo_inverse(kinematics.jacobian(), &damping).matrix * error;
    }
    None
}

/// Points a check interval is scanned at for the peak inside it, where its value rises at the
/// start and ends lower though still rising at the end.
const PEAK_SCAN: usize = 8;

/// Times such a scan narrows down on the last stretch of its interval, where the value keeps
/// rising until it drops (8⁶: to a few nanometres of a millimetre-long interval).
const PEAK_ZOOMS: usize = 6;

/// How much closer than the tolerance (m) the spline's checked points must lie to the line or
/// path: a timed sample falls between checked points, where the spline departs from the
/// distance at its neighbouring checks and peaks by well under this (measured up to 0.5 µm at
/// 0.1 mm and 0.5 mm tolerances).
pub const LINE_CHECK_MARGIN_M: f64 = 2e-6;

/// How much closer still (m) the spline's checked points must lie to the path point their
/// progress reached from their segment's first knot: the checker follows the progress sample
/// by sample, which near a corner or a tight turn places a sample a few micrometres further
/// from the path than the knot's progress does.
pub const PROGRESS_CHECK_MARGIN_M: f64 = 1e-5;

/// Bisection steps that place a peak of the tool angle or of the distance inside a check interval (an interval of
/// a few millimetres shrinks below a nanometre).
const PEAK_BISECTIONS: usize = 24;

/// A segment of a spline that breaks a constraint.
struct Failing {
    /// Its index.
    segment: usize,
    /// The progress its first knot reached along the task (m).
    from_s: f64,
    /// The first constraint a checked point breaks.
    violation: Violation,
}

/// The first segment of `spline` with a checked inside point that breaks a constraint (the line
/// tolerance less [`LINE_CHECK_MARGIN_M`]), the spline's start standing `from_s` along the task.
/// Checked are [`CHECKS_PER_SEGMENT`] evenly spaced points, every joint's turning points (where
/// a joint's extreme values inside the segment lie, so the joint limits hold on the whole
/// segment) and the peaks of the tool angle and of the distance from the line or path ([`peaks`]);
/// the distance both from the nearest point of the whole path ([`first_violation`]) and from
/// the path point reached from the segment's first knot's progress ([`Task::along`]).
fn first_failing_segment(
    robot: &Robot,
    task: &Task,
    constraints: &ConstraintConfig,
    spline: &JointSpline,
    from_s: f64,
) -> Option<Failing> {
    let constraints = &ConstraintConfig {
        line_tolerance_m: (constraints.line_tolerance_m - LINE_CHECK_MARGIN_M)
            .max(constraints.line_tolerance_m / 2.0),
        ..constraints.clone()
    };
    let knots = spline.knots();
    // Each knot's progress, followed from the start knot by knot.
    let mut s = from_s;
    let reached: Vec<f64> = knots
        .iter()
        .map(|&knot| {
            s = task
                .along(&robot.forward(&spline.eval(knot).q).tcp(), s)
                .s_m;
            s
        })
        .collect();
    (0..knots.len() - 1).find_map(|k| {
        let even: Vec<f64> = (1..CHECKS_PER_SEGMENT + 1)
            .map(|j| {
                knots[k] + (knots[k + 1] - knots[k]) * j as f64 / (CHECKS_PER_SEGMENT + 1) as f64
            })
            .collect();
        let peaks = peaks(robot, task, spline, k, &even, reached[k]);
        even.iter()
            .copied()
            .chain(spline.turning_points(k))
            .chain(peaks)
            .find_map(|s| {
                let kinematics = robot.forward(&spline.eval(s).q);
                first_violation(robot, task, &kinematics, constraints)
                    .or_else(|| {
                        let distance_m = task.along(&kinematics.tcp(), reached[k]).lateral.norm();
                        (task.path.is_some()
                            && distance_m > constraints.line_tolerance_m - PROGRESS_CHECK_MARGIN_M)
                            .then_some(Violation::LineTolerance { distance_m })
                    })
                    .map(|violation| Failing {
                        segment: k,
                        from_s: reached[k],
                        violation,
                    })
            })
    })
}

/// Where the tool angle `θ(s) = ∠(z(q(s)), n)` and the TCP's distance `δ(s)` from the line or
/// path peak inside segment `k` of `spline`: in each interval between consecutive points of the
/// segment's knots and `inner` (increasing) where a rate (`θ' = ∇θ · q'`, and `(δ²/2)' = −e ·
/// J q'` with `e` the TCP's offset to the line, or to the path point reached from the
/// progress `reached` of the segment's first knot, [`Task::along`]) turns from rising to
/// falling, or rises at the start and ends lower (found then among [`PEAK_SCAN`] points of the
/// interval, narrowed [`PEAK_ZOOMS`] times onto its last stretch where it rises to the end: the
/// distance to a path is not smooth where its nearest point jumps from one piece to the next),
/// its root found by [`PEAK_BISECTIONS`] bisections. The largest value on an
/// interval lies at one of its ends or at such a peak, unless the rate changes sign more than
/// once inside it; so a spline that holds the cone and the tolerance at its check points and
/// peaks holds them between them, where the timed samples fall.
fn peaks(
    robot: &Robot,
    task: &Task,
    spline: &JointSpline,
    k: usize,
    inner: &[f64],
    reached: f64,
) -> Vec<f64> {
    // The rates and the values themselves (the tool angle's cosine falls as the angle rises).
    let measures = |s: f64| {
        let point = spline.eval(s);
        let kinematics = robot.forward(&point.q);
        let offset = task.along(&kinematics.tcp(), reached).lateral;
        let angle = tool_angle_gradient(&kinematics, &task.n).map_or(0.0, |g| g.dot(&point.dq));
        let distance = -offset.dot(&(kinematics.jacobian() * point.dq));
        let angle_value = -kinematics.tool_axis().dot(&task.n);
        [[angle, angle_value], [distance, offset.norm()]]
    };
    let knots = spline.knots();
    let points: Vec<f64> = std::iter::once(knots[k])
        .chain(inner.iter().copied())
        .chain(std::iter::once(knots[k + 1]))
        .collect();
    let at_points: Vec<[[f64; 2]; 2]> = points.iter().map(|&s| measures(s)).collect();
    (0..2)
        .flat_map(|which| {
            let rate = |s: f64| measures(s)[which][0];
            let at = |i: usize| at_points[i][which];
            (0..points.len() - 1)
                .filter_map(|i| {
                    let (start, end) = (at(i), at(i + 1));
                    // Rising at the start, and falling at the end or ending lower: a peak inside
                    // (a value that is not smooth, the distance to a path's corner, may rise again
                    // just before the end).
                    if !(start[0] > 0.0 && (end[0] <= 0.0 || end[1] < start[1])) {
                        return None;
                    }
                    let (mut rising, mut falling) = (points[i], points[i + 1]);
                    if end[0] > 0.0 {
                        // Rising all along the scan, the value drops in its last stretch: look
                        // there, down to where it jumps.
                        let mut bracket = None;
                        for _ in 0..PEAK_ZOOMS {
                            let step = (falling - rising) / PEAK_SCAN as f64;
                            match (1..PEAK_SCAN)
                                .map(|j| rising + step * j as f64)
                                .find(|&s| rate(s) <= 0.0)
                            {
                                Some(s) => {
                                    bracket = Some((s - step, s));
                                    break;
                                }
                                None => rising = falling - step,
                            }
                        }
                        match bracket {
                            Some(found) => (rising, falling) = found,
                            None => return Some(rising),
                        }
                    }
                    for _ in 0..PEAK_BISECTIONS {
                        let middle = 0.5 * (rising + falling);
                        if rate(middle) > 0.0 {
                            rising = middle;
                        } else {
                            falling = middle;
                        }
                    }
                    Some(0.5 * (rising + falling))
                })
                .collect::<Vec<_>>()
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use emg_control::{ClassicalController, RolloutConfig, rollout};

    use super::*;

    /// The sum over inner waypoints of `|q[k-1] - 2 q[k] + q[k+1]|²`: how much the joint path
    /// bends from step to step.
    fn bending(waypoints: &[JointVector]) -> f64 {
        waypoints
            .windows(3)
            .map(|w| (w[0] - w[1] * 2.0 + w[2]).norm_squared())
            .sum()
    }

    #[test]
    fn smoothing_keeps_every_tcp_and_takes_out_the_step_to_step_jitter() {
        let urdf = concat!(
            env!("CARGO_MANIFEST_DIR"),
            "/../../data/robots/fr3_pen.urdf"
        );
        let robot = Robot::from_urdf_file(urdf, "link0", "pen_tip").unwrap();
        let seed = robot.mid_range();
        let kinematics = robot.forward(&seed);
        let direction = Vec3::new(0.0, 1.0, 0.0);
        let task = Task::new(
            &robot,
            kinematics.tcp(),
            direction,
            kinematics.tool_axis(),
            Some(seed),
        )
        .unwrap();
        let config = RolloutConfig::default();
        let mut controller = ClassicalController::default();
        let steps = rollout(&robot, &task, &seed, &mut controller, &config).steps;
        // The controller's steps, each shaken by a posture change that keeps its TCP.
        let waypoints: Vec<JointVector> = steps
            .iter()
            .enumerate()
            .map(|(k, step)| {
                let sign = if k % 2 == 0 { 1.0 } else { -1.0 };
                let mut shaken = step.q;
                shaken[6] += sign * 0.02;
                shaken[4] -= sign * 0.01;
                let tcp = robot.forward(&step.q).tcp();
                moved_to(&robot, &shaken, &tcp).unwrap()
            })
            .collect();
        let smooth = smoothed(&robot, &task, &config.constraints, &waypoints);
        assert_eq!(smooth.len(), waypoints.len());
        assert_eq!(smooth[0], waypoints[0]);
        assert_eq!(smooth[smooth.len() - 1], waypoints[waypoints.len() - 1]);
        for (q, original) in smooth.iter().zip(&waypoints) {
            let moved = (robot.forward(q).tcp() - robot.forward(original).tcp()).norm();
            assert!(moved < 1e-8, "a TCP moved by {moved} m");
        }
        let (before, after) = (bending(&waypoints), bending(&smooth));
        assert!(after < 0.05 * before, "bending {before} → {after}");
    }
}
