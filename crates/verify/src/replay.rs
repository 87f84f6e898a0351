//! Verifying timed joint positions read from a file: every point against the task and the
//! bounds, joint speeds from positions and times, and the velocities the file declares.

use crate::check::{FailedCheck, Measured, Points};
use crate::dynamics::{DynamicsCheck, DynamicsReport, JointDynamics, check_dynamics};
use crate::model::{ReferenceModel, within};
use crate::record::{Bounds, Joints, Line, Recording};
use crate::samples::JointSamples;

/// Relative slack when comparing a declared velocity with its limit (float rounding).
pub const VELOCITY_LIMIT_SLACK: f64 = 1e-9;

/// Tolerance of declared velocities: a declared `q̇_i` may differ from the one
/// [`point_velocities`] gives from the file's own positions and times by
/// `1e-9 · (1 + |q̇_i|)` rad/s (the writers use that very rule, so their files agree to the
/// last bit; the tolerance admits a reader that computes it in another order).
pub const DECLARED_VELOCITY_TOLERANCE: f64 = 1e-9;

/// Joint velocities at timed points: interior points take the central difference
/// `(q_{k+1} − q_{k−1}) / (t_{k+1} − t_{k−1})` (a convex combination of the two segment
/// velocities, so within any bound both segments hold), the first and last points the velocity
/// of their one segment; a single point has zero velocity. The writers of every trajectory file
/// declare these velocities, and the replay check recomputes them.
///
/// `time_s` and `q` have the same length and the times increase strictly.
pub fn point_velocities(time_s: &[f64], q: &[Joints]) -> Vec<Joints> {
    assert_eq!(time_s.len(), q.len(), "one time per configuration");
    let n = q.len();
    let slope = |a: usize, b: usize| (q[b] - q[a]) / (time_s[b] - time_s[a]);
    (0..n)
        .map(|k| match (k, n) {
            (_, 1) => Joints::zeros(),
            (0, _) => slope(0, 1),
            (k, n) if k == n - 1 => slope(k - 1, k),
            (k, _) => slope(k - 1, k + 1),
        })
        .collect()
}

/// Per joint, `max_k |q̇_{k+1,i} − q̇_{k,i}| / (t_{k+1} − t_k)` over consecutive timed points
/// (zeros for a single point).
fn peak_accelerations(time_s: &[f64], velocities: &[Joints], joints: usize) -> Vec<f64> {
    let mut peak = vec![0.0_f64; joints];
    for k in 1..velocities.len() {
        let gap = time_s[k] - time_s[k - 1];
        for (i, peak) in peak.iter_mut().enumerate() {
            *peak = peak.max((velocities[k][i] - velocities[k - 1][i]).abs() / gap);
        }
    }
    peak
}

/// What a verified trajectory does, for the report of a check.
#[derive(Clone, Debug, PartialEq)]
pub struct ReplayReport {
    /// Number of points.
    pub points: usize,
    /// Time of the last point (s).
    pub duration_s: f64,
    /// `(p_last − p0)·d` (m), from the checker's forward kinematics; along a path, the arc
    /// length reached.
    pub path_length_m: f64,
    /// The least and the greatest progress of the points (m), followed as `path_length_m` is:
    /// [`Line::covered`] of their TCPs.
    pub progress_range_m: (f64, f64),
    /// Per joint, the fastest segment speed `|Δq_i| / Δt` as a fraction of the robot file's
    /// velocity limit of that joint (0 for a single point).
    pub peak_speed_fraction: Vec<f64>,
    /// Per joint, the largest change of point velocity between consecutive points over their
    /// time gap (rad/s²), from the declared velocities or else [`point_velocities`]: what a
    /// controller interpolating the points meets between them (0 for a single point). The
    /// planner does not bound it.
    pub peak_acceleration_rad_s2: Vec<f64>,
    /// The fastest joint at the first and at the last point, as a fraction of its velocity
    /// limit: a motion that starts or ends moving needs the arm brought up to (down from) that
    /// speed outside the file.
    pub boundary_speed_fraction: [f64; 2],
    /// Largest lateral distance of the TCP from the task line (m).
    pub max_line_deviation_m: f64,
    /// Largest angle between the tool axis and `n` (degrees).
    pub max_tool_angle_deg: f64,
    /// Smallest clearance between checked capsule pairs (m), with the pair's links.
    pub min_clearance: (f64, String, String),
    /// Largest difference between a declared velocity and the velocity rule (rad/s); `None`
    /// when the file declares no velocities or declares accelerations too (then the dynamic
    /// check verifies the declared values).
    pub max_declared_velocity_error: Option<f64>,
    /// What the dynamic check measured, when joint dynamics limits were given.
    pub dynamics: Option<DynamicsReport>,
}

