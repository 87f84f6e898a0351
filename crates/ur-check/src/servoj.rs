//! A joint stream read back: one or more `def emg_motion():` programs, the first coming to the
//! motion's start by the home check (a motion that starts at the arm's home) or a `movej`, each
//! later one by a `movej` to where the one before it stopped; then one `servoj` target per
//! controller cycle, each the motion's sample at its time (the quintic through the two samples
//! around it where none falls there), within the arm's joint limits and, by differences, its
//! velocity and acceleration limits; a hold at a target where the motion rests, and `stopj`.

use emg_io::{JointTrajectoryPoint, TimingLimits};
use emg_job::JobFile;
use emg_verify::ReferenceModel;

use crate::error::{ReadError, fail};
use crate::script::{Form, Statement, parse_program};

/// The e-Series controller's cycle (s): the time each streamed target is tracked for, and the
/// time between the motion's samples two targets stand for.
pub const SERVO_PERIOD_S: f64 = 0.002;

/// [`SERVO_PERIOD_S`] in nanoseconds.
const SERVO_PERIOD_NS: i64 = 2_000_000;

/// How closely (rad per joint) a target between two samples must equal the quintic through
/// them; a target at a sample's time equals the sample exactly.
pub const TARGET_MATCH_RAD: f64 = 1e-9;

/// Relative slack of the acceleration check: the second difference of the targets over a
/// cycle averages the acceleration over two cycles, which a limit holds only up to rounding
/// and the spline's curvature between samples.
pub const ACCELERATION_SLACK: f64 = 0.01;

/// Relative slack of the speed check: a move at a joint's speed limit differs from it by the
/// rounding of its positions.
const SPEED_SLACK: f64 = 1e-9;

/// A timed motion as the servoj reader reads it: its samples, the limits they hold and where
/// it starts.
#[derive(Clone, Copy, Debug)]
pub struct TimedMotion<'a> {
    /// The samples, from rest to rest, in time order.
    pub points: &'a [JointTrajectoryPoint],
    /// The velocity and acceleration limits every sample holds.
    pub limits: &'a TimingLimits,
    /// The arm's home, where the motion starts (a job's program): the first program must check
    /// that the arm stands there rather than move it.
    pub home: Option<&'a [f64]>,
}

/// What the servoj reader found.
#[derive(Clone, Debug, PartialEq)]
pub struct ServojReport {
    /// Programs read.
    pub programs: usize,
    /// `servoj` targets streamed (the holds apart), all programs together.
    pub targets: usize,
    /// The motion's duration (s).
    pub duration_s: f64,
    /// Whether the first program checks that the arm stands at its home.
    pub home_checked: bool,
    /// Largest joint speed between consecutive targets, as a fraction of the joint's limit.
    pub worst_speed_fraction: f64,
    /// Largest joint acceleration by second differences of the targets, as a fraction of the
    /// joint's limit.
    pub worst_acceleration_fraction: f64,
}

/// Reads the joint stream `scripts` (its programs in order) against the job's plan `file`,
/// the joints' limits those of the checker `model`.
pub fn read_servoj(
    scripts: &[&str],
    file: &JobFile,
    model: &ReferenceModel,
) -> Result<ServojReport, ReadError> {
    let points = file.points();
    let motion = TimedMotion {
        points: &points,
        limits: &file.limits,
        home: file.home.as_deref(),
    };
    read_servoj_motion(scripts, &motion, model)
}

