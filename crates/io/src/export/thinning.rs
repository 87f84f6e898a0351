//! Fewer points for a ROS 2 `joint_trajectory_controller`: the points kept are those through
//! which the controller's quintic spline (positions, velocities and accelerations matched at
//! both ends of each segment, as `joint_trajectory_controller` interpolates when accelerations
//! are given) stays within a tolerance of every sample of the timed motion.

use emg_kinematics::Robot;

use crate::joint_trajectory::{JointTrajectoryPoint, padded};

/// The default largest joint deviation (rad) of the quintic spline through the kept points from
/// any sample: 10 µrad, a tenth of the margin the timing keeps inside the joint limits
/// (`emg_timing::JOINT_INSET_RAD`, 10⁻⁴ rad), about 10 µm at the tool of an arm of 1 m reach.
pub const DEFAULT_TOLERANCE_RAD: f64 = 1e-5;

/// The quintic polynomial of one joint between two points, in the time since the first.
#[derive(Clone, Copy, Debug)]
struct Quintic([f64; 6]);

impl Quintic {
    /// The quintic matching position `p`, velocity `v` and acceleration `a` at both ends of a
    /// segment of `h` seconds (the coefficients ros2_control's `joint_trajectory_controller`
    /// computes).
    fn new(start: (f64, f64, f64), end: (f64, f64, f64), h: f64) -> Self {
        let ((p0, v0, a0), (p1, v1, a1)) = (start, end);
        let (h2, h3) = (h * h, h * h * h);
        Self([
            p0,
            v0,
            0.5 * a0,
            (20.0 * (p1 - p0) - (8.0 * v1 + 12.0 * v0) * h - (3.0 * a0 - a1) * h2) / (2.0 * h3),
            (30.0 * (p0 - p1) + (14.0 * v1 + 16.0 * v0) * h + (3.0 * a0 - 2.0 * a1) * h2)
                / (2.0 * h3 * h),
            (12.0 * (p1 - p0) - 6.0 * (v1 + v0) * h + (a1 - a0) * h2) / (2.0 * h3 * h2),
        ])
    }

    /// Position, velocity and acceleration `t` seconds after the segment's start.
    fn at(&self, t: f64) -> (f64, f64, f64) {
        let c = &self.0;
        let p = c[0] + t * (c[1] + t * (c[2] + t * (c[3] + t * (c[4] + t * c[5]))));
        let v = c[1] + t * (2.0 * c[2] + t * (3.0 * c[3] + t * (4.0 * c[4] + t * 5.0 * c[5])));
        let a = 2.0 * c[2] + t * (6.0 * c[3] + t * (12.0 * c[4] + t * 20.0 * c[5]));
        (p, v, a)
    }
}

/// Nanoseconds since the start of a point.
fn nanoseconds(point: &JointTrajectoryPoint) -> i64 {
    i64::from(point.time_from_start.sec) * 1_000_000_000 + i64::from(point.time_from_start.nanosec)
}

/// The quintic spline of every joint between `points[i]` and `points[j]`.
fn segment(points: &[JointTrajectoryPoint], i: usize, j: usize) -> (i64, Vec<Quintic>) {
    let (a, b) = (&points[i], &points[j]);
    let h = (nanoseconds(b) - nanoseconds(a)) as f64 * 1e-9;
    let quintics = (0..a.positions.len())
        .map(|joint| {
            let end = |p: &JointTrajectoryPoint| {
                (
                    p.positions[joint],
                    p.velocities[joint],
                    p.accelerations[joint],
                )
            };
            Quintic::new(end(a), end(b), h)
        })
        .collect();
    (nanoseconds(a), quintics)
}

/// The spline's positions, velocities and accelerations at the time of `point`.
fn spline_at(start_ns: i64, quintics: &[Quintic], point: &JointTrajectoryPoint) -> Vec<[f64; 3]> {
    let t = (nanoseconds(point) - start_ns) as f64 * 1e-9;
    quintics
        .iter()
        .map(|q| {
            let (p, v, a) = q.at(t);
            [p, v, a]
        })
        .collect()
}

