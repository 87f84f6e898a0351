//! The independent trajectory checker (`ReferenceModel`).
//!
//! Positive side: the checker's own kinematics and collision model agree with the library's on
//! random configurations, and every classical rollout passes `check`: 1500 sampled tasks with
//! the default `k_lat = 5`, 300 with `k_lat = 0`, and tasks whose tool axis starts exactly on
//! `n` (recorded angle ≈ 0°).
//! Negative side: every kind of tampering with a recorded trajectory — a joint outside its limit,
//! a TCP moved by 1 mm, a wrong tool angle, a wrong path length, a non-increasing timestamp, NaN
//! in any recorded value, an empty trajectory, an invalid start with extra steps, a termination
//! blamed on a constraint (or a joint number) its rejected configuration does not break, a task
//! line moved 3 cm, a tilted normal, a colliding configuration — is rejected, without panicking,
//! with the offending step named.

mod common;

use emg_control::{
    CheckRollout, ConstraintConfig, RolloutConfig, Task, Termination, Trajectory, Violation,
};
use emg_kinematics::{JointVector, Vec3};
use rayon::prelude::*;

use common::{checker, classical, random_q, rng, robot, tasks};

/// The checker's FK and the library's FK are independent implementations of the same chain.
#[test]
fn checker_kinematics_match_library_and_spec() {
    let robot = robot();
    let checker = checker();
    let mut rng = rng(11);
    for _ in 0..500 {
        let q = random_q(&mut rng, &robot);
        let kin = robot.forward(&q);
        let (tcp, z) = checker.tcp_pose(&q);
        assert!((tcp - kin.tcp()).norm() < 1e-12, "TCP differs at {q:?}");
        assert!(
            (z - kin.tool_axis()).norm() < 1e-12,
            "tool axis differs at {q:?}"
        );
    }
    // SPEC §1 known answers.
    let (tcp, z) = checker.tcp_pose(&emg_verify::Joints::zeros());
    assert!(
        (tcp - Vec3::new(0.088, 0.0, 0.7226)).norm() < 1e-9,
        "{tcp:?}"
    );
    assert!((z - Vec3::new(0.0, 0.0, -1.0)).norm() < 1e-12, "{z:?}");
    use std::f64::consts::{FRAC_PI_2, FRAC_PI_4};
    let home = [
        0.0,
        -FRAC_PI_4,
        0.0,
        -3.0 * FRAC_PI_4,
        0.0,
        FRAC_PI_2,
        FRAC_PI_4,
    ];
    let (tcp, z) = checker.tcp_pose(&emg_verify::Joints::from(home));
    assert!(
        (tcp - Vec3::new(0.306891, 0.0, 0.386882)).norm() < 1e-5,
        "{tcp:?}"
    );
    assert!((z - Vec3::new(0.0, 0.0, -1.0)).norm() < 1e-9, "{z:?}");
    // Joint limits as in SPEC §1.
    let limits = checker.limits();
    assert_eq!(limits.len(), 7);
    for (i, (lo, hi)) in limits.iter().enumerate() {
        assert_eq!(*lo, robot.limits().lower[i]);
        assert_eq!(*hi, robot.limits().upper[i]);
    }
    assert!((limits[3].1 - (-0.1518)).abs() < 1e-12 && (limits[5].0 - 0.5445).abs() < 1e-12);
}

/// Both collision models give the same smallest clearance, hence the same collide/free verdict.
#[test]
fn checker_collision_model_matches_library() {
    let robot = robot();
    let checker = checker();
    let mut rng = rng(12);
    let mut colliding = 0;
    for _ in 0..2000 {
        let q = random_q(&mut rng, &robot);
        let kin = robot.forward(&q);
        let library = robot.min_clearance(&kin).expect("pairs exist").clearance;
        let (reference, a, b) = checker.min_clearance(&q);
        assert!(
            (library - reference).abs() < 1e-9,
            "clearance {library} (library) vs {reference} (checker, {a}–{b}) at {q:?}"
        );
        assert_eq!(
            robot.first_collision(&kin, 0.0).is_some(),
            reference < 0.0,
            "verdicts differ at {q:?}"
        );
        colliding += usize::from(reference < 0.0);
    }
    // The uniform population has a noticeable share of self-collisions; both models must see them.
    assert!(
        colliding > 20 && colliding < 1800,
        "{colliding} of 2000 collide"
    );
}

