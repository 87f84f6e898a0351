//! Motions that hold the TCP on the line (`emg_planner::in_place_motion`,
//! `emg_planner::motion_along_line`) on the shipped UR5e: in place, one joins two configurations
//! that a walk in place joins, every configuration of its motion on the point and valid; along
//! the line, one joins configurations at the two ends of a stretch, every configuration on the
//! stretch and valid; and neither finds anything between configurations with opposite elbows
//! where every point is too near the shoulder for the elbow to straighten (the only way between
//! them, since the elbow joint's limits are ±π).

use emg_control::{ConstraintConfig, Task, first_violation};
use emg_kinematics::{JointVector, Robot, Vec3, project_to_point};
use emg_planner::{DataDir, InPlaceConfig, ShippedRobot, in_place_motion, motion_along_line};
use emg_seeding::{IkConfig, cone_ik_solutions};
use rand::{RngExt, SeedableRng};
use rand_chacha::ChaCha8Rng;

/// The elbow joint (0-based).
const ELBOW: usize = 2;

/// The stretch of the setup's line, from its point, that motions along it may use (m): all of
/// it under 0.41 m from the shoulder, still too near for the elbow to straighten.
const STRETCH_M: f64 = 0.1;

struct Setup {
    robot: Robot,
    task: Task,
    constraints: ConstraintConfig,
    point: Vec3,
    /// Valid configurations with the TCP on `point` (within `POINT_TOLERANCE_M`).
    solutions: Vec<JointVector>,
}

