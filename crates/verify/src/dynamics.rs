//! Verifying a timed motion against joint velocity, acceleration and jerk limits, as a robot
//! controller streamed its samples judges it: at rest at both ends, divided differences of the
//! positions (the arm held at rest before the first and after the last sample), the declared
//! velocities and accelerations, and their agreement with the positions.

use crate::record::Joints;
use crate::samples::JointSamples;

/// Joint velocity (rad/s), acceleration (rad/s²) and jerk (rad/s³) limits, one per joint of the
/// arm, base to tip.
#[derive(Clone, Debug, PartialEq)]
pub struct JointDynamics {
    /// Largest joint speed.
    pub velocity: Vec<f64>,
    /// Largest joint acceleration.
    pub acceleration: Vec<f64>,
    /// Largest joint jerk.
    pub jerk: Vec<f64>,
}

/// Relative slack on every velocity, acceleration and jerk limit (float rounding).
pub const DYNAMICS_LIMIT_SLACK: f64 = 1e-6;

/// A declared velocity or acceleration at the first or last sample may differ from zero by
/// this much (rad/s, rad/s²).
pub const REST_TOLERANCE: f64 = 1e-12;

/// Samples of rest the check puts before the first and after the last sample (at the first and
/// last gap), as a controller that holds the arm there sees it.
const REST_PADDING: usize = 3;

/// Which dynamic check a sample fails.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum DynamicsCheck {
    /// The first or last sample declares a velocity or acceleration other than zero.
    Rest,
    /// A velocity, acceleration or jerk passes its limit.
    Limit {
        /// 1-based joint number.
        joint: usize,
    },
    /// Declared velocities or accelerations disagree with the positions (trapezoid rule).
    Agreement {
        /// 1-based joint number.
        joint: usize,
    },
}

/// What the dynamic check measured, per joint: the largest value found as a fraction of the
/// limit.
#[derive(Clone, Debug, PartialEq)]
pub struct DynamicsReport {
    /// Largest `|q̇| / v_max` (declared or from positions).
    pub peak_velocity_fraction: Vec<f64>,
    /// Largest `|q̈| / a_max` (declared or from positions).
    pub peak_acceleration_fraction: Vec<f64>,
    /// Largest `|q⃛| / j_max` (from declared accelerations or from positions).
    pub peak_jerk_fraction: Vec<f64>,
}

/// A sample that fails a dynamic check.
#[derive(Clone, Debug, PartialEq)]
pub struct DynamicsFailure {
    /// Index of the sample.
    pub sample: usize,
    /// The check.
    pub check: DynamicsCheck,
    /// What is wrong, with the values.
    pub problem: String,
}

/// Verifies `samples` (with declared velocities and accelerations) against `limits`:
///
/// 1. rest: the first and last samples declare `|q̇|, |q̈| ≤` [`REST_TOLERANCE`];
/// 2. declared values: `|q̇_i| ≤ v_i`, `|q̈_i| ≤ a_i`, and `|q̈_{k+1} − q̈_k| / Δt ≤ j_i`;
/// 3. positions: `m!` times the divided difference of order `m = 1, 2, 3` over every `m + 1`
///    consecutive samples (a weighted average of the `m`-th derivative there, so any motion
///    within the limits passes) within the velocity, acceleration and jerk limits, with the arm
///    at rest for three samples before the first and after the last;
/// 4. agreement, by the trapezoid rule: `|Δq − Δt (q̇_k + q̇_{k+1}) / 2| ≤ Δt³ j_i / 6` and
///    `|Δq̇ − Δt (q̈_k + q̈_{k+1}) / 2| ≤ Δt² j_i / 2` (twice what a motion whose jerk stays within
///    `j_i` can produce), plus `10⁻¹² (1 + |value|)` for rounding.
///
/// Limits get the relative slack [`DYNAMICS_LIMIT_SLACK`] and, for divided differences, the
/// rounding of the positions (`m! 2^m 10⁻¹⁵ (1 + |q|) / Δt^m`). Samples without declared
/// velocities or accelerations fail at sample 0.
pub fn check_dynamics(
    samples: &JointSamples,
    limits: &JointDynamics,
) -> Result<DynamicsReport, DynamicsFailure> {
    let (Some(qd), Some(qdd)) = (&samples.qd, &samples.qdd) else {
        return Err(DynamicsFailure::at(
            0,
            DynamicsCheck::Rest,
            "the file declares no velocities and accelerations, so rest and limits cannot be \
             checked"
                .to_string(),
        ));
    };
    check_rest(samples.len(), qd, qdd, limits.velocity.len())?;
    let mut peaks = PeakLimits::new(limits);
    peaks.check_declared(samples, qd, qdd)?;
    peaks.check_positions(samples)?;
    check_agreement(samples, qd, qdd, limits)?;
    Ok(peaks.report())
}

