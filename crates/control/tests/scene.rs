//! Scene constraints in the rollout and in the independent checker:
//! - on random configurations and obstacles (and the work surface of sampled tasks) the
//!   library's `first_contact` and the checker's `scene_margin` agree wherever the margin is
//!   not within rounding of zero;
//! - classical rollouts with the work surface on hold it at every step, pass the checker, and
//!   some end on it, blamed and confirmed by the checker;
//! - rollouts planned with the surface off that cross it fail the checker told of the surface,
//!   at the first step that crosses it; an obstacle placed on a rollout's path ends the rollout
//!   before it;
//! - an elbow dipping into the work plate is caught by the library and the checker; moved
//!   beside the line, the plate no longer touches it while the half-space still does;
//! - a constraint file with the surface and a scene reads; without them it writes as before.

mod common;

use emg_control::{
    CheckRollout, ConstraintConfig, RolloutConfig, Termination, Violation, WORK_SURFACE,
    first_contact,
};
use emg_kinematics::{Obstacle, Plate, Scene, Shape, Vec3, WorkSurface};
use emg_verify::{Bounds, FailedCheck, Line};
use rand::RngExt;

use common::{checker, classical, random_q, rng, robot, tasks};

fn with_surface(surface: WorkSurface) -> RolloutConfig {
    let mut config = RolloutConfig::default();
    config.constraints.work_surface = surface;
    config
}

/// The three work surfaces, in turn.
fn surface(case: usize) -> WorkSurface {
    [
        WorkSurface::Off,
        WorkSurface::HalfSpace,
        WorkSurface::plate(),
    ][case % 3]
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
        tool_may_touch: rng.random_bool(0.5),
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
            work_surface: surface(case / 3),
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
        let bounds: Bounds = emg_control::task_bounds(task, &constraints);
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
    for surface in [WorkSurface::HalfSpace, WorkSurface::plate()] {
        let config = with_surface(surface);
        let (mut invalid_starts, mut surface_ends, mut others) = (0, 0, 0);
        for (index, task) in tasks(&robot, 400) {
            let trajectory = classical(&robot, &task, &config);
            checker
                .check(&task, &trajectory, &config.constraints)
                .unwrap_or_else(|e| panic!("{surface}, task {index}: {e}"));
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
            "{surface}: {invalid_starts} invalid starts, {surface_ends} ended on the surface, \
             {others} others"
        );
    }
}

#[test]
fn the_checker_catches_a_rollout_through_the_work_surface() {
    let robot = robot();
    let free = RolloutConfig::default();
    for (surface, least) in [(WorkSurface::HalfSpace, 6), (WorkSurface::plate(), 1)] {
        let surface_config = with_surface(surface);
        let mut caught = 0;
        for (index, task) in tasks(&robot, 120) {
            let crossing = classical(&robot, &task, &free);
            let Some(first) = crossing.steps.iter().position(|step| {
                let kin = robot.forward(&step.q);
                first_contact(&robot, &task, &kin, &surface_config.constraints).is_some()
            }) else {
                continue;
            };
            let failure = checker()
                .check(&task, &crossing, &surface_config.constraints)
                .expect_err("crossing the surface fails");
            assert_eq!(failure.check, FailedCheck::SceneContact, "task {index}");
            assert_eq!(failure.step, first, "task {index}: {failure}");
            assert!(failure.to_string().contains(WORK_SURFACE), "{failure}");
            caught += 1;
        }
        assert!(
            caught >= least,
            "{surface}: only {caught} of 120 rollouts cross their surface"
        );
    }
}

#[test]
fn an_elbow_dipping_into_the_plate_is_caught_and_a_plate_beside_it_is_not() {
    let robot = robot();
    let checker = checker();
    let (_, sampled) = tasks(&robot, 1).remove(0);
    let q = sampled.q0_seed.expect("a sampled task has its seed");
    let kin = robot.forward(&q);
    // The fourth link's capsules: the elbow.
    let elbow = robot
        .capsules()
        .iter()
        .find(|c| c.link == "link4")
        .expect("the FR3 has a link4 capsule");
    let elbow_point = kin.segment_point(elbow.segment, &elbow.start);
    let n = Vec3::new(0.0, 0.0, -1.0);
    let d = Vec3::new(1.0, 0.0, 0.0);
    let across = n.cross(&d);
    // A line whose plate's top face lies 1 cm below the elbow's axis point, 0.5 m before it.
    let dipping = |offset_across: f64| {
        let p0 = elbow_point - n * (0.01 + elbow.radius) - d * 0.5 + across * offset_across;
        emg_control::Task::new(&robot, p0, d, n, None).unwrap()
    };
    let plate = ConstraintConfig {
        work_surface: WorkSurface::plate(),
        ..ConstraintConfig::default()
    };
    let half_space = ConstraintConfig {
        work_surface: WorkSurface::HalfSpace,
        ..ConstraintConfig::default()
    };
    for (task, constraints, touches) in [
        (dipping(0.0), &plate, true),
        (dipping(0.0), &half_space, true),
        (dipping(Plate::default().half_width_m + 0.2), &plate, false),
        (
            dipping(Plate::default().half_width_m + 0.2),
            &half_space,
            true,
        ),
    ] {
        let library = first_contact(&robot, &task, &kin, constraints);
        let (margin, link, _) = checker
            .scene_margin(&q, &(&task).into(), &(constraints).into())
            .expect("a surface to keep off");
        assert_eq!(
            matches!(library, Some(Violation::SceneContact { .. })),
            touches,
            "{}: {library:?}",
            constraints.work_surface
        );
        assert_eq!(margin < 0.0, touches, "{link}: {margin}");
    }
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
            tool_may_touch: false,
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
    assert_eq!(constraints.work_surface, WorkSurface::HalfSpace);
    let plate: ConstraintConfig =
        serde_json::from_str(r#"{"work_surface": {"plate": {"ahead_m": 1.0}}}"#).unwrap();
    assert_eq!(
        plate.work_surface,
        WorkSurface::Plate(Plate {
            ahead_m: 1.0,
            ..Plate::default()
        })
    );
    for (text, surface) in [
        (r#"{"work_surface": "plate"}"#, WorkSurface::plate()),
        (r#"{"work_surface": "off"}"#, WorkSurface::Off),
        (r#"{"work_surface": false}"#, WorkSurface::Off),
    ] {
        let read: ConstraintConfig = serde_json::from_str(text).unwrap();
        assert_eq!(read.work_surface, surface, "{text}");
        let again: ConstraintConfig =
            serde_json::from_str(&serde_json::to_string(&read).unwrap()).unwrap();
        assert_eq!(again, read);
    }
    let error = serde_json::from_str::<ConstraintConfig>(
        r#"{"work_surface": {"plate": {"thickness_m": -1}}}"#,
    )
    .unwrap_err();
    assert!(error.to_string().contains("plate.thickness_m"), "{error}");
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
