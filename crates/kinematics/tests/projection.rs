//! Newton projection onto an exact pose: from random reachable poses `FK(q*)` and starts
//! `q* + U(−0.2, 0.2)` rad per joint, the projection reaches the position and the tool axis to
//! 1e-9 (and the TCP x-axis with a roll target), inside the limits (and margin); bad targets
//! are rejected by field; an unreachable target is an honest `NotConverged`, not a panic. The
//! projection onto a TCP position alone reaches it from the same starts, and not a point out of
//! reach.

mod common;

use common::{angle_between, random_q, random_unit, rng, robot};
use emg_kinematics::{
    JointVector, POINT_TOLERANCE_M, PoseTarget, ProjectionConfig, ProjectionError, Vec3,
    project_to_point, project_to_pose,
};
use rand::RngExt;

const TRIALS: usize = 500;

#[test]
fn converges_to_position_and_tool_axis_from_perturbed_starts() {
    let robot = robot();
    let cfg = ProjectionConfig::default();
    let mut rng = rng(30);
    let (mut converged, mut worst_p, mut worst_angle, mut most_iterations) = (0, 0.0f64, 0.0f64, 0);
    let mut failures = Vec::new();
    for _ in 0..TRIALS {
        let q_star = random_q(&mut rng, &robot);
        let kin = robot.forward(&q_star);
        let target = PoseTarget {
            position: kin.tcp(),
            tool_axis: kin.tool_axis(),
            roll_axis: None,
        };
        let start = q_star + JointVector::from_fn(|_, _| rng.random_range(-0.2..0.2));
        match project_to_pose(&robot, &start, &target, &cfg) {
            Ok((q, iterations)) => {
                converged += 1;
                most_iterations = most_iterations.max(iterations);
                let reached = robot.forward(&q);
                worst_p = worst_p.max((reached.tcp() - target.position).norm());
                worst_angle =
                    worst_angle.max(angle_between(&reached.tool_axis(), &target.tool_axis));
                assert!(
                    robot.limits().first_violation(&q, 0.0).is_none(),
                    "result outside limits: {q:?}"
                );
            }
            Err(ProjectionError::NotConverged {
                position_error_m,
                orientation_error_rad,
                ..
            }) => {
                // An honest failure reports a real remaining error.
                assert!(
                    position_error_m >= cfg.position_tolerance_m
                        || orientation_error_rad >= cfg.orientation_tolerance_rad
                );
                failures.push((position_error_m, orientation_error_rad));
            }
            Err(other) => panic!("unexpected error {other}"),
        }
    }
    println!(
        "projection without roll: {converged}/{TRIALS} converged (≤ {most_iterations} iterations), \
         worst position {worst_p:.3e} m, worst tool-axis angle {worst_angle:.3e} rad; failures {failures:?}"
    );
    assert!(
        converged >= TRIALS * 99 / 100,
        "only {converged}/{TRIALS} converged"
    );
    assert!(worst_p < 1e-9, "position error {worst_p:e}");
    assert!(worst_angle < 1e-9, "tool-axis angle {worst_angle:e}");
}

#[test]
fn converges_with_roll_target_and_joint_margin() {
    let robot = robot();
    let cfg = ProjectionConfig {
        joint_margin_rad: 0.05,
        ..ProjectionConfig::default()
    };
    let mut rng = rng(31);
    let (mut converged, mut attempted, mut worst_p, mut worst_angle, mut worst_roll) =
        (0, 0, 0.0f64, 0.0f64, 0.0f64);
    while attempted < TRIALS {
        let q_star = random_q(&mut rng, &robot);
        if robot
            .limits()
            .first_violation(&q_star, cfg.joint_margin_rad)
            .is_some()
        {
            continue;
        }
        attempted += 1;
        let kin = robot.forward(&q_star);
        let n = kin.tool_axis();
        let x_star = kin.tcp_rotation().column(0).into_owned();
        // A motion direction whose component ⟂ n is q*'s TCP x-axis (plus an arbitrary part
        // along n that the target construction must remove).
        let d = x_star * rng.random_range(0.2..2.0) + n * rng.random_range(-1.0..1.0);
        let target = PoseTarget::with_roll_from_direction(kin.tcp(), n, d);
        assert!((target.roll_axis.expect("roll set") - x_star).norm() < 1e-12);
        let start = q_star + JointVector::from_fn(|_, _| rng.random_range(-0.2..0.2));
        if let Ok((q, _)) = project_to_pose(&robot, &start, &target, &cfg) {
            converged += 1;
            let reached = robot.forward(&q);
            worst_p = worst_p.max((reached.tcp() - target.position).norm());
            worst_angle = worst_angle.max(angle_between(&reached.tool_axis(), &n));
            let x = reached.tcp_rotation().column(0).into_owned();
            worst_roll = worst_roll.max(angle_between(&x, &x_star));
            assert!(
                robot
                    .limits()
                    .first_violation(&q, cfg.joint_margin_rad - 1e-12)
                    .is_none(),
                "result violates the 0.05 rad margin: {q:?}"
            );
        }
    }
    println!(
        "projection with roll and 0.05 rad margin: {converged}/{TRIALS} converged, worst position \
         {worst_p:.3e} m, tool-axis angle {worst_angle:.3e} rad, x-axis angle {worst_roll:.3e} rad"
    );
    assert!(
        converged >= TRIALS * 99 / 100,
        "only {converged}/{TRIALS} converged"
    );
    assert!(worst_p < 1e-9, "position error {worst_p:e}");
    assert!(worst_angle < 1e-9, "tool-axis angle {worst_angle:e}");
    assert!(worst_roll < 1e-9, "x-axis angle {worst_roll:e}");
}

