//! Planning time on one core: the paper's pipeline (DP seed, one hybrid rollout) and the search
//! planner at its default step budget, each planning the first 20 evaluation tasks per
//! iteration (tasks differ a lot in length; a fixed set keeps the median comparable), and the
//! reachability bound that `emg plan` prints beside each plan, for the same tasks, on one core
//! and on all (a point's restarts are tried in parallel).

use std::hint::black_box;

use criterion::{Criterion, criterion_group, criterion_main};
use emg_benches::Fixture;
use emg_planner::{Models, PlanRequest, Planner, PlannerConfig, PlannerKind};

/// Tasks planned per iteration.
const TASKS: usize = 20;

fn benches(c: &mut Criterion) {
    let fixture = Fixture::load();
    let models = Models::shipped(&fixture.robot, &Fixture::data_dir()).expect("shipped models");
    let planner = Planner::new(fixture.robot.clone(), models, PlannerConfig::default())
        .expect("default config");
    let tasks = &fixture.tasks[..TASKS];
    let one_core = rayon::ThreadPoolBuilder::new()
        .num_threads(1)
        .build()
        .expect("a one-thread pool");
    let mut group = c.benchmark_group("plan");
    group.sample_size(10);
    for (name, planner_kind) in [
        ("pipeline_hybrid_dp_20_tasks", PlannerKind::Controller),
        ("search_default_budget_20_tasks", PlannerKind::Search),
    ] {
        let request = PlanRequest {
            planner: planner_kind,
            ..PlanRequest::pipeline()
        };
        group.bench_function(name, |b| {
            b.iter(|| {
                one_core.install(|| {
                    tasks
                        .iter()
                        .map(|task| {
                            planner
                                .plan(black_box(task), &request)
                                .expect("evaluation tasks plan")
                                .trajectory
                                .path_length_m
                        })
                        .sum::<f64>()
                })
            })
        });
    }
    let reach_all = || {
        tasks
            .iter()
            .map(|task| planner.reach(black_box(task), &[]).reachable_m)
            .sum::<f64>()
    };
    group.bench_function("reach_bound_20_tasks", |b| {
        b.iter(|| one_core.install(reach_all))
    });
    group.bench_function("reach_bound_20_tasks_all_cores", |b| b.iter(reach_all));
    group.finish();
}

criterion_group!(planner, benches);
criterion_main!(planner);
