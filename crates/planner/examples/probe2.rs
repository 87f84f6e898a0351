use emg_control::{
    ActingController, ClassicalController, ClassicalGains, NullAction, NullSpaceController,
    StepContext, Task, rollout,
};
use emg_kinematics::{JointVector, tool_alignment_gradient};

struct Anticipating {
    base: ClassicalController,
    beta_deg: f64,
    k: f64,
}
impl NullSpaceController for Anticipating {
    fn reset(&mut self, _f: &StepContext<'_>) {}
    fn act(&mut self, step: &StepContext<'_>) -> (NullAction, ActingController) {
        let limits = step.robot.limits();
        let centring = (step.q - limits.mid()).component_div(&(limits.upper - limits.lower));
        let n = step.task.n;
        let qdot = step.pseudo_inverse.matrix * step.task_velocity();
        let zdot = step.kinematics.tool_axis_jacobian() * qdot;
        let drift = zdot - n * n.dot(&zdot);
        let m = if drift.norm() > 1e-6 {
            let b = self.beta_deg.to_radians();
            n * b.cos() - drift.normalize() * b.sin()
        } else {
            n
        };
        let g = self
            .base
            .cone_gate(step.tool_angle_deg, step.config.constraints.theta_max_deg);
        let xi: JointVector = step.manipulability_gradient * self.base.gains.k_mu
            - centring * self.base.gains.k_jl
            + tool_alignment_gradient(&step.kinematics, &m) * self.k
            + step.alignment_gradient * (self.base.gains.k_theta * g);
        (step.action_from_secondary(&xi), ActingController::Classical)
    }
}
use emg_io::read_tasks;
use emg_kinematics::Robot;
use emg_planner::{DataDir, Models, PlanRequest, Planner, PlannerConfig, ShippedRobot};
use emg_seeding::{IkConfig, cone_ik_solutions};
use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;
use rayon::prelude::*;

fn main() {
    let args: Vec<usize> = std::env::args()
        .skip(1)
        .map(|a| a.parse().unwrap())
        .collect();
    let (from, to) = (args[0], args[1]);
    let data = DataDir::new("data");
    let fr3 = ShippedRobot::by_name("fr3").unwrap();
    let robot = Robot::from_chain_file(fr3.path(&data)).unwrap();
    let models = Models::shipped(&robot, &fr3.data_dir(&data)).unwrap();
    let planner = Planner::new(robot, models, PlannerConfig::default()).unwrap();
    let robot = planner.robot();
    let tasks = read_tasks(&fr3.data_dir(&data).join("tasks/eval-v1.tasks"), robot).unwrap();
    let rc = &planner.config().rollout;
    let variants: Vec<(f64, f64, f64, f64)> = vec![
        (0.0, 0.0, 20.0, 30.0),
        (10.0, 5.0, 20.0, 8.0),
        (20.0, 5.0, 20.0, 8.0),
        (10.0, 10.0, 20.0, 15.0),
        (20.0, 10.0, 20.0, 15.0),
        (15.0, 2.0, 20.0, 30.0),
        (25.0, 5.0, 20.0, 8.0),
    ];
    let rows: Vec<(f64, f64, Vec<f64>)> = (from..to)
        .into_par_iter()
        .filter_map(|i| {
            let task: &Task = &tasks[i];
            let plan = planner.plan(task, &PlanRequest::default()).ok()?;
            let bound = plan
                .reach
                .as_ref()
                .map(|r| r.reachable_m)
                .unwrap_or(0.0)
                .max(plan.trajectory.path_length_m);
            if bound < 1.0 {
                return None;
            }
            let mut rng = ChaCha8Rng::seed_from_u64(7);
            let starts = cone_ik_solutions(
                robot,
                &task.p0,
                &task.n,
                &IkConfig {
                    restarts: 64,
                    ..IkConfig::default()
                },
                &mut rng,
            );
            let best: Vec<f64> = variants
                .iter()
                .map(|&(beta_deg, k, k_theta, w)| {
                    let mut c = Anticipating {
                        base: ClassicalController::new(ClassicalGains {
                            k_mu: 0.8,
                            k_jl: 0.4,
                            k_theta,
                            cone_gate_width_deg: w,
                        }),
                        beta_deg,
                        k,
                    };
                    starts
                        .iter()
                        .map(|q| rollout(robot, task, q, &mut c, rc).path_length_m)
                        .fold(0.0, f64::max)
                })
                .collect();
            Some((bound, plan.trajectory.path_length_m, best))
        })
        .collect();
    let sb: f64 = rows.iter().map(|r| r.0).sum();
    println!(
        "{} long tasks; search {:.3}",
        rows.len(),
        rows.iter().map(|r| r.1).sum::<f64>() / sb
    );
    for (j, v) in variants.iter().enumerate() {
        println!(
            "{v:?}: {:.3}  max(search, this) {:.3}",
            rows.iter().map(|r| r.2[j]).sum::<f64>() / sb,
            rows.iter().map(|r| r.2[j].max(r.1)).sum::<f64>() / sb
        );
    }
}
