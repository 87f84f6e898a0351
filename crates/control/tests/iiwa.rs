//! The second shipped arm through the control layer: the independent checker's kinematics and
//! collision model agree with the library's for the iiwa 14, and classical rollouts on its
//! shipped evaluation tasks hold every constraint (joint speeds included) when re-checked.

use emg_control::{CheckRollout, ClassicalController, RolloutConfig, rollout};
use emg_io::read_tasks;
use emg_kinematics::{JointVector, Robot};
use emg_planner::{DataDir, ShippedRobot};
use emg_verify::ReferenceModel;
use rand::{RngExt, SeedableRng};

fn iiwa() -> (Robot, ReferenceModel, ShippedRobot) {
    let shipped = ShippedRobot::by_name("iiwa14").expect("shipped");
    let robot = Robot::from_chain_file(shipped.path(&data())).expect("robot loads");
    let checker =
        ReferenceModel::from_urdf_file(&shipped.path(&data()), robot.base_link(), robot.tip_link())
            .expect("checker loads");
    (robot, checker, shipped)
}

#[test]
fn checker_agrees_with_the_library_on_the_iiwa() {
    let (robot, checker, _) = iiwa();
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(5);
    let limits = robot.limits().clone();
    for _ in 0..300 {
        let q = JointVector::from_fn(|i, _| rng.random_range(limits.lower[i]..limits.upper[i]));
        let kin = robot.forward(&q);
        let (tcp, axis) = checker.tcp_pose(&q);
        assert!((tcp - kin.tcp()).norm() < 1e-12, "TCP at {q:?}");
        assert!(
            (axis - kin.tool_axis()).norm() < 1e-12,
            "tool axis at {q:?}"
        );
        let library = robot.min_clearance(&kin).expect("pairs exist").clearance;
        let (reference, _, _) = checker.min_clearance(&q);
        assert!(
            (library - reference).abs() < 1e-9,
            "{library} vs {reference}"
        );
    }
    let velocity: Vec<f64> = robot.limits().velocity.iter().copied().collect();
    assert_eq!(checker.velocity_limits(), velocity);
}

#[test]
fn classical_rollouts_on_iiwa_tasks_pass_the_checker() {
    let (robot, checker, shipped) = iiwa();
    let tasks = read_tasks(
        &shipped.data_dir(&data()).join("tasks/eval-v1.tasks"),
        &robot,
    )
    .unwrap();
    let config = RolloutConfig::default();
    let mut slowed = 0;
    for task in tasks.iter().take(200) {
        let seed = task.q0_seed.expect("seeded");
        let trajectory = rollout(
            &robot,
            task,
            &seed,
            &mut ClassicalController::default(),
            &config,
        );
        checker
            .check(task, &trajectory, &config.constraints)
            .unwrap_or_else(|e| panic!("{e}"));
        assert!(
            trajectory.path_length_m >= 0.1 - 1e-9,
            "the population keeps ≥ 0.1 m"
        );
        let expected = (trajectory.steps.len() - 1) as f64 * config.dt_s;
        if trajectory.steps.last().unwrap().time_s > expected + 1e-9 {
            slowed += 1;
        }
    }
    assert!(
        slowed > 0,
        "the iiwa's lower velocity limits slow some rollouts"
    );
}

/// The workspace's shipped data directory.
fn data() -> DataDir {
    DataDir::new(std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../../data"))
}