fn check_all(k_lat: f64, count: usize) -> Vec<(Task, Trajectory)> {
    let robot = robot();
    let checker = checker();
    let config = RolloutConfig {
        lateral_gain_per_s: k_lat,
        ..RolloutConfig::default()
    };
    let tasks = tasks(&robot, count);
    let results: Vec<(Task, Trajectory)> = tasks
        .into_par_iter()
        .map(|(index, task)| {
            let trajectory = classical(&robot, &task, &config);
            if let Err(e) = checker.check(&task, &trajectory, &config.constraints) {
                panic!(
                    "k_lat {k_lat}, candidate {index}: checker rejects the classical rollout: {e}"
                );
            }
            (task, trajectory)
        })
        .collect();
    // The rollouts must be non-trivial for the check to mean anything.
    let long = results.iter().filter(|(_, t)| t.steps.len() > 10).count();
    assert!(
        long * 3 > results.len(),
        "only {long} of {} rollouts exceed 10 steps",
        results.len()
    );
    let steps: usize = results.iter().map(|(_, t)| t.steps.len()).sum();
    assert!(steps > 20 * results.len(), "only {steps} steps in total");
    results
}

#[test]
fn checker_accepts_every_classical_rollout() {
    let results = check_all(5.0, 1500);
    // Every termination reason other than the invalid start appears in a population this size.
    let labels: std::collections::BTreeSet<&str> =
        results.iter().map(|(_, t)| t.termination.label()).collect();
    assert!(
        !labels.contains("invalid_start"),
        "a q0_seed broke a constraint: {labels:?}"
    );
    assert!(labels.contains("joint_limit"), "{labels:?}");
    assert!(labels.contains("tool_cone"), "{labels:?}");
}

#[test]
fn checker_accepts_rollouts_without_lateral_correction() {
    check_all(0.0, 300);
}

/// Tool axis exactly along `n` at the seed (zero tilt): the recorded angle is ~0 and the
/// checker's own angle must agree with it to its tolerance.
#[test]
fn checker_accepts_rollouts_with_zero_tilt() {
    let robot = robot();
    let checker = checker();
    let config = RolloutConfig::default();
    let sampler = emg_control::SamplerConfig {
        max_tilt_deg: 0.0,
        ..Default::default()
    };
    let mut checked = 0;
    for index in 0..300 {
        let Some(task) = emg_control::candidate(&robot, &sampler, index) else {
            continue;
        };
        let trajectory = classical(&robot, &task, &config);
        assert!(trajectory.steps[0].tool_angle_deg < 1e-5);
        if let Err(e) = checker.check(&task, &trajectory, &config.constraints) {
            panic!("candidate {index}: {e}");
        }
        checked += 1;
    }
    assert!(checked > 150);
}

/// A task whose classical rollout ends in a violation after at least 8 steps, and that rollout.
fn sample() -> (Task, Trajectory) {
    let robot = robot();
    let config = RolloutConfig::default();
    for (_, task) in tasks(&robot, 60) {
        let trajectory = classical(&robot, &task, &config);
        if trajectory.steps.len() >= 8
            && matches!(trajectory.termination, Termination::Violation { .. })
        {
            return (task, trajectory);
        }
    }
    panic!("no classical rollout of 8+ steps ending in a violation among 60 tasks");
}