impl DynamicsFailure {
    /// The failure of check `check` at sample `sample`, `problem` saying what is wrong.
    fn at(sample: usize, check: DynamicsCheck, problem: String) -> Self {
        DynamicsFailure {
            sample,
            check,
            problem,
        }
    }
}

/// Fails unless the first and last of `n` samples declare velocities `qd` and accelerations
/// `qdd` of zero (within [`REST_TOLERANCE`]) for each of the `joints`.
fn check_rest(
    n: usize,
    qd: &[Joints],
    qdd: &[Joints],
    joints: usize,
) -> Result<(), DynamicsFailure> {
    for (k, name) in [(0, "first"), (n - 1, "last")] {
        for i in 0..joints {
            if qd[k][i].abs() > REST_TOLERANCE || qdd[k][i].abs() > REST_TOLERANCE {
                return Err(DynamicsFailure::at(
                    k,
                    DynamicsCheck::Rest,
                    format!(
                        "the {name} point is not at rest: joint {} velocity {} rad/s, \
                         acceleration {} rad/s²",
                        i + 1,
                        qd[k][i],
                        qdd[k][i]
                    ),
                ));
            }
        }
    }
    Ok(())
}

/// The velocity, acceleration and jerk limits (orders 0, 1 and 2) and, per order and joint,
/// the largest value met so far as a fraction of its limit.
struct PeakLimits<'l> {
    /// Number of joints checked: as many as velocity limits.
    joints: usize,
    /// Limits of each order, per joint.
    bounds: [&'l [f64]; 3],
    /// Largest fraction of the limit met, per order and joint.
    peaks: [Vec<f64>; 3],
}

impl<'l> PeakLimits<'l> {
    /// Nothing met yet of `limits`.
    fn new(limits: &'l JointDynamics) -> Self {
        let joints = limits.velocity.len();
        PeakLimits {
            joints,
            bounds: [&limits.velocity, &limits.acceleration, &limits.jerk],
            peaks: [vec![0.0_f64; joints], vec![0.0; joints], vec![0.0; joints]],
        }
    }

    /// Records `value` of order `order` at sample `k` and fails when a joint passes its limit
    /// (with the relative slack and `rounding`); `what` says where the value comes from.
    fn limit(
        &mut self,
        k: usize,
        order: usize,
        what: &str,
        value: &Joints,
        rounding: f64,
    ) -> Result<(), DynamicsFailure> {
        let names = ["velocity", "acceleration", "jerk"];
        let bounds = self.bounds[order];
        for i in 0..self.joints {
            let fraction = value[i].abs() / bounds[i];
            self.peaks[order][i] = self.peaks[order][i].max(fraction);
            if value[i].abs() > bounds[i] * (1.0 + DYNAMICS_LIMIT_SLACK) + rounding {
                return Err(DynamicsFailure::at(
                    k,
                    DynamicsCheck::Limit { joint: i + 1 },
                    format!(
                        "joint {} {} {what} is {}, {fraction:.6} × its limit {}",
                        i + 1,
                        names[order],
                        value[i],
                        bounds[i]
                    ),
                ));
            }
        }
        Ok(())
    }

    /// Holds the declared velocities `qd`, accelerations `qdd` and the jerk between
    /// consecutive declared accelerations to their limits.
    fn check_declared(
        &mut self,
        samples: &JointSamples,
        qd: &[Joints],
        qdd: &[Joints],
    ) -> Result<(), DynamicsFailure> {
        for k in 0..samples.len() {
            self.limit(k, 0, "(declared, rad/s)", &qd[k], 0.0)?;
            self.limit(k, 1, "(declared, rad/s²)", &qdd[k], 0.0)?;
            if k > 0 {
                let gap = samples.time_s[k] - samples.time_s[k - 1];
                let jerk = (qdd[k] - qdd[k - 1]) / gap;
                self.limit(k, 2, "(from declared accelerations, rad/s³)", &jerk, 0.0)?;
            }
        }
        Ok(())
    }

