//! The DP seed (50 DDIM steps, guidance 1.5, up to 32 tries) per task, over the shipped weights
//! and the first evaluation tasks; criterion reports the median and the spread.

use std::hint::black_box;

use criterion::{Criterion, criterion_group, criterion_main};
use emg_benches::Fixture;
use emg_control::RolloutConfig;
use emg_diffusion::{DenoiserWeights, DpSeedConfig, DpSeeder, SeedWorkspace};

fn benches(c: &mut Criterion) {
    let fixture = Fixture::load();
    let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../data/models/diffusion-v1.weights");
    let weights =
        DenoiserWeights::read(&path).expect("shipped weights load (cargo xtask train-diffusion)");
    let seeder = DpSeeder::new(&fixture.robot, &weights, DpSeedConfig::default())
        .expect("weights fit the seeder");
    let constraints = RolloutConfig::default().constraints;
    let mut workspace = SeedWorkspace::default();
    let mut next = 0;
    c.bench_function("dp_seed_per_task", |b| {
        b.iter(|| {
            let task = &fixture.tasks[next % fixture.tasks.len()];
            next += 1;
            seeder
                .seed(
                    &fixture.robot,
                    black_box(task),
                    &constraints,
                    &mut workspace,
                )
                .expect("evaluation tasks have a fallback")
        })
    });
}

criterion_group!(diffusion, benches);
criterion_main!(diffusion);
