//! Batch rollouts are thread-count independent and equal one rollout at a time; `Summary` and
//! the histograms match hand counts.

use emg_control::{
    ClassicalController, RolloutConfig, SamplerConfig, Task, Termination, Trajectory, Violation,
    candidate, rollout,
};
use emg_eval::{Summary, joint_limit_histogram, rollout_all, termination_histogram};
use emg_kinematics::{JointVector, Robot};

fn robot() -> Robot {
    let path =
        std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../../data/robots/fr3_pen.urdf");
    Robot::from_urdf_file(path, "link0", "pen_tip").expect("shipped robot file loads")
}

fn classical(robot: &Robot, task: &Task, config: &RolloutConfig) -> Trajectory {
    let seed = task.q0_seed.expect("sampled tasks carry their seed");
    rollout(
        robot,
        task,
        &seed,
        &mut ClassicalController::default(),
        config,
    )
}

#[test]
fn rollout_all_is_independent_of_threads() {
    let robot = robot();
    let config = RolloutConfig::default();
    let tasks: Vec<Task> = (0..80)
        .filter_map(|i| candidate(&robot, &SamplerConfig::default(), i))
        .collect();
    let run = |threads: usize| {
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .unwrap();
        let calls = std::sync::atomic::AtomicUsize::new(0);
        let result = pool.install(|| {
            rollout_all(
                &robot,
                &tasks,
                |task| task.q0_seed.unwrap(),
                ClassicalController::default,
                &config,
                &|| {
                    calls.fetch_add(1, std::sync::atomic::Ordering::Relaxed);
                },
            )
        });
        assert_eq!(calls.into_inner(), tasks.len(), "progress once per task");
        result
    };
    let one = run(1);
    let two = run(2);
    assert_eq!(one, two);
    assert_eq!(one.len(), tasks.len());
    // In task order, and the same as one rollout at a time.
    for (task, trajectory) in tasks.iter().zip(&one) {
        assert_eq!(*trajectory, classical(&robot, task, &config));
    }
    // The seed function is honoured: the mid-range seed gives different (mostly invalid) starts.
    let mid: JointVector = robot.mid_range();
    let from_mid = rollout_all(
        &robot,
        &tasks[..5],
        |_| mid,
        ClassicalController::default,
        &config,
        &|| {},
    );
    for (trajectory, task) in from_mid.iter().zip(&tasks) {
        assert_eq!(trajectory.steps[0].q, mid);
        assert_eq!(
            *trajectory,
            rollout(
                &robot,
                task,
                &mid,
                &mut ClassicalController::default(),
                &config
            )
        );
    }
}

#[test]
fn summary_and_histograms_match_hand_counts() {
    let summary = Summary::of(&[1.0, 2.0, 3.0, 4.0]).unwrap();
    assert_eq!(summary.count, 4);
    assert_eq!(summary.mean, 2.5);
    assert!((summary.std - 1.25f64.sqrt()).abs() < 1e-15);
    assert_eq!((summary.min, summary.max), (1.0, 4.0));
    let summary = Summary::of(&[-0.5, 3.0, -0.5]).unwrap();
    assert!((summary.mean - 2.0 / 3.0).abs() < 1e-15);
    let variance = (2.0 * (-0.5f64 - 2.0 / 3.0).powi(2) + (3.0f64 - 2.0 / 3.0).powi(2)) / 3.0;
    assert!((summary.std - variance.sqrt()).abs() < 1e-15);
    assert_eq!((summary.min, summary.max), (-0.5, 3.0));
    let single = Summary::of(&[0.7]).unwrap();
    assert_eq!(
        (
            single.count,
            single.mean,
            single.std,
            single.min,
            single.max
        ),
        (1, 0.7, 0.0, 0.7, 0.7)
    );
    assert_eq!(Summary::of(&[]), None);

    let ending = |termination: Termination| Trajectory {
        steps: Vec::new(),
        termination,
        path_length_m: 0.0,
    };
    let joint = |joint: usize| Termination::Violation {
        violation: Violation::JointLimit {
            joint,
            value_rad: 0.0,
            limit_rad: 0.0,
        },
        rejected_q: JointVector::zeros(),
    };
    let set = vec![
        ending(joint(4)),
        ending(Termination::StepCap),
        ending(joint(6)),
        ending(joint(4)),
        ending(Termination::Violation {
            violation: Violation::ToolCone { angle_deg: 31.0 },
            rejected_q: JointVector::zeros(),
        }),
        ending(Termination::InvalidStart {
            violation: Violation::LineTolerance { distance_m: 0.1 },
        }),
    ];
    let histogram = termination_histogram(&set);
    let expected: std::collections::BTreeMap<String, usize> = [
        ("joint_limit", 3),
        ("step_cap", 1),
        ("tool_cone", 1),
        ("invalid_start", 1),
    ]
    .into_iter()
    .map(|(k, v)| (k.to_string(), v))
    .collect();
    assert_eq!(histogram, expected);
    let joints = joint_limit_histogram(&set);
    assert_eq!(joints.into_iter().collect::<Vec<_>>(), vec![(4, 2), (6, 1)]);
}