fn expect_failure(
    task: &Task,
    trajectory: &Trajectory,
    constraints: &ConstraintConfig,
    step: usize,
    words: &[&str],
) {
    let failure = checker()
        .check(task, trajectory, constraints)
        .expect_err("tampered trajectory must fail");
    assert_eq!(failure.step, step, "wrong step blamed: {failure}");
    let message = failure.to_string();
    assert!(message.contains(&format!("step {step}")), "{message}");
    for word in words {
        assert!(message.contains(word), "'{word}' missing from: {message}");
    }
}

#[test]
fn checker_rejects_a_joint_outside_its_limit() {
    let (task, original) = sample();
    let constraints = ConstraintConfig::default();
    checker()
        .check(&task, &original, &constraints)
        .expect("untampered passes");
    let limits = checker().limits();
    for (joint, upper) in [(1usize, true), (4, true), (6, false)] {
        let mut trajectory = original.clone();
        let (lo, hi) = limits[joint - 1];
        trajectory.steps[3].q[joint - 1] = if upper { hi + 1e-6 } else { lo - 1e-6 };
        expect_failure(
            &task,
            &trajectory,
            &constraints,
            3,
            &[&format!("joint {joint}")],
        );
    }
    let mut trajectory = original.clone();
    trajectory.steps[2].q[4] = f64::NAN;
    expect_failure(&task, &trajectory, &constraints, 2, &["joint 5"]);
}

#[test]
fn checker_rejects_a_moved_tcp_or_tool_angle() {
    let (task, original) = sample();
    let constraints = ConstraintConfig::default();
    for axis in 0..3 {
        let mut trajectory = original.clone();
        trajectory.steps[5].tcp[axis] += 1e-3;
        expect_failure(&task, &trajectory, &constraints, 5, &["TCP"]);
    }
    // A configuration changed without its TCP: the recorded TCP no longer matches FK.
    let mut trajectory = original.clone();
    trajectory.steps[4].q[0] += 1e-4;
    expect_failure(&task, &trajectory, &constraints, 4, &["TCP"]);
    let mut trajectory = original.clone();
    trajectory.steps[1].tool_angle_deg += 0.01;
    expect_failure(&task, &trajectory, &constraints, 1, &["tool angle"]);
}

#[test]
fn checker_rejects_a_wrong_path_length() {
    let (task, original) = sample();
    let constraints = ConstraintConfig::default();
    let last = original.steps.len() - 1;
    for delta in [1e-3, -1e-3, 1e-7] {
        let mut trajectory = original.clone();
        trajectory.path_length_m += delta;
        expect_failure(&task, &trajectory, &constraints, last, &["path length"]);
    }
    // Dropping the final steps without updating the length is caught too.
    let mut trajectory = original.clone();
    trajectory.steps.truncate(last - 2);
    assert!(checker().check(&task, &trajectory, &constraints).is_err());
}

/// A checker must fail closed: NaN anywhere in the record is an error, not a pass.
#[test]
fn checker_rejects_nan_records() {
    let (task, original) = sample();
    let constraints = ConstraintConfig::default();
    let mut trajectory = original.clone();
    trajectory.steps[3].tcp.y = f64::NAN;
    expect_failure(&task, &trajectory, &constraints, 3, &["TCP"]);
    let mut trajectory = original.clone();
    trajectory.steps[2].tool_angle_deg = f64::NAN;
    expect_failure(&task, &trajectory, &constraints, 2, &["tool angle"]);
    let mut trajectory = original.clone();
    trajectory.steps[4].time_s = f64::NAN;
    assert!(
        checker().check(&task, &trajectory, &constraints).is_err(),
        "NaN time accepted"
    );
    let mut trajectory = original.clone();
    trajectory.path_length_m = f64::NAN;
    expect_failure(
        &task,
        &trajectory,
        &constraints,
        original.steps.len() - 1,
        &["path length"],
    );
}