#[test]
fn rejects_bad_targets_by_field() {
    let robot = robot();
    let cfg = ProjectionConfig::default();
    let start = robot.mid_range();
    let position = robot.forward(&start).tcp();
    let non_unit = PoseTarget {
        position,
        tool_axis: Vec3::new(0.0, 0.0, -2.0),
        roll_axis: None,
    };
    match project_to_pose(&robot, &start, &non_unit, &cfg) {
        Err(ProjectionError::BadTarget { field, .. }) => assert_eq!(field, "tool_axis"),
        other => panic!("expected BadTarget(tool_axis), got {other:?}"),
    }
    let error = project_to_pose(&robot, &start, &non_unit, &cfg).unwrap_err();
    assert!(error.to_string().contains("tool_axis"), "message: {error}");

    let nan_position = PoseTarget {
        position: Vec3::new(f64::NAN, 0.0, 0.5),
        tool_axis: Vec3::new(0.0, 0.0, -1.0),
        roll_axis: None,
    };
    assert!(matches!(
        project_to_pose(&robot, &start, &nan_position, &cfg),
        Err(ProjectionError::BadTarget {
            field: "position",
            ..
        })
    ));

    let skew_roll = PoseTarget {
        position,
        tool_axis: Vec3::new(0.0, 0.0, -1.0),
        roll_axis: Some(Vec3::new(0.0, 0.6, 0.8)),
    };
    assert!(matches!(
        project_to_pose(&robot, &start, &skew_roll, &cfg),
        Err(ProjectionError::BadTarget {
            field: "roll_axis",
            ..
        })
    ));
}

#[test]
fn unreachable_target_fails_honestly() {
    let robot = robot();
    let cfg = ProjectionConfig::default();
    let mut rng = rng(32);
    let (centre, radius) = robot.reach_sphere();
    for _ in 0..20 {
        let start = random_q(&mut rng, &robot);
        let kin = robot.forward(&start);
        let far = kin.tcp() + random_unit(&mut rng) * 5.0;
        assert!(
            (far - centre).norm() > radius,
            "the target must be outside the reach sphere"
        );
        let target = PoseTarget {
            position: far,
            tool_axis: kin.tool_axis(),
            roll_axis: None,
        };
        match project_to_pose(&robot, &start, &target, &cfg) {
            Err(ProjectionError::NotConverged {
                iterations,
                position_error_m,
                ..
            }) => {
                assert_eq!(iterations, cfg.max_iterations);
                assert!(
                    position_error_m > 3.0,
                    "reported position error {position_error_m}"
                );
            }
            other => panic!("expected NotConverged, got {other:?}"),
        }
    }
}

#[test]
fn a_point_is_reached_from_perturbed_starts_and_an_unreachable_one_is_not() {
    let robot = robot();
    let mut rng = rng(31);
    let mut converged = 0;
    for _ in 0..TRIALS {
        let q_star = random_q(&mut rng, &robot);
        let point = robot.forward(&q_star).tcp();
        let start = q_star + robot.configuration_from_fn(|_| rng.random_range(-0.2..0.2));
        if let Some(q) = project_to_point(&robot, &start, &point) {
            converged += 1;
            let off = (robot.forward(&q).tcp() - point).norm();
            assert!(off <= POINT_TOLERANCE_M, "{off} m off the point");
        }
    }
    assert!(converged >= TRIALS * 95 / 100, "{converged} of {TRIALS}");
    let far = Vec3::new(3.0, 0.0, 0.5);
    assert_eq!(project_to_point(&robot, &robot.mid_range(), &far), None);
}