    /// Holds the divided differences of order 1 to 3 of the rest-padded positions to the
    /// velocity, acceleration and jerk limits, with the rounding of the positions.
    fn check_positions(&mut self, samples: &JointSamples) -> Result<(), DynamicsFailure> {
        let n = samples.len();
        let padded = rest_padded(samples);
        let scale = 1.0 + samples.q.iter().map(|q| q.amax()).fold(0.0, f64::max);
        let units = ["rad/s", "rad/s²", "rad/s³"];
        for order in 1..=3 {
            let factorial = [1.0, 1.0, 2.0, 6.0][order];
            for start in 0..padded.len() - order {
                let points = &padded[start..=start + order];
                let span = points[order].0 - points[0].0;
                let gap = span / order as f64;
                let rounding =
                    factorial * 2f64.powi(order as i32) * 1e-15 * scale / gap.powi(order as i32);
                let value = divided_difference(points) * factorial;
                let sample = (start + order).saturating_sub(REST_PADDING).min(n - 1);
                let what = format!("(from positions, {})", units[order - 1]);
                self.limit(sample, order - 1, &what, &value, rounding)?;
            }
        }
        Ok(())
    }

    /// The largest fractions met, as the report of the check.
    fn report(self) -> DynamicsReport {
        let [
            peak_velocity_fraction,
            peak_acceleration_fraction,
            peak_jerk_fraction,
        ] = self.peaks;
        DynamicsReport {
            peak_velocity_fraction,
            peak_acceleration_fraction,
            peak_jerk_fraction,
        }
    }
}

/// Fails where the declared velocities `qd` and accelerations `qdd` do not integrate, by the
/// trapezoid rule, to the changes of position and of velocity between consecutive samples.
fn check_agreement(
    samples: &JointSamples,
    qd: &[Joints],
    qdd: &[Joints],
    limits: &JointDynamics,
) -> Result<(), DynamicsFailure> {
    for k in 1..samples.len() {
        let h = samples.time_s[k] - samples.time_s[k - 1];
        for i in 0..limits.velocity.len() {
            let checks = [
                (
                    samples.q[k][i] - samples.q[k - 1][i],
                    h * (qd[k][i] + qd[k - 1][i]) / 2.0,
                    h.powi(3) * limits.jerk[i] / 6.0,
                    "position change",
                    "velocities",
                ),
                (
                    qd[k][i] - qd[k - 1][i],
                    h * (qdd[k][i] + qdd[k - 1][i]) / 2.0,
                    h.powi(2) * limits.jerk[i] / 2.0,
                    "velocity change",
                    "accelerations",
                ),
            ];
            for (change, integral, bound, what, declared) in checks {
                let tolerance = bound + 1e-12 * (1.0 + change.abs());
                if (change - integral).abs() > tolerance {
                    return Err(DynamicsFailure::at(
                        k,
                        DynamicsCheck::Agreement { joint: i + 1 },
                        format!(
                            "joint {}: {what} {change} over {h} s, but the declared {declared} \
                             integrate to {integral} (tolerance {tolerance:e})",
                            i + 1
                        ),
                    ));
                }
            }
        }
    }
    Ok(())
}

/// `(t, q)` of every sample with [`REST_PADDING`] samples of rest before and after.
fn rest_padded(samples: &JointSamples) -> Vec<(f64, Joints)> {
    let n = samples.len();
    let t = &samples.time_s;
    let (first_gap, last_gap) = if n > 1 {
        (t[1] - t[0], t[n - 1] - t[n - 2])
    } else {
        (1.0, 1.0)
    };
    let before = (1..=REST_PADDING)
        .rev()
        .map(|i| (t[0] - i as f64 * first_gap, samples.q[0]));
    let after = (1..=REST_PADDING).map(|i| (t[n - 1] + i as f64 * last_gap, samples.q[n - 1]));
    before
        .chain(t.iter().copied().zip(samples.q.iter().copied()))
        .chain(after)
        .collect()
}