#[test]
fn checker_rejects_malformed_trajectories_without_panicking() {
    let (task, original) = sample();
    let constraints = ConstraintConfig::default();
    let mut trajectory = original.clone();
    trajectory.steps.clear();
    expect_failure(&task, &trajectory, &constraints, 0, &["no step"]);
    // An invalid start holds only its seed; extra steps would go unchecked.
    let mut trajectory = original.clone();
    trajectory.steps.truncate(3);
    trajectory.termination = Termination::InvalidStart {
        violation: Violation::LineTolerance { distance_m: 0.03 },
    };
    expect_failure(&task, &trajectory, &constraints, 1, &["only the seed"]);
    // A joint number that does not exist is an error, not a panic.
    let Termination::Violation { rejected_q, .. } = &original.termination else {
        unreachable!()
    };
    for joint in [0, 8, usize::MAX] {
        let mut trajectory = original.clone();
        trajectory.termination = Termination::Violation {
            violation: Violation::JointLimit {
                joint,
                value_rad: 0.0,
                limit_rad: 0.0,
            },
            rejected_q: *rejected_q,
        };
        expect_failure(
            &task,
            &trajectory,
            &constraints,
            original.steps.len(),
            &["does not break"],
        );
    }
    // A NaN configuration breaks the joint limits, as the rollout's own rule says.
    let mut nan = *rejected_q;
    nan[2] = f64::NAN;
    let robot = robot();
    let found = emg_control::first_violation(&robot, &task, &robot.forward(&nan), &constraints);
    let Some(violation @ Violation::JointLimit { joint: 3, .. }) = found else {
        panic!("{found:?}")
    };
    let mut trajectory = original.clone();
    trajectory.termination = Termination::Violation {
        violation,
        rejected_q: nan,
    };
    checker()
        .check(&task, &trajectory, &constraints)
        .expect("a NaN step is rightly rejected by the rollout");
}

#[test]
fn checker_rejects_non_increasing_time() {
    let (task, original) = sample();
    let constraints = ConstraintConfig::default();
    let mut trajectory = original.clone();
    trajectory.steps[6].time_s = trajectory.steps[5].time_s;
    expect_failure(&task, &trajectory, &constraints, 6, &["timestamps"]);
}

#[test]
fn checker_rejects_a_termination_that_breaks_nothing() {
    let (task, original) = sample();
    let constraints = ConstraintConfig::default();
    let valid_q = original.steps[2].q;
    let len = original.steps.len();
    let violations = [
        Violation::JointLimit {
            joint: 3,
            value_rad: 3.0,
            limit_rad: 2.9007,
        },
        Violation::LineTolerance { distance_m: 0.03 },
        Violation::ToolCone { angle_deg: 31.0 },
        Violation::SelfCollision {
            first_link: "link1".into(),
            second_link: "link7".into(),
            clearance_m: -0.01,
        },
    ];
    for violation in violations {
        let mut trajectory = original.clone();
        trajectory.termination = Termination::Violation {
            violation: violation.clone(),
            rejected_q: valid_q,
        };
        expect_failure(&task, &trajectory, &constraints, len, &["does not break"]);
        // An invalid start blamed on a seed that holds every constraint fails the same way.
        let mut trajectory = original.clone();
        trajectory.steps.truncate(1);
        trajectory.path_length_m = 0.0;
        trajectory.termination = Termination::InvalidStart { violation };
        expect_failure(&task, &trajectory, &constraints, 1, &["does not break"]);
    }
    // The genuine rejected configuration is accepted, but not when blamed on another constraint.
    let Termination::Violation {
        violation,
        rejected_q,
    } = &original.termination
    else {
        unreachable!()
    };
    let other = match violation {
        Violation::ToolCone { .. } => Violation::LineTolerance { distance_m: 0.03 },
        _ => Violation::ToolCone { angle_deg: 31.0 },
    };
    let robot = robot();
    let kin = robot.forward(rejected_q);
    let breaks_other = match &other {
        Violation::ToolCone { .. } => {
            emg_control::tool_angle_deg(&kin.tool_axis(), &task.n) > 30.0 - 1e-6
        }
        _ => task.lateral_error(&kin.tcp()).norm() > 0.02 - 1e-9,
    };
    if !breaks_other {
        let mut trajectory = original.clone();
        trajectory.termination = Termination::Violation {
            violation: other,
            rejected_q: *rejected_q,
        };
        expect_failure(&task, &trajectory, &constraints, len, &["does not break"]);
    }
}

