use emg_control::{ClassicalController, Task, rollout};
use emg_io::read_tasks;
use emg_kinematics::Robot;
use emg_planner::{DataDir, Models, PlanRequest, Planner, PlannerConfig, ShippedRobot};
use emg_seeding::{IkConfig, solve_cone_ik};

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
    let robot = planner.robot();
    let tasks = read_tasks(&fr3.data_dir(&data).join("tasks/eval-v1.tasks"), robot).unwrap();
    let rc = &planner.config().rollout;
    for &i in &args {
        let task = &tasks[i];
        let plan = planner.plan(task, &PlanRequest::default()).unwrap();
        let reach = planner.reach(task, &[]);
        println!(
            "task {i}: search {:.3} ({}) bound {:.2}",
            plan.trajectory.path_length_m, plan.trajectory.termination, reach.scanned_m
        );
        let mut best = 0.0f64;
        let cone: f64 = std::env::var("CONE")
            .map(|v| v.parse().unwrap())
            .unwrap_or(5.0);
        let ik = IkConfig {
            cone_deg: cone,
            joint_margin_rad: 1e-3,
            max_iterations: 100,
            ..IkConfig::default()
        };
        for (k, q) in reach.witnesses.iter().enumerate().step_by(5) {
            let s = k as f64 * 0.01;
            let p = task.p0 + task.d * s;
            let Some(q) = solve_cone_ik(robot, q, &p, &task.n, &ik) else {
                println!("  s {s:.2}: no polish");
                continue;
            };
            let q = &q;
            let fwd = Task {
                p0: p,
                d: task.d,
                n: task.n,
                q0_seed: None,
            };
            let bwd = Task {
                p0: p,
                d: -task.d,
                n: task.n,
                q0_seed: None,
            };
            let mut c = ClassicalController::default();
            let f = rollout(robot, &fwd, q, &mut c, rc);
            let b = rollout(robot, &bwd, q, &mut c, rc);
            let ok = b.path_length_m >= s - 0.02;
            if ok {
                best = best.max(s + f.path_length_m);
            }
            println!(
                "  s {s:.2}: fwd {:.3} [{}]  bwd {:.3} [{}] {}",
                f.path_length_m,
                f.termination,
                b.path_length_m,
                b.termination,
                if ok { "CONNECTS" } else { "" }
            );
        }
        println!("  best bidirectional {best:.3}");
    }
}
