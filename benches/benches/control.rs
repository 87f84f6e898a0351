//! Hot-path benchmarks: forward kinematics with the Jacobian, one classical control step, one
//! constraint check, and one full classical rollout.

use std::hint::black_box;

use criterion::{Criterion, criterion_group, criterion_main};
use emg_benches::Fixture;
use emg_control::{
    ClassicalController, NullAction, NullSpaceController, RolloutConfig, StepContext,
    first_violation, rollout,
};

fn benches(c: &mut Criterion) {
    let fixture = Fixture::load();
    let robot = &fixture.robot;
    let task = &fixture.tasks[0];
    let q = task.q0_seed.expect("evaluation tasks keep their seed");
    let config = RolloutConfig::default();

    c.bench_function("fk_jacobian", |b| b.iter(|| robot.forward(black_box(&q))));

    let mut controller = ClassicalController::default();
    c.bench_function("classical_control_step", |b| {
        b.iter(|| {
            let kinematics = robot.forward(black_box(&q));
            let step =
                StepContext::new(robot, task, &config, 0, q, kinematics, NullAction::zeros());
            let (action, _) = controller.act(&step);
            q + step.joint_velocity(&action) * config.dt_s
        })
    });

    let kinematics = robot.forward(&q);
    c.bench_function("constraint_check", |b| {
        b.iter(|| first_violation(robot, task, black_box(&q), &kinematics, &config.constraints))
    });

    c.bench_function("classical_rollout", |b| {
        b.iter(|| {
            let mut controller = ClassicalController::default();
            rollout(robot, black_box(task), &q, &mut controller, &config).path_length_m
        })
    });
}

criterion_group!(control, benches);
criterion_main!(control);