#[test]
fn checker_rejects_a_line_moved_by_three_centimetres() {
    let (task, trajectory) = sample();
    let robot = robot();
    let constraints = ConstraintConfig::default();
    // Shift p0 by 3 cm perpendicular to d (along n × d): step 0 is then 3 cm off the line.
    let shift = task.n.cross(&task.d).normalize() * 0.03;
    let shifted = Task::new(&robot, task.p0 + shift, task.d, task.n, None).expect("valid task");
    expect_failure(&shifted, &trajectory, &constraints, 0, &["off the line"]);
    // A shift along d keeps the line: only the path length is wrong then.
    let along =
        Task::new(&robot, task.p0 + task.d * 0.03, task.d, task.n, None).expect("valid task");
    expect_failure(
        &along,
        &trajectory,
        &constraints,
        trajectory.steps.len() - 1,
        &["path length"],
    );
    // A tighter tolerance catches steps that the default one accepts.
    let worst = trajectory
        .steps
        .iter()
        .map(|s| task.lateral_error(&s.tcp).norm())
        .fold(0.0, f64::max);
    assert!(worst > 0.0);
    let tight = ConstraintConfig {
        line_tolerance_m: worst * 0.5,
        ..constraints.clone()
    };
    assert!(checker().check(&task, &trajectory, &tight).is_err());
}

#[test]
fn checker_rejects_a_tilted_normal() {
    let (task, trajectory) = sample();
    let robot = robot();
    // Tilt n by 40° about d: every recorded tool axis is then far outside the 30° cone,
    // and the recorded angles disagree with the new normal.
    let rotation = emg_kinematics::rotation_about(&task.d.normalize(), 40f64.to_radians());
    let tilted = Task::new(&robot, task.p0, task.d, rotation * task.n, None).expect("valid task");
    let failure = checker()
        .check(&tilted, &trajectory, &ConstraintConfig::default())
        .expect_err("must fail");
    assert_eq!(failure.step, 0, "{failure}");
    assert!(failure.problem.contains("from n"), "{failure}");
}

#[test]
fn checker_rejects_a_colliding_configuration() {
    let robot = robot();
    let checker = checker();
    let mut rng = rng(13);
    let colliding: JointVector = loop {
        let q = random_q(&mut rng, &robot);
        if checker.min_clearance(&q).0 < -0.005 {
            break q;
        }
    };
    let (task, mut original) = sample();
    // Loose line and cone limits so that only the collision can be blamed; under them the
    // recorded termination no longer holds, so it is dropped.
    original.termination = Termination::StepCap;
    let loose = ConstraintConfig {
        line_tolerance_m: 100.0,
        theta_max_deg: 180.0,
        collision_margin_m: 0.0,
        ..ConstraintConfig::default()
    };
    checker
        .check(&task, &original, &loose)
        .expect("untampered passes loose limits");
    let mut trajectory = original.clone();
    let kin = robot.forward(&colliding);
    let step = &mut trajectory.steps[4];
    step.q = colliding;
    step.tcp = kin.tcp();
    step.tool_angle_deg = emg_control::tool_angle_deg(&kin.tool_axis(), &task.n);
    expect_failure(&task, &trajectory, &loose, 4, &["collide"]);
    // A positive margin rejects configurations that merely come close.
    let clearance = original
        .steps
        .iter()
        .map(|s| checker.min_clearance(&s.q).0)
        .fold(f64::INFINITY, f64::min);
    let margin = ConstraintConfig {
        collision_margin_m: clearance + 1e-3,
        ..loose
    };
    assert!(checker.check(&task, &original, &margin).is_err());
}
