//! Hot-path benchmarks: forward kinematics with the Jacobian, one classical control step, one
//! constraint check, one full classical rollout, and the full step (`full_step`: everything one
//! accepted step of a rollout costs, measured over a long rollout), also with the corrected step
//! (`full_step_corrected`: the same rollout, where no step needs a correction at 20 mm, and
//! `full_step_corrected_0.5mm`, where steps are corrected).

use std::hint::black_box;
use std::time::{Duration, Instant};

use criterion::{Criterion, criterion_group, criterion_main};
use emg_benches::{Fixture, LongRollout};
use emg_control::{
    ClassicalController, NullAction, NullSpaceController, RolloutConfig, StepContext, Tracking,
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
            let step = StepContext::new(robot, task, &config, 0, kinematics, NullAction::zeros());
            let (action, _) = controller.act(&step);
            q + step.joint_velocity(&action) * config.dt_s
        })
    });

    let kinematics = robot.forward(&q);
    c.bench_function("constraint_check", |b| {
        b.iter(|| first_violation(robot, task, black_box(&kinematics), &config.constraints))
    });

    c.bench_function("classical_rollout", |b| {
        b.iter(|| {
            let mut controller = ClassicalController::default();
            rollout(robot, black_box(task), &q, &mut controller, &config).path_length_m
        })
    });

    let LongRollout {
        task: long_task,
        seed: long_seed,
        ..
    } = fixture.long_rollout();
    let corrected = RolloutConfig {
        tracking: Tracking::Corrected,
        ..config.clone()
    };
    let mut tight = corrected.clone();
    tight.constraints.line_tolerance_m = 5e-4;
    for (name, config) in [
        ("full_step", &config),
        ("full_step_corrected", &corrected),
        ("full_step_corrected_0.5mm", &tight),
    ] {
        let mut controller = ClassicalController::default();
        let steps = rollout(robot, long_task, &long_seed, &mut controller, config)
            .steps
            .len()
            - 1;
        c.bench_function(name, |b| {
            b.iter_custom(|iterations| {
                let mut elapsed = Duration::ZERO;
                for _ in 0..iterations {
                    let mut controller = ClassicalController::default();
                    let start = Instant::now();
                    black_box(rollout(
                        robot,
                        black_box(long_task),
                        &long_seed,
                        &mut controller,
                        config,
                    ));
                    elapsed += start.elapsed();
                }
                elapsed / steps as u32
            })
        });
    }
}

criterion_group!(control, benches);
criterion_main!(control);
