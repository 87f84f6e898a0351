//! The task population (SPEC §2).
//!
//! `candidate(i)` is a pure function of the seed and `i` (`committed_tasks.rs` regenerates the
//! shipped sets bit for bit in another process); sampled tasks have `n` within 5° of
//! the generating tool axis, `d ⟂ n`, `p0 = TCP(q0_seed)` and a collision-free seed inside the
//! limits. `TaskSampler::take` gives the same tasks on 1 and 2 threads, in any batch size and
//! when taken in pieces, keeps exactly the candidates whose classical rollout reaches 0.1 m, and
//! stops once its candidate budget is spent. With a surface clearance it keeps exactly the
//! paper population's tasks whose work surface clears the arm at `q0_seed`.

mod common;

use emg_control::{
    ClassicalController, ClassicalGains, ConstraintConfig, RolloutConfig, SamplerConfig, Task,
    TaskSampler, Termination, candidate, rollout, surface_clears, tool_angle_deg,
};
use emg_kinematics::Robot;

use common::{checker, classical, robot};

#[test]
fn candidates_are_well_formed() {
    let robot = robot();
    let checker = checker();
    let config = SamplerConfig::default();
    let (mut kept, mut max_tilt, mut min_tilt) = (0, 0.0f64, f64::INFINITY);
    let mut mean_d = emg_kinematics::Vec3::zeros();
    for index in 0..600 {
        let Some(task) = candidate(&robot, &config, index) else {
            continue;
        };
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
            checker.min_clearance(&q).0 > 0.0,
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
            let batch = sampler.take(count, u64::MAX, &|n| reported.lock().unwrap().push(n));
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
fn a_candidate_budget_bounds_the_draw() {
    let robot = robot();
    let config = SamplerConfig {
        batch_size: 16,
        ..SamplerConfig::default()
    };
    let (rollout, gains) = (RolloutConfig::default(), ClassicalGains::default());
    let mut bounded = TaskSampler::new(&robot, &rollout, &gains, &config);
    // Far more tasks than 40 candidates can give: the budget, not the count, ends the draw.
    let tasks = bounded.take(1000, 40, &|_| {});
    assert_eq!(bounded.candidates_drawn(), 40);
    assert!(
        !tasks.is_empty() && tasks.len() < 40,
        "{} tasks",
        tasks.len()
    );
    let (unbounded, _) = take_in_pool(2, &robot, &config, &[tasks.len()]);
    assert_eq!(
        tasks, unbounded,
        "the budget changes which tasks are accepted"
    );
    // The budget counts from where the previous draw stopped.
    bounded.take(1000, 25, &|_| {});
    assert_eq!(bounded.candidates_drawn(), 65);
}

#[test]
fn the_realistic_population_is_the_paper_population_where_the_surface_clears_the_arm() {
    let robot = robot();
    let paper = SamplerConfig {
        batch_size: 64,
        ..SamplerConfig::default()
    };
    let realistic = SamplerConfig {
        surface_clearance_m: Some(0.01),
        ..paper.clone()
    };
    let (all, _) = take_in_pool(2, &robot, &paper, &[200]);
    let (kept, _) = take_in_pool(2, &robot, &realistic, &[100]);
    // The same tasks in the same order, minus those whose surface comes within 1 cm of the arm
    // (the pen excepted) at q0_seed.
    let clear: Vec<Task> = all
        .into_iter()
        .filter(|task| {
            let kin = robot.forward(&task.q0_seed.unwrap());
            surface_clears(&robot, task, &kin, 0.01)
        })
        .collect();
    assert!(
        clear.len() > 100 && clear.len() < 190,
        "{} of 200 tasks clear",
        clear.len()
    );
    assert_eq!(kept[..], clear[..100]);
    // Every kept task's surface stays 1 cm from the arm, as the checker of a rollout with the
    // surface on confirms at the seed.
    let config = RolloutConfig {
        max_steps: 1,
        constraints: ConstraintConfig {
            work_surface: emg_kinematics::WorkSurface::HalfSpace,
            ..ConstraintConfig::default()
        },
        ..RolloutConfig::default()
    };
    for task in &kept {
        let trajectory = rollout(
            &robot,
            task,
            &task.q0_seed.unwrap(),
            &mut ClassicalController::default(),
            &config,
        );
        assert!(
            !matches!(trajectory.termination, Termination::InvalidStart { .. }),
            "{}",
            trajectory.termination
        );
    }
}
