//! Labels of real tasks: every label reaches the exact pose to 1e-6, holds every constraint
//! (independent checker on its rollout), its stored length is its rollout's length, and labels do
//! not depend on the thread count or the order in which tasks are labelled.

mod common;

use common::{checker, eval_tasks, robot, small_config};
use emg_control::{CheckRollout, ClassicalController, first_violation, rollout};
use emg_seeding::label_task;

#[test]
fn labels_reach_the_exact_pose_and_hold_every_constraint() {
    let (robot, checker, config) = (robot(), checker(), small_config());
    let tasks = eval_tasks(&robot, 6);
    let mut labelled = 0;
    for (i, task) in tasks.iter().enumerate() {
        let (labels, stats) = label_task(&robot, task, i as u32, &config);
        assert_eq!(labels.task_index, i as u32);
        assert!(labels.labels.len() <= config.max_labels);
        assert!(stats.branches >= 1, "task {i}: no branch found");
        assert!(
            stats.best_length_m + 1e-12 >= labels.labels.first().map_or(0.0, |l| l.length_m) - 1e-6
        );
        for label in &labels.labels {
            labelled += 1;
            let kin = robot.forward(&label.q);
            assert!((kin.tcp() - task.p0).norm() < 1e-6, "task {i}: TCP off p0");
            let axis_error = kin.tool_axis().cross(&task.n).norm();
            assert!(
                axis_error < 1e-6 && kin.tool_axis().dot(&task.n) > 0.0,
                "task {i}: axis ≠ n"
            );
            assert!(first_violation(&robot, task, &kin, &config.rollout.constraints).is_none());
            assert!(label.length_m >= config.min_length_m);
            let tolerance = config
                .stability
                .stable_abs_m
                .max(config.stability.stable_fraction * label.length_m);
            assert!(label.stability_m <= tolerance + 1e-6);
            let mut controller = ClassicalController::new(config.gains.clone());
            let trajectory = rollout(&robot, task, &label.q, &mut controller, &config.rollout);
            checker
                .check(task, &trajectory, &config.rollout.constraints)
                .expect("the scored rollout passes the independent checker");
            assert!((trajectory.path_length_m - label.length_m).abs() < 1e-6);
        }
        assert!(
            labels
                .labels
                .windows(2)
                .all(|w| (w[0].q - w[1].q).amax() >= config.dedup_rad),
            "task {i}: duplicate labels"
        );
    }
    assert!(labelled > 0, "no task received a label");
}

#[test]
fn labels_do_not_depend_on_the_thread_count_or_the_order_of_tasks() {
    use rayon::prelude::*;
    let (robot, config) = (robot(), small_config());
    let tasks = eval_tasks(&robot, 3);
    let labelled = |threads: usize, reversed: bool| {
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .unwrap();
        let mut order: Vec<usize> = (0..tasks.len()).collect();
        if reversed {
            order.reverse();
        }
        let mut labels: Vec<_> = pool.install(|| {
            order
                .par_iter()
                .map(|&i| (i, label_task(&robot, &tasks[i], i as u32, &config)))
                .collect()
        });
        labels.sort_by_key(|(i, _)| *i);
        labels
    };
    assert_eq!(labelled(1, false), labelled(2, true));
}
