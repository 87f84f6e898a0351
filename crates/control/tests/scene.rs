//! Scene constraints in the rollout and in the independent checker:
//! - on random configurations and obstacles (and the work surface of sampled tasks) the
//!   library's `first_contact` and the checker's `scene_margin` agree wherever the margin is
//!   not within rounding of zero;
//! - classical rollouts with the work surface on hold it at every step, pass the checker, and
//!   some end on it, blamed and confirmed by the checker;
//! - rollouts planned with the surface off that cross it fail the checker told of the surface,
//!   at the first step that crosses it; an obstacle placed on a rollout's path ends the rollout
//!   before it;
//! - a constraint file with the surface and a scene reads; without them it writes as before.

mod common;

use emg_control::{
    CheckRollout, ConstraintConfig, RolloutConfig, Termination, Violation, WORK_SURFACE,
    first_contact,
};
use emg_kinematics::{Obstacle, Scene, Shape, Vec3};
use emg_verify::{Bounds, FailedCheck, Line};
use rand::RngExt;

use common::{checker, classical, random_q, rng, robot, tasks};

fn with_surface() -> RolloutConfig {
    let mut config = RolloutConfig::default();
    config.constraints.work_surface = true;
    config
}

fn random_obstacle(rng: &mut rand_chacha::ChaCha8Rng, kind: usize) -> Obstacle {
    let centre = Vec3::new(
        rng.random_range(-0.6..0.8),
        rng.random_range(-0.7..0.7),
        rng.random_range(0.0..1.0),
    );
    let shape = match kind {
        0 => Shape::Cuboid {
            centre,
            rotation: emg_kinematics::rotation_from_rpy(
                rng.random_range(-3.0..3.0),
                rng.random_range(-1.5..1.5),
                rng.random_range(-3.0..3.0),
            ),
            half_extents: Vec3::new(
                rng.random_range(0.0..0.2),
                rng.random_range(0.0..0.2),
                rng.random_range(0.0..0.2),
            ),
        },
        1 => Shape::Sphere {
            centre,
            radius: rng.random_range(0.0..0.2),
        },
        2 => Shape::Capsule {
            start: centre,
            end: centre + Vec3::new(0.2, -0.1, 0.3),
            radius: rng.random_range(0.0..0.1),
        },
        _ => Shape::HalfSpace {
            point: centre,
            normal: Vec3::new(0.3, -0.2, 1.0).normalize(),
        },
    };
    Obstacle {
        name: format!("obstacle {kind}"),
        shape,
        clearance_m: rng.random_range(0.0..0.02),
    }
}

#[test]
fn library_and_checker_agree_on_scene_contact() {
    let robot = robot();
    let checker = checker();
    let tasks = tasks(&robot, 50);
    let mut rng = rng(21);
    let (mut contacts, mut clear) = (0, 0);
    for case in 0..2_000 {
        let task = &tasks[case % tasks.len()].1;
        let mut constraints = ConstraintConfig {
            work_surface: case % 3 == 0,
            ..ConstraintConfig::default()
        };
        constraints.scene.obstacles = (0..case % 3)
            .map(|k| random_obstacle(&mut rng, (case + k) % 4))
            .collect();
        let q = random_q(&mut rng, &robot);
        let kin = robot.forward(&q);
        if robot.first_collision(&kin, 0.0).is_some() {
            continue;
        }
        let library = first_contact(&robot, task, &kin, &constraints);
        let bounds: Bounds = (&constraints).into();
        let line: Line = task.into();
        let Some((margin, link, obstacle)) = checker.scene_margin(&q, &line, &bounds) else {
            assert_eq!(library, None, "nothing to touch");
            continue;
        };
        if margin.abs() < 1e-9 {
            continue;
        }
        match &library {
            Some(Violation::SceneContact { .. }) => {
                assert!(
                    margin < 0.0,
                    "case {case}: checker margin {margin} at {link}"
                );
                contacts += 1;
            }
            None => {
                assert!(
                    margin > 0.0,
                    "case {case}: {link} {margin} m into the {obstacle}"
                );
                clear += 1;
            }
            Some(other) => panic!("case {case}: {other}"),
        }
    }
    assert!(
        contacts > 200 && clear > 200,
        "{contacts} contacts, {clear} clear"
    );
}

