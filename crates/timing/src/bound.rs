//! The least time any motion needs: lower bounds on a program's duration, against which its
//! timing is measured (docs/jobs.md, "cycle time").
//!
//! A joint that moves a distance `d` from rest to rest with its speed, acceleration and jerk
//! bounded by `v`, `a` and `j` needs at least the time of the double-S profile (jerk ±`j`,
//! then acceleration held at `a`, then speed held at `v`, each phase only where the distance
//! leaves room for it): that profile drives every bound to its limit for as long as the
//! distance allows, so no motion within the limits covers `d` sooner. A motion of the whole arm
//! between two configurations needs at least its slowest joint's time.

use emg_kinematics::JointVector;

use crate::limits::DynamicLimits;

/// Least time (s) in which a joint moves `distance` (rad, either sign) from rest to rest with
/// its speed within `velocity`, its acceleration within `acceleration` and its jerk within
/// `jerk` (rad/s, rad/s², rad/s³; a jerk that is not finite and positive bounds nothing): the
/// duration of the symmetric double-S profile.
///
/// With `Tj = a/j`, the time acceleration takes to build up:
/// - speed reached: `T = Ta + d/v`, where the speed-up takes `Ta = v/a + Tj` (acceleration
///   reached, `v·j ≥ a²`) or `2·√(v/j)`;
/// - acceleration reached, speed not: `T = 2·Ta`, `Ta = (Tj + √(Tj² + 4·d/a))/2`;
/// - neither: `T = 4·∛(d/(2·j))`.
pub fn rest_to_rest_s(distance: f64, velocity: f64, acceleration: f64, jerk: f64) -> f64 {
    let d = distance.abs();
    if d == 0.0 {
        return 0.0;
    }
    let (v, a) = (velocity, acceleration);
    let jerk_bounded = jerk.is_finite() && jerk > 0.0;
    let tj = if jerk_bounded { a / jerk } else { 0.0 };
    // The time to reach full speed, and the distance that covers.
    let speed_up_s = if !jerk_bounded || v * jerk >= a * a {
        v / a + tj
    } else {
        2.0 * (v / jerk).sqrt()
    };
    if d >= v * speed_up_s {
        return speed_up_s + d / v;
    }
    if jerk_bounded {
        let ramp_s = libm::cbrt(d / (2.0 * jerk));
        if jerk * ramp_s <= a {
            return 4.0 * ramp_s;
        }
    }
    tj + (tj * tj + 4.0 * d / a).sqrt()
}