/// The UR5e, a point 0.35 m from its shoulder (its upper arm and forearm reach 0.817 m, its
/// wrist and pen well under 0.47 m), a line through it, and IK solutions there with the tool
/// axis within 5° of the line's normal.
fn setup() -> Setup {
    let data = DataDir::new(std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../../data"));
    let arm = ShippedRobot::by_name("ur5e").expect("the UR5e is shipped");
    let robot = Robot::from_chain_file(arm.path(&data)).expect("robot loads");
    let point = Vec3::new(0.3, 0.15, 0.25);
    let normal = Vec3::new(0.0, 0.0, 1.0);
    let task = Task::new(&robot, point, Vec3::new(0.0, 1.0, 0.0), normal, None).expect("a task");
    let constraints = ConstraintConfig::default();
    let mut rng = ChaCha8Rng::seed_from_u64(11);
    let solutions: Vec<JointVector> =
        cone_ik_solutions(&robot, &point, &normal, &IkConfig::default(), &mut rng)
            .into_iter()
            .filter_map(|q| project_to_point(&robot, &q, &point))
            .filter(|q| first_violation(&robot, &task, &robot.forward(q), &constraints).is_none())
            .collect();
    Setup {
        robot,
        task,
        constraints,
        point,
        solutions,
    }
}

/// `motion` runs from `from` to `to`, every configuration of it valid with its TCP where
/// `misplaced` finds nothing wrong (it says what is, else), each within twice the step of the
/// one before.
fn assert_motion(
    setup: &Setup,
    motion: &[JointVector],
    from: &JointVector,
    to: &JointVector,
    misplaced: impl Fn(&Vec3) -> Option<String>,
) {
    let step_rad = InPlaceConfig::default().step_rad;
    assert_eq!(motion.first(), Some(from));
    assert_eq!(motion.last(), Some(to));
    for (i, q) in motion.iter().enumerate() {
        let kinematics = setup.robot.forward(q);
        if let Some(wrong) = misplaced(&kinematics.tcp()) {
            panic!("configuration {i}: {wrong}");
        }
        let violation = first_violation(&setup.robot, &setup.task, &kinematics, &setup.constraints);
        assert!(violation.is_none(), "configuration {i}: {violation:?}");
    }
    for (i, pair) in motion.windows(2).enumerate() {
        let jump = (pair[1] - pair[0]).norm();
        assert!(jump <= 2.0 * step_rad + 1e-12, "step {i} moves {jump} rad");
    }
}

/// [`assert_motion`] with every TCP on the point (within 1 µm).
fn assert_in_place(setup: &Setup, motion: &[JointVector], from: &JointVector, to: &JointVector) {
    assert_motion(setup, motion, from, to, |tcp| {
        let off = (tcp - setup.point).norm();
        (off >= 1e-6).then(|| format!("the TCP is {off} m off the point"))
    });
}

#[test]
fn a_motion_in_place_joins_what_a_walk_in_place_joins() {
    let setup = setup();
    let from = *setup.solutions.first().expect("a solution at the point");
    // A walk in place: steps along one joint-space direction with a little noise, each put back
    // on the point and kept when a one-step motion in place takes it.
    let mut rng = ChaCha8Rng::seed_from_u64(3);
    let heading = setup
        .robot
        .configuration_from_fn(|i| [0.0, 0.0, 0.0, 0.3, 0.3, 1.0][i]);
    let one_step = InPlaceConfig {
        samples: 1,
        ..InPlaceConfig::default()
    };
    let mut to = from;
    for _ in 0..60 {
        let noise = setup
            .robot
            .configuration_from_fn(|_| 0.01 * (rng.random::<f64>() - 0.5));
        let Some(guess) =
            project_to_point(&setup.robot, &(to + heading * 0.03 + noise), &setup.point)
        else {
            continue;
        };
        let moved = in_place_motion(
            &setup.robot,
            &setup.task,
            &setup.constraints,
            &setup.point,
            &to,
            &guess,
            &one_step,
        );
        if let Some(moved) = moved {
            to = *moved.last().expect("a motion ends");
        }
    }
    assert!(
        (to - from).norm() > 0.3,
        "the walk moved {} rad",
        (to - from).norm()
    );
    let motion = in_place_motion(
        &setup.robot,
        &setup.task,
        &setup.constraints,
        &setup.point,
        &from,
        &to,
        &InPlaceConfig::default(),
    )
    .expect("a motion in place");
    assert_in_place(&setup, &motion, &from, &to);
    assert!(motion.len() > 2, "more than one step apart");
}

#[test]
fn no_motion_in_place_flips_an_elbow_that_cannot_straighten() {
    let setup = setup();
    let (up, down) = elbows(&setup);
    let motion = in_place_motion(
        &setup.robot,
        &setup.task,
        &setup.constraints,
        &setup.point,
        &up[0],
        &down[0],
        &flip_budget(),
    );
    assert_none(motion);
}

/// The setup's solutions with the elbow up and with it down, neither side empty.
fn elbows(setup: &Setup) -> (Vec<JointVector>, Vec<JointVector>) {
    let side = |up: bool| -> Vec<JointVector> {
        let solutions = setup.solutions.iter();
        solutions
            .filter(|q| if up { q[ELBOW] > 0.2 } else { q[ELBOW] < -0.2 })
            .copied()
            .collect()
    };
    let (up, down) = (side(true), side(false));
    assert!(
        !up.is_empty() && !down.is_empty(),
        "solutions with both elbows: {:?}",
        setup.solutions
    );
    (up, down)
}

/// The settings of a search for an elbow flip that cannot exist: the default's, 3000 draws.
fn flip_budget() -> InPlaceConfig {
    InPlaceConfig {
        samples: 3000,
        ..InPlaceConfig::default()
    }
}

/// The search found no motion.
fn assert_none(motion: Option<Vec<JointVector>>) {
    assert!(
        motion.is_none(),
        "{} configurations",
        motion.map_or(0, |m| m.len())
    );
}

#[test]
fn a_configuration_off_the_point_is_refused() {
    let setup = setup();
    let on = setup.solutions[0];
    let off = on
        + setup
            .robot
            .configuration_from_fn(|i| if i == 0 { 0.2 } else { 0.0 });
    let motion = in_place_motion(
        &setup.robot,
        &setup.task,
        &setup.constraints,
        &setup.point,
        &on,
        &off,
        &InPlaceConfig::default(),
    );
    assert!(motion.is_none());
}

/// [`assert_motion`] with every TCP on the line's first `STRETCH_M` (within 1 µm).
fn assert_along_line(setup: &Setup, motion: &[JointVector], from: &JointVector, to: &JointVector) {
    assert_motion(setup, motion, from, to, |tcp| {
        let along = setup.task.progress(tcp);
        let off = setup.task.lateral_error(tcp).norm();
        let on = (-1e-6..=STRETCH_M + 1e-6).contains(&along) && off < 1e-6;
        (!on).then(|| format!("the TCP is {along} m along the line, {off} m off it"))
    });
}

#[test]
fn a_motion_along_the_line_joins_its_two_ends() {
    let setup = setup();
    let from = setup.solutions[0];
    let far_point = setup.task.point_at(STRETCH_M);
    let to = project_to_point(&setup.robot, &from, &far_point).expect("the far point is reached");
    assert!(
        first_violation(
            &setup.robot,
            &setup.task,
            &setup.robot.forward(&to),
            &setup.constraints
        )
        .is_none()
    );
    let motion = motion_along_line(
        &setup.robot,
        &setup.task,
        &setup.constraints,
        0.0,
        STRETCH_M,
        &[from],
        &[to],
        &InPlaceConfig::default(),
    )
    .expect("a motion along the line");
    assert_along_line(&setup, &motion, &from, &to);
    assert!(motion.len() > 2, "more than one step apart");
}

#[test]
fn no_motion_along_the_line_flips_an_elbow_that_cannot_straighten() {
    let setup = setup();
    let (up, down) = elbows(&setup);
    let motion = motion_along_line(
        &setup.robot,
        &setup.task,
        &setup.constraints,
        0.0,
        STRETCH_M,
        &up,
        &down,
        &flip_budget(),
    );
    assert_none(motion);
}

#[test]
fn configurations_off_the_stretch_are_left_out() {
    let setup = setup();
    let on = setup.solutions[0];
    let beyond = project_to_point(&setup.robot, &on, &setup.task.point_at(2.0 * STRETCH_M))
        .expect("a point beyond the stretch is reached");
    let motion = motion_along_line(
        &setup.robot,
        &setup.task,
        &setup.constraints,
        0.0,
        STRETCH_M,
        &[on],
        &[beyond],
        &InPlaceConfig::default(),
    );
    assert!(motion.is_none());
}