/// Which check a point of a file fails.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ReplayCheck {
    /// A time is not finite or does not come after the previous one.
    Times,
    /// A check of the points as a recorded motion ([`ReferenceModel::check_recording`]).
    Recording(FailedCheck),
    /// Joint `joint` (1-based) declares a velocity above its share of the limit.
    DeclaredVelocityLimit {
        /// 1-based joint number.
        joint: usize,
    },
    /// Joint `joint` (1-based) declares a velocity its positions and times do not give.
    DeclaredVelocityRule {
        /// 1-based joint number.
        joint: usize,
    },
    /// A check of rest, velocity, acceleration and jerk limits ([`check_dynamics`]).
    Dynamics(DynamicsCheck),
}

/// Why a trajectory file does not hold up: the joint names, or a point and the check it fails.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum ReplayError {
    /// The file's joint names are not the robot's, in the robot's order.
    #[error("joint_names {file:?} are not the robot's joints {robot:?} (same names, same order)")]
    JointNames {
        /// Names in the file.
        file: Vec<String>,
        /// The robot's revolute joints, base to tip.
        robot: Vec<String>,
    },
    /// The file holds no point.
    #[error("point 0: the file holds no point")]
    Empty,
    /// A point breaks a constraint or disagrees with the file's own records.
    #[error("point {point}: {problem}")]
    Point {
        /// Index of the point (0 = the first).
        point: usize,
        /// The check it fails.
        check: ReplayCheck,
        /// The constraint and by how much.
        problem: String,
    },
}

/// Checks that a file's joint names are the robot's, in the same order.
pub fn check_joint_names(file: &[String], robot: &[String]) -> Result<(), ReplayError> {
    if file == robot {
        Ok(())
    } else {
        Err(ReplayError::JointNames {
            file: file.to_vec(),
            robot: robot.to_vec(),
        })
    }
}

/// Verifies timed points against `line` and `bounds` with the independent checker:
///
/// 1. times finite and strictly increasing;
/// 2. [`ReferenceModel::check_recording`] of `recorded` (a file's own recording holding these
///    very points) or else of [`JointSamples::to_recording`]: joint position limits, line
///    tolerance, tool cone, self-collision, joint speeds from positions and times within
///    `velocity_limit_fraction · v_max` (when the bounds enforce it), and the records a
///    recorded motion carries (TCP, tool angle, path length, why it ended);
/// 3. declared velocities, if any: `|q̇_i| ≤ fraction · v_max,i · (1 + VELOCITY_LIMIT_SLACK)`
///    (when enforced) and, for samples that declare no accelerations, within
///    [`DECLARED_VELOCITY_TOLERANCE`] of [`point_velocities`] of the file's own positions and
///    times;
/// 4. with `dynamics`: [`check_dynamics`] (rest at both ends, velocity, acceleration and jerk
///    limits, declared values that agree with the positions).
///
/// # Panics
///
/// If `recorded` does not hold exactly the samples' times and positions.
pub fn check_replay(
    model: &ReferenceModel,
    line: &Line,
    bounds: &Bounds,
    samples: &JointSamples,
    recorded: Option<&Recording>,
    dynamics: Option<&JointDynamics>,
) -> Result<ReplayReport, ReplayError> {
    if samples.is_empty() {
        return Err(ReplayError::Empty);
    }
    check_times(&samples.time_s)?;
    let measured = model
        .check_points(line, replayed_points(samples, recorded), bounds)
        .map_err(|failure| ReplayError::Point {
            point: failure.step,
            check: ReplayCheck::Recording(failure.check),
            problem: failure.problem,
        })?;
    let v_max = model.velocity_limits();
    let max_declared_velocity_error = check_declared_velocities(samples, bounds, &v_max)?;
    let dynamics = match dynamics {
        Some(limits) => {
            Some(
                check_dynamics(samples, limits).map_err(|failure| ReplayError::Point {
                    point: failure.sample,
                    check: ReplayCheck::Dynamics(failure.check),
                    problem: failure.problem,
                })?,
            )
        }
        None => None,
    };
    Ok(replay_report(
        samples,
        &v_max,
        measured,
        max_declared_velocity_error,
        dynamics,
    ))
}

