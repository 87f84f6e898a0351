//! The task population (SPEC §2) and the parallel evaluation helpers.
//!
//! `candidate(i)` is a pure function of the seed and `i`; sampled tasks have `n` within 5° of
//! the generating tool axis, `d ⟂ n`, `p0 = TCP(q0_seed)` and a collision-free seed inside the
//! limits. `TaskSampler::take` gives the same tasks on 1 and 2 threads, in any batch size and
//! when taken in pieces, and keeps exactly the candidates whose classical rollout reaches 0.1 m.
//! `rollout_all` is thread-count independent; `Summary` and the histograms match hand counts.

mod common;

use emg_control::{
    ClassicalController, ClassicalGains, RolloutConfig, SamplerConfig, Summary, Task, TaskSampler,
    Termination, Trajectory, Violation, candidate, joint_limit_histogram, rollout, rollout_all,
    termination_histogram, tool_angle_deg,
};
use emg_kinematics::{JointVector, Robot};

use common::{checker, classical, robot};

#[test]
fn candidates_are_deterministic_and_well_formed() {
    let robot = robot();
    let checker = checker();
    let config = SamplerConfig::default();
    let (mut kept, mut max_tilt, mut min_tilt) = (0, 0.0f64, f64::INFINITY);
    let mut mean_d = emg_kinematics::Vec3::zeros();
    for index in 0..600 {
        let task = candidate(&robot, &config, index);
        assert_eq!(
            task,
            candidate(&robot, &config, index),
            "candidate {index} is not deterministic"
        );
        let Some(task) = task else { continue };
        kept += 1;
        let q = task.q0_seed.expect("sampled tasks keep their seed");
        let kin = robot.forward(&q);
        let tilt = tool_angle_deg(&kin.tool_axis(), &task.n);
        assert!(
            tilt <= 5.0 + 1e-9,
            "candidate {index}: n is {tilt}° from z(q0_seed)"
        );
        (max_tilt, min_tilt) = (max_tilt.max(tilt), min_tilt.min(tilt));
        assert!(
            task.d.dot(&task.n).abs() < 1e-12,
            "candidate {index}: d·n = {}",
            task.d.dot(&task.n)
        );
        assert!((task.d.norm() - 1.0).abs() < 1e-12 && (task.n.norm() - 1.0).abs() < 1e-12);
        assert!(
            (task.p0 - kin.tcp()).norm() < 1e-12,
            "candidate {index}: p0 is not TCP(q0_seed)"
        );
        assert!(
            robot.limits().first_violation(&q, 0.0).is_none(),
            "candidate {index}: seed outside limits"
        );
        assert!(
            robot.first_collision(&kin, 0.0).is_none(),
            "candidate {index}: seed collides"
        );
        assert!(
            checker.min_clearance(q.as_slice()).0 > 0.0,
            "candidate {index}: the checker sees a collision"
        );
        mean_d += task.d;
    }
    // Rejections (self-collisions) happen, but most candidates are kept.
    assert!(kept > 300 && kept < 600, "{kept} of 600 candidates kept");
    // The tilt covers [0°, 5°] and d is not biased towards one direction.
    assert!(
        max_tilt > 4.5 && min_tilt < 0.5,
        "tilts span [{min_tilt}, {max_tilt}]"
    );
    assert!(
        (mean_d / kept as f64).norm() < 0.15,
        "mean d = {:?}",
        mean_d / kept as f64
    );
    // A different seed gives a different population.
    let other = SamplerConfig {
        seed: 7,
        ..SamplerConfig::default()
    };
    let differs = (0..20)
        .filter(|&i| candidate(&robot, &other, i) != candidate(&robot, &config, i))
        .count();
    assert!(differs >= 18, "{differs}");
    // The tilt bound is honoured when changed.
    let flat = SamplerConfig {
        max_tilt_deg: 0.0,
        ..SamplerConfig::default()
    };
    for task in (0..50).filter_map(|i| candidate(&robot, &flat, i)) {
        let kin = robot.forward(&task.q0_seed.unwrap());
        assert!(tool_angle_deg(&kin.tool_axis(), &task.n) < 1e-6);
    }
}

fn take_in_pool(
    threads: usize,
    robot: &Robot,
    config: &SamplerConfig,
    counts: &[usize],
) -> (Vec<Task>, u64) {
    let rollout = RolloutConfig::default();
    let gains = ClassicalGains::default();
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()
        .unwrap();
    pool.install(|| {
        let mut sampler = TaskSampler::new(robot, &rollout, &gains, config);
        let mut tasks = Vec::new();
        for &count in counts {
            let reported = std::sync::Mutex::new(Vec::new());
            let batch = sampler.take(count, &|n| reported.lock().unwrap().push(n));
            assert_eq!(batch.len(), count);
            let reported = reported.into_inner().unwrap();
            assert_eq!(reported.last(), Some(&count), "progress ends at the count");
            assert!(
                reported.windows(2).all(|w| w[0] <= w[1]),
                "progress is monotone: {reported:?}"
            );
            tasks.extend(batch);
        }
        (tasks, sampler.candidates_drawn())
    })
}

#[test]
fn sampler_is_independent_of_threads_and_batches() {
    let robot = robot();
    let config = SamplerConfig {
        batch_size: 64,
        ..SamplerConfig::default()
    };
    let (one, drawn_one) = take_in_pool(1, &robot, &config, &[50]);
    let (two, drawn_two) = take_in_pool(2, &robot, &config, &[50]);
    assert_eq!(one, two, "1 and 2 threads give different tasks");
    assert_eq!(drawn_one, drawn_two);
    // Other batch sizes, and taking the same count in pieces, give the same sequence.
    let small = SamplerConfig {
        batch_size: 7,
        ..SamplerConfig::default()
    };
    let (pieces, drawn_pieces) = take_in_pool(2, &robot, &small, &[1, 20, 29]);
    assert_eq!(pieces, one, "batch size or pieces change the tasks");
    assert_eq!(drawn_pieces, drawn_one);
    // A zero batch size (a hand-written config) must not stall the sampler.
    let zero = SamplerConfig {
        batch_size: 0,
        ..SamplerConfig::default()
    };
    let (first, _) = take_in_pool(2, &robot, &zero, &[5]);
    assert_eq!(first[..], one[..5]);

    // Exactly the candidates up to the last one drawn whose classical rollout reaches 0.1 m.
    let rollout_config = RolloutConfig::default();
    let expected: Vec<Task> = (0..drawn_one)
        .filter_map(|i| candidate(&robot, &config, i))
        .filter(|task| classical(&robot, task, &rollout_config).path_length_m >= 0.1)
        .collect();
    assert_eq!(
        expected, one,
        "the accepted tasks are not the filtered candidates"
    );
    assert!(
        drawn_one > 50,
        "no candidate was filtered out ({drawn_one} drawn)"
    );
    for task in &one {
        let trajectory = classical(&robot, task, &rollout_config);
        assert!(
            trajectory.path_length_m >= 0.1,
            "accepted task travels {}",
            trajectory.path_length_m
        );
    }
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