/// The positions of the spline between `points[i]` and `points[j]`, `t` seconds after `i`.
pub(super) fn positions_between(
    points: &[JointTrajectoryPoint],
    [i, j]: [usize; 2],
    t: f64,
) -> Vec<f64> {
    let (_, quintics) = segment(points, i, j);
    quintics.iter().map(|q| q.at(t).0).collect()
}

/// The joint limits the spline must hold at every sample's time.
#[derive(Clone, Copy, Debug)]
pub struct SplineLimits<'a> {
    /// Velocity limits (rad/s), one per joint.
    pub velocity: &'a [f64],
    /// Acceleration limits (rad/s²), one per joint.
    pub acceleration: &'a [f64],
}

/// Whether the spline between `i` and `j` lies within `tolerance_rad` of the samples strictly
/// between them and holds `limits` at their times.
fn fits(
    points: &[JointTrajectoryPoint],
    i: usize,
    j: usize,
    tolerance_rad: f64,
    limits: &SplineLimits<'_>,
) -> bool {
    let (start, quintics) = segment(points, i, j);
    points[i + 1..j].iter().all(|point| {
        spline_at(start, &quintics, point)
            .iter()
            .enumerate()
            .all(|(k, s)| {
                (s[0] - point.positions[k]).abs() <= tolerance_rad
                    && s[1].abs() <= limits.velocity[k]
                    && s[2].abs() <= limits.acceleration[k]
            })
    })
}

/// The indices of the points to keep (the first and the last among them): greedily, from each
/// kept point, the farthest point whose spline segment stays within `tolerance_rad` of every
/// sample in between and holds `limits` at their times (an exponential search, then a
/// bisection; every segment kept is checked; two neighbouring samples always fit).
pub fn thin(
    points: &[JointTrajectoryPoint],
    tolerance_rad: f64,
    limits: &SplineLimits<'_>,
) -> Vec<usize> {
    let Some(last) = points.len().checked_sub(1) else {
        return Vec::new();
    };
    let mut kept = vec![0];
    let mut i = 0;
    while i < last {
        let fits = |j: usize| fits(points, i, j, tolerance_rad, limits);
        // `good` fits; `bad` does not, or lies past the end.
        let mut good = i + 1;
        let mut step = 2;
        let mut bad = loop {
            let j = i + step;
            if j > last {
                break last + 1;
            }
            if !fits(j) {
                break j;
            }
            good = j;
            step *= 2;
        };
        if bad > last && good < last {
            if fits(last) {
                good = last;
            } else {
                bad = last;
            }
        }
        while bad - good > 1 {
            let mid = good + (bad - good) / 2;
            if fits(mid) {
                good = mid;
            } else {
                bad = mid;
            }
        }
        kept.push(good);
        i = good;
    }
    kept
}

/// How far the spline through the kept points strays from the samples.
#[derive(Clone, Debug, PartialEq)]
pub struct ThinningReport {
    /// The tolerance asked for (rad).
    pub tolerance_rad: f64,
    /// Points of the timed motion.
    pub points_before: usize,
    /// Points kept.
    pub points_after: usize,
    /// Largest joint position deviation of the spline from any sample (rad).
    pub max_joint_deviation_rad: f64,
    /// Largest joint velocity deviation (rad/s).
    pub max_velocity_deviation_rad_s: f64,
    /// Largest joint acceleration deviation (rad/s²).
    pub max_acceleration_deviation_rad_s2: f64,
    /// Largest distance of the tool centre point at the spline's positions from the one at the
    /// sample's (m); `None` without the robot's kinematics.
    pub max_tool_deviation_m: Option<f64>,
}

