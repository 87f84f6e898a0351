//! IK solutions are distinct and on the cone, and restarts given up when they stop converging
//! lose few of them; branch walks stay on the pose; heuristic seeds
//! stay on the exact pose and raise their objective; the tangent projector is a projector onto
//! motions that keep the pose (finite differences).

mod common;

use common::{eval_tasks, robot};
use emg_kinematics::{JointVector, PoseTarget, ProjectionConfig, project_to_pose};
use emg_seeding::{
    BranchConfig, HeuristicConfig, HeuristicObjective, IkConfig, WalkEnd, cone_ik_solutions,
    heuristic_seed, sample_branches, self_motion_projector, tangent_directions, walk,
};
use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;

#[test]
fn cone_ik_solutions_are_distinct_and_inside_the_cone_and_margin() {
    let robot = robot();
    let cfg = IkConfig::default();
    for (i, task) in eval_tasks(&robot, 4).iter().enumerate() {
        let mut rng = ChaCha8Rng::seed_from_u64(i as u64);
        let solutions = cone_ik_solutions(&robot, &task.p0, &task.n, &cfg, &mut rng);
        assert!(
            solutions.len() >= 2,
            "task {i}: {} solutions",
            solutions.len()
        );
        for (a, q) in solutions.iter().enumerate() {
            let kin = robot.forward(q);
            assert!((kin.tcp() - task.p0).norm() < cfg.position_tolerance_m);
            let axis = kin.tool_axis();
            let angle = libm::atan2(axis.cross(&task.n).norm(), axis.dot(&task.n));
            assert!(angle.to_degrees() <= cfg.cone_deg + 1e-9);
            assert!(
                robot
                    .limits()
                    .first_violation(q, cfg.joint_margin_rad - 1e-12)
                    .is_none()
            );
            for b in &solutions[a + 1..] {
                assert!((q - b).amax() >= cfg.dedup_rad);
            }
        }
    }
}

#[test]
fn restarts_given_up_when_they_stall_miss_few_solutions() {
    let robot = robot();
    let full = IkConfig {
        restarts: 64,
        cone_deg: 30.0,
        max_iterations: 100,
        ..IkConfig::default()
    };
    let stalling = IkConfig {
        stall_iterations: 10,
        ..full.clone()
    };
    let (mut found_full, mut found_stalling) = (0, 0);
    for (i, task) in eval_tasks(&robot, 8).iter().enumerate() {
        // A reachable target (the task's start) and one beyond reach along the line.
        for target in [task.p0, task.p0 + task.d * 1.5] {
            let solve = |cfg: &IkConfig| {
                let mut rng = ChaCha8Rng::seed_from_u64(i as u64);
                cone_ik_solutions(&robot, &target, &task.n, cfg, &mut rng)
            };
            let (a, b) = (solve(&full), solve(&stalling));
            // What the stalling solver returns is a solution all the same.
            for q in &b {
                assert!((robot.forward(q).tcp() - target).norm() < full.position_tolerance_m);
            }
            found_full += a.len();
            found_stalling += b.len();
        }
    }
    assert!(found_full > 50, "only {found_full} solutions");
    assert!(
        found_stalling as f64 >= 0.9 * found_full as f64,
        "{found_stalling} of {found_full} solutions kept"
    );
}

#[test]
fn tangent_projector_keeps_the_pose_to_first_order() {
    let robot = robot();
    let task = &eval_tasks(&robot, 1)[0];
    let target = PoseTarget {
        position: task.p0,
        tool_axis: task.n,
        roll_axis: None,
    };
    let (q, _) = project_to_pose(
        &robot,
        &task.q0_seed.unwrap(),
        &target,
        &ProjectionConfig::default(),
    )
    .unwrap();
    let projector = self_motion_projector(&robot, &q, &target, 1e-9);
    assert!(
        (projector * projector - projector).amax() < 1e-6,
        "not idempotent"
    );
    assert!(
        (projector - projector.transpose()).amax() < 1e-9,
        "not symmetric"
    );
    assert!(
        (projector.trace() - 2.0).abs() < 1e-6,
        "rank {} ≠ 2",
        projector.trace()
    );
    let [first, second] = tangent_directions(&robot, &q, &target, &BranchConfig::default());
    assert!((first.norm() - 1.0).abs() < 1e-9 && (second.norm() - 1.0).abs() < 1e-9);
    assert!(first.dot(&second).abs() < 1e-9);
    let h = 1e-6;
    for direction in [first, second] {
        let moved = robot.forward(&(q + direction * h));
        let back = robot.forward(&(q - direction * h));
        let velocity = (moved.tcp() - back.tcp()) / (2.0 * h);
        let axis_rate = (moved.tool_axis() - back.tool_axis()) / (2.0 * h);
        assert!(
            velocity.norm() < 1e-6 && axis_rate.norm() < 1e-6,
            "{velocity} {axis_rate}"
        );
    }
}