/// Reads the joint stream `scripts` (its programs in order) against `motion`, the joints'
/// limits those of the checker `model`.
pub fn read_servoj_motion(
    scripts: &[&str],
    motion: &TimedMotion<'_>,
    model: &ReferenceModel,
) -> Result<ServojReport, ReadError> {
    let stream = Stream::new(motion, model)?;
    if scripts.is_empty() {
        return fail(0, "no program to read");
    }
    let mut state = StreamState {
        streamed: 0,
        recent: vec![stream.sample_q(0)],
        report: ServojReport {
            programs: scripts.len(),
            targets: 0,
            duration_s: stream.end_ns as f64 * 1e-9,
            home_checked: false,
            worst_speed_fraction: 0.0,
            worst_acceleration_fraction: 0.0,
        },
    };
    for (index, script) in scripts.iter().enumerate() {
        stream
            .read_program(script, index, &mut state)
            .map_err(|error| ReadError {
                program: Some(index + 1),
                ..error
            })?;
    }
    let needed = stream.targets_needed();
    if state.streamed != needed {
        return Err(ReadError {
            program: Some(scripts.len()),
            line: 0,
            problem: format!(
                "the programs stream {} targets; the motion's {:.3} s need {needed}",
                state.streamed, state.report.duration_s
            ),
        });
    }
    state.report.targets = state.streamed;
    Ok(state.report)
}

/// What a reading needs of the motion and the checker.
struct Stream<'a> {
    motion: &'a TimedMotion<'a>,
    /// Each sample's time (ns).
    times_ns: Vec<i64>,
    /// The last sample's time (ns).
    end_ns: i64,
    /// Each joint's position limits (rad).
    position_limits: Vec<(f64, f64)>,
}

/// The stream as its programs run.
struct StreamState {
    /// Targets streamed so far.
    streamed: usize,
    /// The last two targets (the motion's start before the first).
    recent: Vec<[f64; 6]>,
    report: ServojReport,
}

/// A point's time (ns).
fn nanoseconds(point: &JointTrajectoryPoint) -> i64 {
    i64::from(point.time_from_start.sec) * 1_000_000_000 + i64::from(point.time_from_start.nanosec)
}

/// The value at `t` (s) of the quintic through `(p, v, a)` at both ends of `h` seconds (what a
/// controller interpolates between two timed points, ROS 2's trajectory controller too).
pub fn quintic(start: [f64; 3], end: [f64; 3], h: f64, t: f64) -> f64 {
    let [p0, v0, a0] = start;
    let [p1, v1, a1] = end;
    // What the cubic, quartic and quintic terms must make up at `h`: position, velocity and
    // acceleration.
    let r0 = p1 - p0 - v0 * h - 0.5 * a0 * h * h;
    let r1 = v1 - v0 - a0 * h;
    let r2 = a1 - a0;
    let c3 = (10.0 * r0 - 4.0 * r1 * h + 0.5 * r2 * h * h) / h.powi(3);
    let c4 = (-15.0 * r0 + 7.0 * r1 * h - r2 * h * h) / h.powi(4);
    let c5 = (6.0 * r0 - 3.0 * r1 * h + 0.5 * r2 * h * h) / h.powi(5);
    p0 + v0 * t + 0.5 * a0 * t * t + c3 * t.powi(3) + c4 * t.powi(4) + c5 * t.powi(5)
}

impl<'a> Stream<'a> {
    /// What the reading needs of `motion` and `model`.
    fn new(motion: &'a TimedMotion<'a>, model: &ReferenceModel) -> Result<Self, ReadError> {
        let points = motion.points;
        let six = |values: &[f64]| values.len() == 6;
        if points.is_empty() {
            return fail(0, "the motion has no sample");
        }
        if !(points.iter().all(|p| six(&p.positions))
            && six(&motion.limits.max_velocity)
            && six(&motion.limits.max_acceleration)
            && model.limits().len() == 6)
        {
            return fail(0, "the motion is not a six-joint arm's");
        }
        let times_ns: Vec<i64> = points.iter().map(nanoseconds).collect();
        if times_ns[0] != 0 || times_ns.windows(2).any(|pair| pair[1] <= pair[0]) {
            return fail(0, "the motion's samples do not start at 0 s in time order");
        }
        let end_ns = times_ns[times_ns.len() - 1];
        Ok(Self {
            motion,
            times_ns,
            end_ns,
            position_limits: model.limits(),
        })
    }

    /// The targets the whole motion needs: one per cycle after its start, the last at its end.
    fn targets_needed(&self) -> usize {
        ((self.end_ns + SERVO_PERIOD_NS - 1) / SERVO_PERIOD_NS) as usize
    }

    /// Sample `k`'s positions.
    fn sample_q(&self, k: usize) -> [f64; 6] {
        std::array::from_fn(|j| self.motion.points[k].positions[j])
    }

