//! Joint-velocity limits by time scaling: a rollout whose steps would be too fast keeps the same
//! geometric path, stretches those steps in time so every joint stays within its share of the
//! limit, and the independent checker verifies the speeds from positions and timestamps.

mod common;

use emg_control::{CheckRollout, ConstraintConfig, RolloutConfig, VelocityLimitFraction};

use common::{checker, classical, robot, tasks};

fn config(fraction: Option<f64>) -> RolloutConfig {
    RolloutConfig {
        constraints: ConstraintConfig {
            velocity_limit_fraction: fraction.map(|f| VelocityLimitFraction::new(f).unwrap()),
            ..ConstraintConfig::default()
        },
        ..RolloutConfig::default()
    }
}

/// Peak joint speed of a trajectory as a fraction of each joint's limit, from positions and times.
fn peak_speed_ratio(trajectory: &emg_control::Trajectory, limits: &[f64]) -> f64 {
    trajectory
        .steps
        .windows(2)
        .flat_map(|pair| {
            let elapsed = pair[1].time_s - pair[0].time_s;
            (0..7).map(move |i| (pair[1].q[i] - pair[0].q[i]).abs() / elapsed / limits[i])
        })
        .fold(0.0, f64::max)
}

#[test]
fn time_scaling_keeps_the_path_and_honours_the_limits() {
    let robot = robot();
    let checker = checker();
    let limits = checker.velocity_limits();
    let free = config(None);
    // A tenth of the limits makes most steps too fast.
    let slow = config(Some(0.1));
    let mut stretched_tasks = 0;
    for (_, task) in tasks(&robot, 40) {
        let unlimited = classical(&robot, &task, &free);
        let limited = classical(&robot, &task, &slow);
        assert_eq!(unlimited.steps.len(), limited.steps.len());
        assert_eq!(unlimited.termination, limited.termination);
        assert_eq!(unlimited.path_length_m, limited.path_length_m);
        for (a, b) in unlimited.steps.iter().zip(&limited.steps) {
            assert_eq!(a.q, b.q, "time scaling must not change the shape");
            assert!(b.time_s >= a.time_s - 1e-12);
        }
        checker
            .check(&task, &limited, &slow.constraints)
            .expect("the limited rollout holds the limits");
        assert!(peak_speed_ratio(&limited, &limits) <= 0.1 * (1.0 + 1e-9));
        let unlimited_peak = peak_speed_ratio(&unlimited, &limits);
        if unlimited_peak > 0.1 {
            stretched_tasks += 1;
            let last = |t: &emg_control::Trajectory| t.steps.last().unwrap().time_s;
            assert!(last(&limited) > last(&unlimited));
            // The unlimited rollout breaks the 10 % limit, and the checker says so.
            let failure = checker
                .check(&task, &unlimited, &slow.constraints)
                .expect_err("too fast for 10 % of the limits");
            assert!(failure.problem.contains("rad/s"), "{failure}");
        }
    }
    assert!(
        stretched_tasks > 20,
        "only {stretched_tasks} tasks needed scaling"
    );
}

#[test]
fn unstretched_steps_last_exactly_dt() {
    let robot = robot();
    let full = config(Some(1.0));
    let (_, task) = tasks(&robot, 1).remove(0);
    let trajectory = classical(&robot, &task, &full);
    let limits = robot.limits().velocity;
    for pair in trajectory.steps.windows(2) {
        let elapsed = pair[1].time_s - pair[0].time_s;
        let needed = (0..7)
            .map(|i| (pair[1].q[i] - pair[0].q[i]).abs() / full.dt_s / limits[i])
            .fold(1.0, f64::max);
        assert!(
            (elapsed - full.dt_s * needed).abs() < 1e-12,
            "{elapsed} vs {needed}"
        );
    }
}

#[test]
fn fraction_outside_the_unit_interval_is_an_error_naming_the_field() {
    for bad in ["0.0", "1.5", "-0.2"] {
        let json = format!("{{\"velocity_limit_fraction\": {bad}}}");
        let error = serde_json::from_str::<ConstraintConfig>(&json).unwrap_err();
        assert!(
            error.to_string().contains("velocity_limit_fraction"),
            "{error}"
        );
    }
    let off: ConstraintConfig =
        serde_json::from_str("{\"velocity_limit_fraction\": null}").unwrap();
    assert_eq!(off.velocity_limit_fraction, None);
    let default: ConstraintConfig = serde_json::from_str("{}").unwrap();
    assert_eq!(
        default.velocity_limit_fraction,
        Some(VelocityLimitFraction::FULL)
    );
}