#[test]
fn walks_stay_on_the_pose_and_branches_are_distinct() {
    let robot = robot();
    let cfg = BranchConfig::default();
    let projection = ProjectionConfig::default();
    let task = &eval_tasks(&robot, 1)[0];
    let target = PoseTarget {
        position: task.p0,
        tool_axis: task.n,
        roll_axis: None,
    };
    let (q, _) = project_to_pose(&robot, &task.q0_seed.unwrap(), &target, &projection).unwrap();
    let [first, _] = tangent_directions(&robot, &q, &target, &cfg);
    let path = walk(&robot, &q, &target, &first, &cfg, &projection);
    assert!(path.points.len() > 1);
    assert!(path.arc_length_rad.windows(2).all(|w| w[1] > w[0]));
    for p in &path.points {
        let kin = robot.forward(p);
        assert!((kin.tcp() - task.p0).norm() < 1e-9);
        assert!(kin.tool_axis().cross(&task.n).norm() < 1e-9);
        assert!(robot.limits().first_violation(p, 0.0).is_none());
    }
    if let WalkEnd::JointLimit { joint } = path.end {
        assert!((1..=7).contains(&joint));
    }

    let mut rng = ChaCha8Rng::seed_from_u64(3);
    let exact: Vec<JointVector> =
        cone_ik_solutions(&robot, &task.p0, &task.n, &IkConfig::default(), &mut rng)
            .iter()
            .filter_map(|s| {
                project_to_pose(&robot, s, &target, &projection)
                    .ok()
                    .map(|(q, _)| q)
            })
            .collect();
    let samples = sample_branches(&robot, &exact, &target, &cfg, &projection);
    assert!(samples.branch_count >= 1);
    // Roots of different branches are far apart in joint space.
    let roots: Vec<JointVector> = (0..samples.branch_count)
        .map(|b| {
            samples
                .configurations
                .iter()
                .find(|(_, id)| *id == b)
                .unwrap()
                .0
        })
        .collect();
    for (a, p) in roots.iter().enumerate() {
        for q in &roots[a + 1..] {
            assert!((p - q).amax() >= cfg.reach_rad);
        }
    }
}

#[test]
fn heuristic_seeds_stay_on_the_pose_and_raise_their_objective() {
    let robot = robot();
    let cfg = HeuristicConfig::default();
    let projection = ProjectionConfig::default();
    let mut raised = 0;
    for task in eval_tasks(&robot, 5) {
        for objective in [
            HeuristicObjective::Manipulability,
            HeuristicObjective::JointCentring,
        ] {
            let seed = heuristic_seed(&robot, &task, objective, &cfg, &projection).unwrap();
            let kin = robot.forward(&seed.q);
            assert!((kin.tcp() - task.p0).norm() < 1e-9);
            assert!(kin.tool_axis().cross(&task.n).norm() < 1e-9);
            assert!(robot.limits().first_violation(&seed.q, 0.0).is_none());
            assert!(seed.objective_end >= seed.objective_start);
            let (value, _) = objective.evaluate(&robot, &task, &seed.q, &cfg);
            assert_eq!(value, seed.objective_end);
            raised += usize::from(seed.objective_end > seed.objective_start);
        }
    }
    assert!(
        raised >= 8,
        "the ascent raised the objective on only {raised} of 10 seeds"
    );
}

#[test]
fn objective_gradients_match_finite_differences() {
    let robot = robot();
    let cfg = HeuristicConfig::default();
    for task in eval_tasks(&robot, 3) {
        let q = task.q0_seed.unwrap();
        for objective in [
            HeuristicObjective::Manipulability,
            HeuristicObjective::JointCentring,
        ] {
            let (_, gradient) = objective.evaluate(&robot, &task, &q, &cfg);
            let h = 1e-6;
            for i in 0..7 {
                let mut e = JointVector::zeros();
                e[i] = h;
                let (plus, _) = objective.evaluate(&robot, &task, &(q + e), &cfg);
                let (minus, _) = objective.evaluate(&robot, &task, &(q - e), &cfg);
                let numeric = (plus - minus) / (2.0 * h);
                assert!(
                    (numeric - gradient[i]).abs() < 1e-5 * (1.0 + numeric.abs()),
                    "{objective:?} joint {i}"
                );
            }
        }
    }
}
