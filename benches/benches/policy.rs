//! Batch-1 policy inference (the plain-Rust actor forward plus `tanh`) over the shipped PPO
//! weights: the per-step cost of the RL controller besides the shared step.

use std::hint::black_box;

use criterion::{Criterion, criterion_group, criterion_main};
use emg_policy::{OBSERVATION_DIM, PlainPolicy, PolicyWeights};

fn benches(c: &mut Criterion) {
    let path =
        std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../data/models/ppo-v1.weights");
    let weights = PolicyWeights::read(&path).expect("shipped weights load (cargo xtask train-ppo)");
    let policy = PlainPolicy::new(&weights);
    let mut scratch = policy.scratch();
    let observation: [f32; OBSERVATION_DIM] = std::array::from_fn(|i| libm::sinf(i as f32 * 0.37));
    c.bench_function("policy_action_batch1", |b| {
        b.iter(|| {
            policy
                .actor(black_box(&observation), &mut scratch)
                .deterministic_action()
        })
    });
}

criterion_group!(policy, benches);
criterion_main!(policy);