/// Fails at the first time that is not finite or does not come strictly after the previous.
fn check_times(time_s: &[f64]) -> Result<(), ReplayError> {
    for (k, t) in time_s.iter().enumerate() {
        if !t.is_finite() {
            return Err(ReplayError::Point {
                point: k,
                check: ReplayCheck::Times,
                problem: format!("time {t} s is not finite"),
            });
        }
        if k > 0 && *t <= time_s[k - 1] {
            return Err(ReplayError::Point {
                point: k,
                check: ReplayCheck::Times,
                problem: format!(
                    "timestamps must increase strictly: {t} s after {} s",
                    time_s[k - 1]
                ),
            });
        }
    }
    Ok(())
}

/// The points to check: `recorded` (which must hold exactly the samples' times and
/// positions), or else the samples as [`JointSamples::to_recording`] makes them.
fn replayed_points<'a>(samples: &'a JointSamples, recorded: Option<&'a Recording>) -> Points<'a> {
    match recorded {
        Some(recording) => {
            assert!(
                recording.steps.len() == samples.len()
                    && recording
                        .steps
                        .iter()
                        .zip(samples.time_s.iter().zip(&samples.q))
                        .all(|(step, (t, q))| step.time_s == *t && step.q == *q),
                "the recording holds the samples' points"
            );
            Points::Recorded(recording)
        }
        // The samples as `JointSamples::to_recording` makes them, checked as that recording.
        None => Points::Samples {
            time_s: &samples.time_s,
            q: &samples.q,
        },
    }
}

/// Verifies the velocities the samples declare, if any, against their share of the limits
/// `v_max` and, without declared accelerations, against [`point_velocities`]; returns the
/// largest difference from that rule where it was compared.
fn check_declared_velocities(
    samples: &JointSamples,
    bounds: &Bounds,
    v_max: &[f64],
) -> Result<Option<f64>, ReplayError> {
    let Some(declared) = &samples.qd else {
        return Ok(None);
    };
    let fail = |point: usize, check: ReplayCheck, problem: String| {
        Err(ReplayError::Point {
            point,
            check,
            problem,
        })
    };
    let rule = point_velocities(&samples.time_s, &samples.q);
    let mut worst = 0.0_f64;
    for (k, (qd, expected)) in declared.iter().zip(&rule).enumerate() {
        for i in 0..v_max.len() {
            if let Some(f) = bounds.velocity_limit_fraction
                && !within(qd[i].abs(), f * v_max[i] * (1.0 + VELOCITY_LIMIT_SLACK))
            {
                return fail(
                    k,
                    ReplayCheck::DeclaredVelocityLimit { joint: i + 1 },
                    format!(
                        "declared velocity of joint {} is {} rad/s, {:.4} × its limit {} \
                         rad/s (allowed: {f} ×)",
                        i + 1,
                        qd[i],
                        qd[i].abs() / v_max[i],
                        v_max[i],
                    ),
                );
            }
            if samples.qdd.is_some() {
                continue;
            }
            let error = (qd[i] - expected[i]).abs();
            if !within(
                error,
                DECLARED_VELOCITY_TOLERANCE * (1.0 + expected[i].abs()),
            ) {
                return fail(
                    k,
                    ReplayCheck::DeclaredVelocityRule { joint: i + 1 },
                    format!(
                        "declared velocity of joint {} is {} rad/s but the positions and \
                         times give {} rad/s (tolerance {DECLARED_VELOCITY_TOLERANCE:e} × \
                         (1 + |q̇|))",
                        i + 1,
                        qd[i],
                        expected[i]
                    ),
                );
            }
            worst = worst.max(error);
        }
    }
    Ok(samples.qdd.is_none().then_some(worst))
}