#[test]
fn rollouts_hold_the_work_surface_and_the_checker_confirms_it() {
    let robot = robot();
    let checker = checker();
    let config = with_surface();
    let (mut invalid_starts, mut surface_ends, mut others) = (0, 0, 0);
    for (index, task) in tasks(&robot, 400) {
        let trajectory = classical(&robot, &task, &config);
        checker
            .check(&task, &trajectory, &config.constraints)
            .unwrap_or_else(|e| panic!("task {index}: {e}"));
        match &trajectory.termination {
            Termination::InvalidStart {
                violation: Violation::SceneContact { obstacle, .. },
            } => {
                assert_eq!(obstacle, WORK_SURFACE);
                invalid_starts += 1;
            }
            Termination::Violation {
                violation: Violation::SceneContact { obstacle, link, .. },
                ..
            } => {
                assert_eq!(obstacle, WORK_SURFACE);
                assert_ne!(link, "pen_tip", "the pen may touch the surface");
                surface_ends += 1;
            }
            _ => others += 1,
        }
    }
    assert!(
        invalid_starts > 0 && surface_ends > 0 && others > 0,
        "{invalid_starts} invalid starts, {surface_ends} ended on the surface, {others} others"
    );
}

#[test]
fn the_checker_catches_a_rollout_through_the_work_surface() {
    let robot = robot();
    let free = RolloutConfig::default();
    let surface = with_surface();
    let mut caught = 0;
    for (index, task) in tasks(&robot, 60) {
        let crossing = classical(&robot, &task, &free);
        let Some(first) = crossing.steps.iter().position(|step| {
            let kin = robot.forward(&step.q);
            first_contact(&robot, &task, &kin, &surface.constraints).is_some()
        }) else {
            continue;
        };
        let failure = checker()
            .check(&task, &crossing, &surface.constraints)
            .expect_err("crossing the surface fails");
        assert_eq!(failure.check, FailedCheck::SceneContact, "task {index}");
        assert_eq!(failure.step, first, "task {index}: {failure}");
        assert!(failure.to_string().contains(WORK_SURFACE), "{failure}");
        caught += 1;
    }
    assert!(
        caught > 5,
        "only {caught} of 60 rollouts cross their surface"
    );
}

#[test]
fn an_obstacle_on_the_path_ends_the_rollout_before_it() {
    let robot = robot();
    let free = RolloutConfig::default();
    let (index, task, long) = tasks(&robot, 40)
        .into_iter()
        .map(|(index, task)| {
            let trajectory = classical(&robot, &task, &free);
            (index, task, trajectory)
        })
        .find(|(_, _, trajectory)| trajectory.steps.len() > 40)
        .expect("a rollout of 40+ steps");
    // A ball 3 cm across where the pen's tip is at step 30.
    let mut blocked = free.clone();
    blocked.constraints.scene = Scene {
        obstacles: vec![Obstacle {
            name: "ball".into(),
            shape: Shape::Sphere {
                centre: long.steps[30].tcp,
                radius: 0.015,
            },
            clearance_m: 0.005,
        }],
    };
    let trajectory = classical(&robot, &task, &blocked);
    assert!(trajectory.steps.len() <= 30, "task {index}");
    assert_eq!(trajectory.steps, long.steps[..trajectory.steps.len()]);
    let Termination::Violation {
        violation:
            Violation::SceneContact {
                obstacle,
                clearance_m,
                ..
            },
        ..
    } = &trajectory.termination
    else {
        panic!("task {index}: {}", trajectory.termination);
    };
    assert_eq!(obstacle, "ball");
    assert!(*clearance_m < 0.005);
    checker()
        .check(&task, &trajectory, &blocked.constraints)
        .expect("the shortened rollout passes");
    // Checked without the ball, the long rollout passes; with it, it fails.
    assert!(checker().check(&task, &long, &free.constraints).is_ok());
    let failure = checker()
        .check(&task, &long, &blocked.constraints)
        .expect_err("the long rollout passes through the ball");
    assert_eq!(failure.check, FailedCheck::SceneContact);
}

#[test]
fn constraint_files_carry_the_surface_and_the_scene() {
    let text = r#"{"work_surface": true, "scene": {"obstacles": [
        {"name": "table", "half_space": {"point": [0, 0, -0.01], "normal": [0, 0, 1]}}]}}"#;
    let constraints: ConstraintConfig = serde_json::from_str(text).unwrap();
    assert!(constraints.work_surface);
    assert_eq!(constraints.scene.obstacles[0].name, "table");
    let again: ConstraintConfig =
        serde_json::from_str(&serde_json::to_string(&constraints).unwrap()).unwrap();
    assert_eq!(again, constraints);
    // Without them, the constraints are written exactly as before they existed.
    let plain = serde_json::to_string(&ConstraintConfig::default()).unwrap();
    assert_eq!(
        plain,
        r#"{"line_tolerance_m":0.02,"theta_max_deg":30.0,"collision_margin_m":0.0,"velocity_limit_fraction":1.0}"#
    );
    let error = serde_json::from_str::<ConstraintConfig>(
        r#"{"scene": {"obstacles": [{"sphere": {"centre": [0, 0], "radius": 1}}]}}"#,
    )
    .unwrap_err();
    assert!(error.to_string().contains("invalid length 2"), "{error}");
}
