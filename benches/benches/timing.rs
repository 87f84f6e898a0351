//! Timing planned motions rest to rest on one core: smooth path, TOPP-RA, jerk limiting and
//! 1 kHz samples with their limit checks, for the search plans of the first 20 evaluation tasks
//! (a fixed set: tasks differ a lot in length) per iteration.

use std::hint::black_box;

use criterion::{Criterion, criterion_group, criterion_main};
use emg_benches::Fixture;
use emg_planner::{
    DEFAULT_RATE_HZ, Models, MotionTiming, PlanRequest, Planner, PlannerConfig, limits_file_beside,
};
use emg_timing::Scaling;

/// Plans timed per iteration.
const TASKS: usize = 20;

fn benches(c: &mut Criterion) {
    let fixture = Fixture::load();
    let models = Models::shipped(&fixture.robot, &Fixture::data_dir()).expect("shipped models");
    let config = PlannerConfig::default();
    let planner =
        Planner::new(fixture.robot.clone(), models, config.clone()).expect("default config");
    let tasks = &fixture.tasks[..TASKS];
    let plans: Vec<_> = tasks
        .iter()
        .map(|task| {
            planner
                .plan(task, &PlanRequest::pipeline())
                .expect("evaluation tasks plan")
        })
        .collect();
    let timing = MotionTiming::new(
        planner.robot(),
        &limits_file_beside(&Fixture::data_dir().join("robots/fr3_pen.urdf")),
        Scaling::default(),
        config.rollout.speed_m_per_s,
        DEFAULT_RATE_HZ,
        &config.rollout.constraints,
    )
    .expect("the shipped limits");
    let constraints = &config.rollout.constraints;
    let mut group = c.benchmark_group("timing");
    group.sample_size(10);
    group.bench_function("rest_to_rest_1khz_20_search_plans", |b| {
        b.iter(|| {
            tasks
                .iter()
                .zip(&plans)
                .map(|(task, plan)| {
                    timing
                        .time(
                            planner.robot(),
                            task,
                            constraints,
                            black_box(&plan.trajectory),
                        )
                        .expect("search plans time")
                        .samples
                        .len()
                })
                .sum::<usize>()
        })
    });
    group.finish();
}

criterion_group!(timing, benches);
criterion_main!(timing);