/// The divided difference `f[t_0, …, t_m]` of at most four points.
fn divided_difference(points: &[(f64, Joints)]) -> Joints {
    let mut table = [Joints::zeros(); 4];
    for (entry, point) in table.iter_mut().zip(points) {
        *entry = point.1;
    }
    for level in 1..points.len() {
        for i in 0..points.len() - level {
            table[i] = (table[i + 1] - table[i]) / (points[i + level].0 - points[i].0);
        }
    }
    table[0]
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::record::MAX_JOINTS;

    /// Every joint moving by `q(t) = c (1 − cos(ω t))²` over one period (ω = 2π): at rest, with
    /// zero acceleration, at both ends; sampled every `h` seconds with exact derivatives.
    fn samples(h: f64, c: f64) -> (JointSamples, [f64; 3]) {
        let omega = std::f64::consts::TAU;
        let n = (1.0 / h).round() as usize;
        let (mut time_s, mut q, mut qd, mut qdd) = (vec![], vec![], vec![], vec![]);
        for k in 0..=n {
            let t = k as f64 * h;
            let (s, co) = libm::sincos(omega * t);
            let value = c * (1.0 - co).powi(2);
            let velocity = 2.0 * c * (1.0 - co) * omega * s;
            let acceleration = 2.0 * c * omega * omega * (s * s + (1.0 - co) * co);
            time_s.push(t);
            q.push(Joints::from_element(value));
            qd.push(Joints::from_element(velocity));
            qdd.push(Joints::from_element(acceleration));
        }
        // The continuous peaks of |q̇|, |q̈| and |q⃛| = 2cω³ |sin(ωt) (4 cos(ωt) − 1)|.
        let mut peaks = [0.0_f64; 3];
        for k in 0..=1_000_000 {
            let (s, co) = libm::sincos(omega * k as f64 * 1e-6);
            peaks[0] = peaks[0].max((2.0 * c * (1.0 - co) * omega * s).abs());
            peaks[1] = peaks[1].max((2.0 * c * omega * omega * (s * s + (1.0 - co) * co)).abs());
            peaks[2] = peaks[2].max((2.0 * c * omega.powi(3) * s * (4.0 * co - 1.0)).abs());
        }
        (
            JointSamples {
                time_s,
                q,
                qd: Some(qd),
                qdd: Some(qdd),
            },
            peaks,
        )
    }

    fn limits(peaks: [f64; 3], factor: f64) -> JointDynamics {
        JointDynamics {
            velocity: vec![peaks[0] * factor; MAX_JOINTS],
            acceleration: vec![peaks[1] * factor; MAX_JOINTS],
            jerk: vec![peaks[2] * factor; MAX_JOINTS],
        }
    }

    #[test]
    fn a_smooth_rest_to_rest_motion_passes_and_reports_its_peaks() {
        let (motion, peaks) = samples(1e-3, 0.1);
        let report = check_dynamics(&motion, &limits(peaks, 1.0)).unwrap();
        assert!(
            report
                .peak_velocity_fraction
                .iter()
                .all(|f| *f > 0.99 && *f <= 1.0)
        );
        assert!(
            report
                .peak_acceleration_fraction
                .iter()
                .all(|f| *f > 0.85 && *f <= 1.0)
        );
        assert!(
            report
                .peak_jerk_fraction
                .iter()
                .all(|f| *f > 0.3 && *f <= 1.0)
        );
    }

    #[test]
    fn each_limit_is_enforced() {
        let (motion, peaks) = samples(1e-3, 0.1);
        for (order, name) in ["velocity", "acceleration", "jerk"].iter().enumerate() {
            let mut tight = limits(peaks, 1.0);
            let (limit, factor) = match order {
                0 => (&mut tight.velocity, 0.9),
                1 => (&mut tight.acceleration, 0.7),
                _ => (&mut tight.jerk, 0.2),
            };
            limit.iter_mut().for_each(|value| *value *= factor);
            let failure = check_dynamics(&motion, &tight).unwrap_err();
            assert!(
                matches!(failure.check, DynamicsCheck::Limit { joint: 1 }),
                "{failure:?}"
            );
            assert!(failure.problem.contains(name), "{}", failure.problem);
        }
    }

    #[test]
    fn a_motion_that_does_not_start_at_rest_fails() {
        let (mut motion, peaks) = samples(1e-3, 0.1);
        motion.qd.as_mut().unwrap()[0][3] = 1e-6;
        let failure = check_dynamics(&motion, &limits(peaks, 1.0)).unwrap_err();
        assert_eq!((failure.sample, failure.check), (0, DynamicsCheck::Rest));
        // A jump out of rest shows in the positions' jerk even with consistent declarations.
        let (mut motion, peaks) = samples(1e-3, 0.1);
        for q in &mut motion.q[1..] {
            *q += Joints::from_element(1e-5);
        }
        let failure = check_dynamics(&motion, &limits(peaks, 1.0)).unwrap_err();
        assert!(matches!(
            failure.check,
            DynamicsCheck::Limit { .. } | DynamicsCheck::Agreement { .. }
        ));
    }

    #[test]
    fn declared_values_must_agree_with_the_positions() {
        let (mut motion, peaks) = samples(1e-3, 0.1);
        motion.qd.as_mut().unwrap()[500][2] += 1e-3;
        let failure = check_dynamics(&motion, &limits(peaks, 1.0)).unwrap_err();
        assert_eq!(
            failure.check,
            DynamicsCheck::Agreement { joint: 3 },
            "{failure:?}"
        );
    }
}