    /// Whether the motion rests at time `t_ns`: a sample there with every velocity zero.
    fn rests_at(&self, t_ns: i64) -> bool {
        self.times_ns
            .binary_search(&t_ns)
            .is_ok_and(|k| self.motion.points[k].velocities.iter().all(|v| *v == 0.0))
    }

    /// Checks that `q` is the motion at `t_ns`: the sample there exactly, else within
    /// [`TARGET_MATCH_RAD`] of the quintic through the samples around it.
    fn check_target(&self, q: &[f64; 6], t_ns: i64, line: usize) -> Result<(), ReadError> {
        let points = self.motion.points;
        let (expected, tolerance) = match self.times_ns.binary_search(&t_ns) {
            Ok(k) => (self.sample_q(k), 0.0),
            Err(after) => {
                let (a, b) = (&points[after - 1], &points[after]);
                let h = (self.times_ns[after] - self.times_ns[after - 1]) as f64 * 1e-9;
                let t = (t_ns - self.times_ns[after - 1]) as f64 * 1e-9;
                let expected = std::array::from_fn(|j| {
                    quintic(
                        [a.positions[j], a.velocities[j], a.accelerations[j]],
                        [b.positions[j], b.velocities[j], b.accelerations[j]],
                        h,
                        t,
                    )
                });
                (expected, TARGET_MATCH_RAD)
            }
        };
        let worst = q
            .iter()
            .zip(&expected)
            .map(|(a, b)| (a - b).abs())
            .fold(0.0, f64::max);
        if worst > tolerance {
            return fail(
                line,
                format!(
                    "target {q:?} is not the motion at t = {:.3} s ({expected:?}; {worst:.3e} \
                     rad away)",
                    t_ns as f64 * 1e-9
                ),
            );
        }
        Ok(())
    }

    /// Checks the target `q` that follows the recent ones: the joints within their limits, the
    /// speed and acceleration by differences within the motion's limits.
    fn check_limits(
        &self,
        q: &[f64; 6],
        state: &mut StreamState,
        line: usize,
    ) -> Result<(), ReadError> {
        let limits = self.motion.limits;
        let recent = &state.recent;
        let last = recent[recent.len() - 1];
        let before = (recent.len() >= 2).then(|| recent[recent.len() - 2]);
        for (j, value) in q.iter().enumerate() {
            let (low, high) = self.position_limits[j];
            if !(*value >= low && *value <= high) {
                return fail(
                    line,
                    format!(
                        "joint {} = {value} leaves its limits [{low}, {high}]",
                        j + 1
                    ),
                );
            }
            let speed = (value - last[j]).abs() / SERVO_PERIOD_S;
            let fraction = speed / limits.max_velocity[j];
            state.report.worst_speed_fraction = state.report.worst_speed_fraction.max(fraction);
            if fraction > 1.0 + SPEED_SLACK {
                return fail(
                    line,
                    format!(
                        "joint {} moves at {speed:.4} rad/s; its limit is {} rad/s",
                        j + 1,
                        limits.max_velocity[j]
                    ),
                );
            }
            if let Some(before) = before {
                let acceleration =
                    (value - 2.0 * last[j] + before[j]).abs() / (SERVO_PERIOD_S * SERVO_PERIOD_S);
                let fraction = acceleration / limits.max_acceleration[j];
                state.report.worst_acceleration_fraction =
                    state.report.worst_acceleration_fraction.max(fraction);
                if fraction > 1.0 + ACCELERATION_SLACK {
                    return fail(
                        line,
                        format!(
                            "joint {} accelerates at {acceleration:.3} rad/s²; its limit is {} \
                             rad/s²",
                            j + 1,
                            limits.max_acceleration[j]
                        ),
                    );
                }
            }
        }
        Ok(())
    }