/// Per joint, the fastest segment speed of the samples as a fraction of its limit in `v_max`.
fn peak_speed_fractions(samples: &JointSamples, v_max: &[f64]) -> Vec<f64> {
    let mut peak_speed_fraction = vec![0.0_f64; v_max.len()];
    for k in 1..samples.len() {
        let gap = samples.time_s[k] - samples.time_s[k - 1];
        for (i, peak) in peak_speed_fraction.iter_mut().enumerate() {
            let speed = (samples.q[k][i] - samples.q[k - 1][i]).abs() / gap;
            *peak = peak.max(speed / v_max[i]);
        }
    }
    peak_speed_fraction
}

/// The report of verified samples: their timing and speeds against `v_max`, what the point
/// check `measured`, and the results of the declared-velocity and dynamic checks.
fn replay_report(
    samples: &JointSamples,
    v_max: &[f64],
    measured: Measured,
    max_declared_velocity_error: Option<f64>,
    dynamics: Option<DynamicsReport>,
) -> ReplayReport {
    let peak_speed_fraction = peak_speed_fractions(samples, v_max);
    let velocities = match &samples.qd {
        Some(declared) => declared.clone(),
        None => point_velocities(&samples.time_s, &samples.q),
    };
    let peak_acceleration_rad_s2 = peak_accelerations(&samples.time_s, &velocities, v_max.len());
    let fastest_joint = |qd: &Joints| {
        (0..v_max.len())
            .map(|i| qd[i].abs() / v_max[i])
            .fold(0.0, f64::max)
    };
    let boundary_speed_fraction = [
        fastest_joint(&velocities[0]),
        fastest_joint(&velocities[velocities.len() - 1]),
    ];
    let last = samples.len() - 1;
    let progress = &measured.progress;
    ReplayReport {
        points: samples.len(),
        duration_s: samples.time_s[last],
        path_length_m: progress[last],
        progress_range_m: progress
            .iter()
            .fold((progress[0], progress[0]), |(low, high), s| {
                (low.min(*s), high.max(*s))
            }),
        peak_speed_fraction,
        peak_acceleration_rad_s2,
        boundary_speed_fraction,
        max_line_deviation_m: measured.max_line_deviation_m,
        max_tool_angle_deg: measured.max_tool_angle_deg,
        min_clearance: measured.min_clearance,
        max_declared_velocity_error,
        dynamics,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn velocity_rule_on_non_uniform_times() {
        let time_s = [0.0, 0.1, 0.3, 0.35];
        let joint = [0.0, 0.2, 0.3, 0.5];
        let q: Vec<Joints> = joint.iter().map(|&v| Joints::from_element(v)).collect();
        let qd = point_velocities(&time_s, &q);
        let expected = [
            (0.2 - 0.0) / 0.1,
            (0.3 - 0.0) / 0.3,
            (0.5 - 0.2) / (0.35 - 0.1),
            (0.5 - 0.3) / (0.35 - 0.3),
        ];
        for (v, e) in qd.iter().zip(expected) {
            assert!(v.iter().all(|x| *x == e), "{v} vs {e}");
        }
        // Interior points lie between their two segment velocities (2.0 / 0.5 and 0.5 / 4.0).
        assert!(qd[1][0] > 0.5 && qd[1][0] < 2.0);
        assert!(qd[2][0] > 0.5 && qd[2][0] < 4.0);
        assert_eq!(point_velocities(&[0.0], &q[..1]), vec![Joints::zeros()]);
    }

    #[test]
    fn peak_accelerations_compare_consecutive_point_velocities() {
        let velocity = |v: f64| Joints::from_element(v);
        // Joint velocities 1, 2/3, 1/2 rad/s at 0, 1 and 3 s: changes of 1/3 over 1 s and
        // 1/6 over 2 s.
        let peaks = peak_accelerations(
            &[0.0, 1.0, 3.0],
            &[velocity(1.0), velocity(2.0 / 3.0), velocity(0.5)],
            7,
        );
        for peak in peaks {
            assert!((peak - 1.0 / 3.0).abs() < 1e-15, "{peak}");
        }
        assert_eq!(
            peak_accelerations(&[0.0], &[velocity(1.0)], 6),
            vec![0.0; 6]
        );
    }
}
