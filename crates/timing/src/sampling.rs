//! A motion along a joint path sampled at a rate: the samples of a speed profile along it, and
//! the sample at rest.

use emg_kinematics::JointVector;

use crate::dynamics::TimedSample;
use crate::profile::{PathState, SmoothedProfile};
use crate::spline::JointSpline;

/// A sample at rest at `q` at time 0.
pub(crate) fn at_rest(q: JointVector) -> TimedSample {
    TimedSample {
        time_ns: 0,
        q,
        qd: JointVector::zeros(),
        qdd: JointVector::zeros(),
    }
}

/// Appends the samples of `profile` along a joint path, `path(s)` its point, first and second
/// derivatives by the path parameter, every `1 / rate_hz` from `elapsed` periods on (the last
/// at `end`, at rest); returns the periods elapsed after them.
pub(crate) fn push_samples(
    profile: &SmoothedProfile,
    rate_hz: f64,
    elapsed: u64,
    end: &JointVector,
    samples: &mut Vec<TimedSample>,
    path: impl Fn(f64) -> (JointVector, JointVector, JointVector),
) -> u64 {
    let period_ns = 1e9 / rate_hz;
    let duration = profile.duration();
    let last = ((duration * rate_hz).ceil() as u64).max(1);
    let mut hints = [0, 0];
    for k in 1..=last {
        let time_ns = ((elapsed + k) as f64 * period_ns).round() as u64;
        if k == last {
            samples.push(TimedSample {
                time_ns,
                q: *end,
                qd: JointVector::zeros(),
                qdd: JointVector::zeros(),
            });
            break;
        }
        let state = profile.state_from(k as f64 / rate_hz, &mut hints);
        let (q, dq, ddq) = path(state.s);
        samples.push(TimedSample {
            time_ns,
            q,
            qd: dq * state.sd,
            qdd: dq * state.sdd + ddq * (state.sd * state.sd),
        });
    }
    elapsed + last
}

/// The motion sampled at `k / rate_hz` (rounded to whole nanoseconds) for `k = 0, 1, …` up to
/// the first sample at or after the end, with the path state of each sample.
pub(crate) fn sample(
    spline: &JointSpline,
    profile: &SmoothedProfile,
    rate_hz: f64,
) -> (Vec<TimedSample>, Vec<PathState>) {
    let duration = profile.duration();
    let count = (duration * rate_hz - 1e-9).ceil().max(1.0) as u64;
    let (mut profile_hints, mut segment) = ([0, 0], 0);
    (0..=count)
        .map(|k| {
            let time_ns = (k as f64 * 1e9 / rate_hz).round() as u64;
            let state = profile.state_from(time_ns as f64 * 1e-9, &mut profile_hints);
            let point = spline.eval_from(state.s, &mut segment);
            let sample = TimedSample {
                time_ns,
                q: point.q,
                qd: point.dq * state.sd,
                qdd: point.dq * state.sdd + point.ddq * (state.sd * state.sd),
            };
            (sample, state)
        })
        .unzip()
}