    /// Reads program `index` (0-based) of the stream.
    fn read_program(
        &self,
        script: &str,
        index: usize,
        state: &mut StreamState,
    ) -> Result<(), ReadError> {
        let program = parse_program(script, Form::Servoj)?;
        let mut statements = program.statements.iter();
        let resting = state.recent[state.recent.len() - 1];
        match (statements.next(), index, self.motion.home) {
            (Some((line, Statement::HomeCheck { home, .. })), 0, Some(motion_home)) => {
                if home.as_slice() != motion_home || *home != resting {
                    return fail(*line, "the home checked is not the motion's home and start");
                }
                state.report.home_checked = true;
            }
            (Some((line, Statement::MoveJ { q, radius_m })), _, home)
                if *radius_m == 0.0 && (index > 0 || home.is_none()) =>
            {
                if *q != resting {
                    return fail(
                        *line,
                        format!(
                            "movej to {q:?}, not to {resting:?}, where the motion rests at t = \
                             {:.3} s",
                            self.time_ns(state.streamed) as f64 * 1e-9
                        ),
                    );
                }
            }
            (Some((line, _)), 0, Some(_)) => {
                return fail(
                    *line,
                    "the motion starts at the arm's home: the program must check that the arm \
                     stands there first",
                );
            }
            (Some((line, _)), _, _) => {
                return fail(*line, "the program must come to its start by movej first");
            }
            (None, _, _) => return fail(0, "the program holds no statement"),
        }
        let mut stopped = None;
        let mut held = false;
        for (line, statement) in statements {
            match (*statement, held, stopped) {
                (_, _, Some(_)) => return fail(*line, "a statement after stopj"),
                (Statement::ServoJ { q, time_s }, false, None) if time_s == SERVO_PERIOD_S => {
                    state.streamed += 1;
                    let t_ns = self.time_ns(state.streamed);
                    if state.streamed > self.targets_needed() {
                        return fail(*line, "a target after the motion's end");
                    }
                    self.check_target(&q, t_ns, *line)?;
                    self.check_limits(&q, state, *line)?;
                    state.recent.push(q);
                    if state.recent.len() > 2 {
                        state.recent.remove(0);
                    }
                }
                (Statement::ServoJ { q, .. }, false, None) => {
                    let last = state.recent[state.recent.len() - 1];
                    let t_ns = self.time_ns(state.streamed);
                    if q != last {
                        return fail(*line, "the hold is not at the last target");
                    }
                    if !self.rests_at(t_ns) {
                        return fail(
                            *line,
                            format!(
                                "the program stops at t = {:.3} s, where the motion does not rest",
                                t_ns as f64 * 1e-9
                            ),
                        );
                    }
                    held = true;
                }
                (Statement::StopJ, true, None) => stopped = Some(*line),
                _ => {
                    return fail(
                        *line,
                        "expected servoj targets, a hold at the last one, then stopj",
                    );
                }
            }
        }
        if stopped.is_none() {
            return fail(0, "the program does not hold its last target and stopj");
        }
        Ok(())
    }

    /// The motion's time (ns) of target `k` (the `k`-th after the start): `k` cycles, at most
    /// the motion's end.
    fn time_ns(&self, k: usize) -> i64 {
        (k as i64 * SERVO_PERIOD_NS).min(self.end_ns)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_quintic_meets_its_ends_and_follows_a_quintic_polynomial() {
        // p(t) = 1 + 2t − t² + 3t³ − 4t⁴ + 5t⁵ and its derivatives.
        let p =
            |t: f64| 1.0 + 2.0 * t - t * t + 3.0 * t.powi(3) - 4.0 * t.powi(4) + 5.0 * t.powi(5);
        let v = |t: f64| 2.0 - 2.0 * t + 9.0 * t * t - 16.0 * t.powi(3) + 25.0 * t.powi(4);
        let a = |t: f64| -2.0 + 18.0 * t - 48.0 * t * t + 100.0 * t.powi(3);
        let (t0, h) = (0.3, 0.5);
        let start = [p(t0), v(t0), a(t0)];
        let end = [p(t0 + h), v(t0 + h), a(t0 + h)];
        for s in [0.0, 0.1, 0.25, 0.4, 0.5] {
            assert!((quintic(start, end, h, s) - p(t0 + s)).abs() < 1e-12, "{s}");
        }
    }
}
