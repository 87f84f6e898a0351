//! Path tasks on both shipped arms: a rectangle, a full circle and an S-curve of the path
//! population planned by the search (a small budget, so that the test stays short), timed rest
//! to rest within each arm's joint limits (at rest at the rectangle's corners) and their files
//! verified as `emg check` verifies them; the search never returns less than the pipeline's plan
//! and a plan that reaches the end says so.

mod common;

use common::{TimedArm, data};
use emg_control::{PathShape, Task, Termination, path_tasks};
use emg_io::read_tasks;
use emg_planner::{
    PlanRequest, Planner, PlannerConfig, SHIPPED_ROBOTS, SearchConfig, ShippedRobot,
};

/// The first eight paths of the population from `arm`'s evaluation tasks (two of each shape).
fn population(arm: ShippedRobot, planner: &Planner) -> Vec<(PathShape, Task)> {
    let mut anchors = read_tasks(
        &arm.data_dir(&data()).join("tasks/eval-v1.tasks"),
        planner.robot(),
    )
    .expect("shipped tasks");
    anchors.truncate(8);
    path_tasks(planner.robot(), &anchors, 20_261_126).expect("valid path tasks")
}

#[test]
fn rectangles_circles_and_s_curves_plan_time_and_check_on_every_shipped_arm() {
    for arm in SHIPPED_ROBOTS {
        let name = arm.name;
        let config = PlannerConfig {
            search: SearchConfig {
                budget_steps: 2_000,
                dp_samples: 8,
                ik_restarts: 16,
                ..SearchConfig::default()
            },
            ..PlannerConfig::default()
        };
        let timed = TimedArm::new(arm, config);
        let planner = &timed.planner;
        let mut completed = Vec::new();
        for (shape, task) in population(arm, planner) {
            if shape == PathShape::Arc {
                continue;
            }
            let pipeline = planner
                .plan(&task, &PlanRequest::pipeline())
                .expect("a plan");
            let request = PlanRequest::default();
            let plan = planner.plan(&task, &request).expect("a plan");
            assert!(plan.trajectory.path_length_m >= pipeline.trajectory.path_length_m);
            let length = task.length_m().expect("a path task");
            let done = plan.trajectory.termination == Termination::Completed;
            assert_eq!(
                done,
                plan.trajectory.path_length_m >= length - 2e-4,
                "{name} {shape:?}"
            );
            if done {
                completed.push(shape);
            }
            let files = timed.checked_files(&format!("{name} {shape:?}"), &task, &plan, &request);
            if shape == PathShape::Rectangle && done {
                assert_eq!(
                    files.timing.rests_s.len(),
                    3,
                    "{name}: at rest at each corner"
                );
            }
        }
        for shape in [PathShape::Rectangle, PathShape::Circle, PathShape::SCurve] {
            assert!(
                completed.contains(&shape),
                "{name}: no {shape:?} planned to its end"
            );
        }
    }
}
