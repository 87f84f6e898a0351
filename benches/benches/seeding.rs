//! Seeding benchmarks: one heuristic seed of each objective (q_μ, q_jl) and the full labelling of
//! one task (IK restarts, branch walks, scoring rollouts, stability).

use std::hint::black_box;

use criterion::{Criterion, criterion_group, criterion_main};
use emg_benches::Fixture;
use emg_kinematics::ProjectionConfig;
use emg_seeding::{HeuristicConfig, HeuristicObjective, LabelConfig, heuristic_seed, label_task};

fn benches(c: &mut Criterion) {
    let fixture = Fixture::load();
    let robot = &fixture.robot;
    let task = &fixture.tasks[0];
    let (heuristic, projection) = (HeuristicConfig::default(), ProjectionConfig::default());
    for (name, objective) in [
        ("heuristic_seed_q_mu", HeuristicObjective::Manipulability),
        ("heuristic_seed_q_jl", HeuristicObjective::JointCentring),
    ] {
        c.bench_function(name, |b| {
            b.iter(|| heuristic_seed(robot, black_box(task), objective, &heuristic, &projection))
        });
    }
    let config = LabelConfig::default();
    let mut group = c.benchmark_group("labelling");
    group.sample_size(20);
    group.bench_function("label_one_task", |b| {
        b.iter(|| label_task(robot, black_box(task), 0, &config))
    });
    group.finish();
}

criterion_group!(seeding, benches);
criterion_main!(seeding);