/// Measures the spline through `kept` against every one of `points` (the tool's deviation with
/// `robot`'s forward kinematics when given).
pub fn measure(
    points: &[JointTrajectoryPoint],
    kept: &[usize],
    tolerance_rad: f64,
    robot: Option<&Robot>,
) -> ThinningReport {
    let mut report = ThinningReport {
        tolerance_rad,
        points_before: points.len(),
        points_after: kept.len(),
        max_joint_deviation_rad: 0.0,
        max_velocity_deviation_rad_s: 0.0,
        max_acceleration_deviation_rad_s2: 0.0,
        max_tool_deviation_m: robot.map(|_| 0.0),
    };
    for pair in kept.windows(2) {
        let (i, j) = (pair[0], pair[1]);
        let (start, quintics) = segment(points, i, j);
        for point in &points[i + 1..j] {
            let spline = spline_at(start, &quintics, point);
            for (k, s) in spline.iter().enumerate() {
                let worst = |m: &mut f64, x: f64| *m = m.max(x.abs());
                worst(
                    &mut report.max_joint_deviation_rad,
                    s[0] - point.positions[k],
                );
                worst(
                    &mut report.max_velocity_deviation_rad_s,
                    s[1] - point.velocities[k],
                );
                worst(
                    &mut report.max_acceleration_deviation_rad_s2,
                    s[2] - point.accelerations[k],
                );
            }
            if let (Some(robot), Some(tool)) = (robot, report.max_tool_deviation_m.as_mut()) {
                let at_spline: Vec<f64> = spline.iter().map(|s| s[0]).collect();
                let deviation = (robot.forward(&padded(&at_spline)).tcp()
                    - robot.forward(&padded(&point.positions)).tcp())
                .norm();
                *tool = tool.max(deviation);
            }
        }
    }
    report
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::joint_trajectory::TimeFromStart;

    const UNLIMITED: SplineLimits<'static> = SplineLimits {
        velocity: &[f64::INFINITY],
        acceleration: &[f64::INFINITY],
    };

    /// Samples of `q(t) = sin(ω t)` at 1 kHz (a smooth motion no quintic holds exactly).
    fn sine(count: usize) -> Vec<JointTrajectoryPoint> {
        (0..count)
            .map(|k| {
                let t = k as f64 * 1e-3;
                JointTrajectoryPoint {
                    positions: vec![libm::sin(2.0 * t)],
                    velocities: vec![2.0 * libm::cos(2.0 * t)],
                    accelerations: vec![-4.0 * libm::sin(2.0 * t)],
                    time_from_start: TimeFromStart::from_nanoseconds(k as u64 * 1_000_000).unwrap(),
                }
            })
            .collect()
    }

    #[test]
    fn a_quintic_matches_its_ends() {
        let q = Quintic::new((0.3, -1.0, 2.0), (1.1, 0.5, -3.0), 0.7);
        let close = |a: (f64, f64, f64), b: (f64, f64, f64)| {
            (a.0 - b.0).abs() < 1e-12 && (a.1 - b.1).abs() < 1e-12 && (a.2 - b.2).abs() < 1e-11
        };
        assert!(close(q.at(0.0), (0.3, -1.0, 2.0)));
        assert!(close(q.at(0.7), (1.1, 0.5, -3.0)), "{:?}", q.at(0.7));
    }

    #[test]
    fn thinning_keeps_the_ends_and_holds_the_tolerance() {
        let points = sine(3001);
        for tolerance in [1e-9, 1e-7, 1e-5] {
            let kept = thin(&points, tolerance, &UNLIMITED);
            assert_eq!((kept[0], *kept.last().unwrap()), (0, 3000));
            assert!(kept.windows(2).all(|w| w[0] < w[1]));
            let report = measure(&points, &kept, tolerance, None);
            assert!(report.max_joint_deviation_rad <= tolerance, "{report:?}");
            assert!(report.points_after < 3001 / 10, "{report:?}");
        }
        assert_eq!(thin(&points[..1], 1e-5, &UNLIMITED), vec![0]);
        assert_eq!(thin(&points[..2], 1e-5, &UNLIMITED), vec![0, 1]);
        assert!(thin(&[], 1e-5, &UNLIMITED).is_empty());
        // Limits just above the motion's own peaks (2 rad/s, 4 rad/s²) hold between the points.
        let tight = SplineLimits {
            velocity: &[2.0 + 1e-9],
            acceleration: &[4.0 + 1e-9],
        };
        let kept = thin(&points, 1e-3, &tight);
        let loose = thin(&points, 1e-3, &UNLIMITED);
        assert!(kept.len() >= loose.len(), "{} {}", kept.len(), loose.len());
    }
}
