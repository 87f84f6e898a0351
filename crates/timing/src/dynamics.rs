//! Whether sampled joint motion keeps its velocity, acceleration and jerk limits, judged the way a
//! robot controller fed the samples judges it: divided differences of the positions, with the arm
//! at rest before the first and after the last sample, and the declared velocities and
//! accelerations themselves.

use emg_kinematics::{JointVector, MAX_DOF};

use crate::limits::DynamicLimits;

/// One sample of a timed trajectory.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TimedSample {
    /// Time since the start (whole nanoseconds).
    pub time_ns: u64,
    /// Joint positions (rad).
    pub q: JointVector,
    /// Joint velocities (rad/s).
    pub qd: JointVector,
    /// Joint accelerations (rad/s²).
    pub qdd: JointVector,
}

impl TimedSample {
    /// Time since the start (s).
    pub fn time_s(&self) -> f64 {
        self.time_ns as f64 * 1e-9
    }
}

/// A limit broken at a sample.
#[derive(Clone, Debug, PartialEq)]
pub struct LimitBreach {
    /// Index of the sample.
    pub sample: usize,
    /// 1-based joint number.
    pub joint: usize,
    /// What is measured: `velocity`, `acceleration` or `jerk`, declared or from positions.
    pub quantity: &'static str,
    /// The value (rad/s, rad/s², rad/s³).
    pub value: f64,
    /// The limit it passes.
    pub limit: f64,
}

impl std::fmt::Display for LimitBreach {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(
            f,
            "sample {}: joint {} {} {} above its limit {}",
            self.sample, self.joint, self.quantity, self.value, self.limit
        )
    }
}

/// The first limit `samples` break, by [`breaches`].
pub fn first_breach(samples: &[TimedSample], limits: &DynamicLimits) -> Option<LimitBreach> {
    let mut first = None;
    scan(samples, limits, |breach| {
        first = Some(breach);
        false
    });
    first
}

/// Every limit `samples` break (none for fewer than two samples): per joint, `|q̇|`, `|q̈|` and
/// `|Δq̈| / Δt` of the declared values, and the first, second and third divided differences of
/// the positions times 1!, 2!, 3! (each a weighted average of the true derivative over its
/// points, so a motion within the limits passes) with three samples of rest prepended and
/// appended at the first and last gap.
pub fn breaches(samples: &[TimedSample], limits: &DynamicLimits) -> Vec<LimitBreach> {
    let mut all = Vec::new();
    scan(samples, limits, |breach| {
        all.push(breach);
        true
    });
    all
}

/// Calls `visit` with each breach while it returns true.
fn scan(
    samples: &[TimedSample],
    limits: &DynamicLimits,
    mut visit: impl FnMut(LimitBreach) -> bool,
) {
    if samples.len() < 2 {
        return;
    }
    let mut check =
        |sample: usize, quantity: &'static str, value: &JointVector, limit: &JointVector| {
            for j in 0..MAX_DOF {
                if value[j].abs() > limit[j]
                    && !visit(LimitBreach {
                        sample,
                        joint: j + 1,
                        quantity,
                        value: value[j],
                        limit: limit[j],
                    })
                {
                    return false;
                }
            }
            true
        };
    for (k, sample) in samples.iter().enumerate() {
        if !check(k, "declared velocity", &sample.qd, &limits.velocity)
            || !check(
                k,
                "declared acceleration",
                &sample.qdd,
                &limits.acceleration,
            )
        {
            return;
        }
        if k > 0 {
            let gap = (sample.time_ns - samples[k - 1].time_ns) as f64 * 1e-9;
            let jerk = (sample.qdd - samples[k - 1].qdd) / gap;
            if !check(k, "jerk from declared accelerations", &jerk, &limits.jerk) {
                return;
            }
        }
    }
    // Divided differences of the padded positions, all three orders ending at point k + 1:
    // f[t_k, t_{k+1}], f[t_{k−1}, …, t_{k+1}], f[t_{k−2}, …, t_{k+1}].
    let padded = padded(samples);
    let (mut first, mut second): (Option<JointVector>, Option<JointVector>) = (None, None);
    for k in 0..padded.len() - 1 {
        let sample = (k + 1).saturating_sub(PAD).min(samples.len() - 1);
        let (t, q) = (|i: usize| padded[i].0, |i: usize| padded[i].1);
        let d1 = (q(k + 1) - q(k)) / (t(k + 1) - t(k));
        if !check(sample, "velocity from positions", &d1, &limits.velocity) {
            return;
        }
        if let Some(p1) = first {
            let d2 = (d1 - p1) / (t(k + 1) - t(k - 1));
            if !check(
                sample,
                "acceleration from positions",
                &(d2 * 2.0),
                &limits.acceleration,
            ) {
                return;
            }
            if let Some(p2) = second {
                let d3 = (d2 - p2) / (t(k + 1) - t(k - 2));
                if !check(sample, "jerk from positions", &(d3 * 6.0), &limits.jerk) {
                    return;
                }
            }
            second = Some(d2);
        }
        first = Some(d1);
    }
}

/// Samples of rest added before the first and after the last sample.
const PAD: usize = 3;

/// `(time s, q)` with [`PAD`] points of rest at the first and last gap before and after.
fn padded(samples: &[TimedSample]) -> Vec<(f64, JointVector)> {
    let n = samples.len();
    let first_gap = samples[1].time_s() - samples[0].time_s();
    let last_gap = samples[n - 1].time_s() - samples[n - 2].time_s();
    let mut out = Vec::with_capacity(n + 2 * PAD);
    out.extend(
        (1..=PAD)
            .rev()
            .map(|i| (samples[0].time_s() - i as f64 * first_gap, samples[0].q)),
    );
    out.extend(samples.iter().map(|s| (s.time_s(), s.q)));
    out.extend((1..=PAD).map(|i| {
        (
            samples[n - 1].time_s() + i as f64 * last_gap,
            samples[n - 1].q,
        )
    }));
    out
}
