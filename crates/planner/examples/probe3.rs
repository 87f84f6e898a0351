use emg_io::read_tasks;
use emg_kinematics::Robot;
use emg_planner::{DataDir, Models, PlanRequest, Planner, PlannerConfig, ShippedRobot};
use rayon::prelude::*;
use std::collections::BTreeMap;

fn main() {
    let args: Vec<usize> = std::env::args()
        .skip(1)
        .map(|a| a.parse().unwrap())
        .collect();
    let data = DataDir::new("data");
    let fr3 = ShippedRobot::by_name("fr3").unwrap();
    let robot = Robot::from_chain_file(fr3.path(&data)).unwrap();
    let models = Models::shipped(&robot, &fr3.data_dir(&data)).unwrap();
    let planner = Planner::new(robot, models, PlannerConfig::default()).unwrap();
    let tasks = read_tasks(
        &fr3.data_dir(&data).join("tasks/eval-v1.tasks"),
        planner.robot(),
    )
    .unwrap();
    let rows: Vec<(usize, f64, f64, String, String)> = (args[0]..args[1])
        .into_par_iter()
        .filter_map(|i| {
            let plan = planner.plan(&tasks[i], &PlanRequest::default()).ok()?;
            let bound = plan
                .reach
                .as_ref()
                .unwrap()
                .reachable_m
                .max(plan.trajectory.path_length_m);
            if bound < 1.0 {
                return None;
            }
            let t = format!("{}", plan.trajectory.termination);
            let kind = t.split_whitespace().take(3).collect::<Vec<_>>().join(" ");
            Some((
                i,
                plan.trajectory.path_length_m,
                bound,
                kind,
                plan.seed.source.to_string(),
            ))
        })
        .collect();
    let mut by: BTreeMap<String, (usize, f64)> = BTreeMap::new();
    for r in &rows {
        let e = by.entry(r.3.clone()).or_default();
        e.0 += 1;
        e.1 += r.2 - r.1;
        if r.1 < 0.7 * r.2 {
            println!("task {} {:.2}/{:.2} {} seed {}", r.0, r.1, r.2, r.3, r.4);
        }
    }
    for (k, v) in by {
        println!("{k}: {} tasks, missing {:.2} m", v.0, v.1);
    }
}