/// Least time (s) in which the arm moves from rest at `from` to rest at `to` within `limits`:
/// the largest of its joints' [`rest_to_rest_s`].
pub fn least_move_s(from: &JointVector, to: &JointVector, limits: &DynamicLimits) -> f64 {
    (0..from.len())
        .map(|j| {
            rest_to_rest_s(
                to[j] - from[j],
                limits.velocity[j],
                limits.acceleration[j],
                limits.jerk[j],
            )
        })
        .fold(0.0, f64::max)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The distance covered, and the largest speed and acceleration reached, by the motion
    /// that applies jerk `+j, 0, −j, 0, −j, 0, +j` for the given phase durations, integrated
    /// exactly phase by phase.
    fn double_s(phases: [f64; 7], j: f64) -> (f64, f64, f64) {
        let jerks = [j, 0.0, -j, 0.0, -j, 0.0, j];
        let (mut x, mut v, mut a) = (0.0_f64, 0.0_f64, 0.0_f64);
        let (mut top_v, mut top_a) = (0.0_f64, 0.0_f64);
        for (t, jerk) in phases.into_iter().zip(jerks) {
            x += v * t + a * t * t / 2.0 + jerk * t * t * t / 6.0;
            v += a * t + jerk * t * t / 2.0;
            a += jerk * t;
            top_v = top_v.max(v.abs());
            top_a = top_a.max(a.abs());
        }
        assert!(v.abs() < 1e-9 && a.abs() < 1e-9, "the profile ends at rest");
        (x, top_v, top_a)
    }

    #[test]
    fn the_bound_is_the_duration_of_a_double_s_profile_that_covers_the_distance_within_the_limits()
    {
        let (v, a, j) = (2.0, 10.0, 5000.0);
        // Distances in each regime: no phase at full acceleration, no phase at full speed,
        // both; and the limits where full acceleration is never reached before full speed.
        for (d, v, a, j) in [
            (1e-6, v, a, j),
            (0.01, v, a, j),
            (0.3, v, a, j),
            (3.0, v, a, j),
            (0.05, 0.2, 10.0, 100.0),
            (1.0, 0.2, 10.0, 100.0),
        ] {
            let total = rest_to_rest_s(d, v, a, j);
            // The profile of that duration: jerk ramps of `tj` (the shortest of the times the
            // acceleration, the speed and the distance allow them), then either no cruise
            // (the acceleration held for what the duration leaves) or the speed held at `v`.
            let tj = (a / j).min((v / j).sqrt()).min(libm::cbrt(d / (2.0 * j)));
            let top_a = j * tj;
            let no_cruise = total / 2.0;
            let (hold, cruise) = if top_a * (no_cruise - tj) <= v * (1.0 + 1e-9) {
                ((no_cruise - 2.0 * tj).max(0.0), 0.0)
            } else {
                let hold = v / top_a - tj;
                (hold, total - 2.0 * (2.0 * tj + hold))
            };
            let (x, top_v, reached_a) = double_s([tj, hold, tj, cruise, tj, hold, tj], j);
            assert!((x - d).abs() < 1e-9 * d.max(1.0), "{d}: covered {x}");
            assert!(top_v <= v * (1.0 + 1e-9), "{d}: speed {top_v} over {v}");
            assert!(
                reached_a <= a * (1.0 + 1e-9),
                "{d}: acceleration {reached_a}"
            );
            // One limit is reached: a faster profile would break it.
            assert!(
                (top_v - v).abs() < 1e-6 * v
                    || (reached_a - a).abs() < 1e-6 * a
                    || (tj - libm::cbrt(d / (2.0 * j))).abs() < 1e-12,
                "{d}: no limit reached"
            );
        }
    }

    #[test]
    fn no_timed_move_is_quicker_than_the_bound() {
        let request = crate::free::tests::request();
        for k in 0..20 {
            let (a, mut b) = (JointVector::zeros(), JointVector::zeros());
            for j in 0..7 {
                b[j] =
                    (((k * 7 + j) as f64 * 0.618_034).fract() - 0.5) * 10f64.powi(-(k as i32 % 4));
            }
            let samples = crate::time_free_move(&[a, b], &request).samples;
            let duration = samples[samples.len() - 1].time_s();
            let least = least_move_s(&a, &b, &request.limits);
            assert!(
                least > 0.0 && duration >= least,
                "{b:?}: {duration} < {least}"
            );
        }
    }

    #[test]
    fn without_a_jerk_limit_the_bound_is_the_bang_bang_time() {
        assert!(
            (rest_to_rest_s(0.1, 5.0, 10.0, f64::INFINITY) - 2.0 * (0.01_f64).sqrt()).abs() < 1e-12
        );
        // At full speed: the speed-up and slow-down add v/a to d/v.
        assert!((rest_to_rest_s(-4.0, 1.0, 10.0, 0.0) - (4.0 + 0.1)).abs() < 1e-12);
        assert_eq!(rest_to_rest_s(0.0, 1.0, 1.0, 1.0), 0.0);
    }

    #[test]
    fn the_bound_grows_with_the_distance_and_is_continuous() {
        let mut last = 0.0;
        for k in 1..4000 {
            let d = k as f64 * 1e-3;
            let t = rest_to_rest_s(d, 2.62, 10.0, 5000.0);
            let nearby = rest_to_rest_s(d * (1.0 + 1e-9), 2.62, 10.0, 5000.0);
            assert!(t > last, "{d}: {last} → {t}");
            assert!((nearby - t).abs() < 1e-6, "{d}: {t} jumps to {nearby}");
            last = t;
        }
    }
}
