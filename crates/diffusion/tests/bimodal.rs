//! Acceptance: a tiny model trained for a few seconds on a known 2-D bimodal conditional
//! distribution samples both modes of the right condition; guidance w = 0 ignores the condition.

use emg_diffusion::{
    Backend, DdimSampler, DiffusionConfig, SampleConfig, TrainConfig, Trainer, TrainingSet,
};
use emg_learning::StandardNormal;
use rand::{RngExt, SeedableRng};
use rand_chacha::ChaCha8Rng;

/// The condition is `[s, 0.5]` (the network's LayerNorm needs two components to carry `s`).
/// Condition s = +1: modes (0.5, 0.5) and (−0.5, −0.5); condition −1: (0.5, −0.5) and (−0.5, 0.5).
fn modes(condition: f32) -> [[f32; 2]; 2] {
    [[0.5, 0.5 * condition], [-0.5, -0.5 * condition]]
}

fn data() -> TrainingSet {
    let mut rng = ChaCha8Rng::seed_from_u64(7);
    let (mut conditions, mut samples) = (Vec::new(), Vec::new());
    for i in 0..2000 {
        let c = if i % 2 == 0 { 1.0f32 } else { -1.0 };
        let mode = modes(c)[rng.random_range(0..2usize)];
        conditions.extend([c, 0.5]);
        for m in mode {
            samples.push(m + 0.03 * rng.sample::<f32, _>(StandardNormal));
        }
    }
    TrainingSet::new(conditions, samples, 2, 2, "bimodal").expect("valid data")
}

fn trained() -> emg_diffusion::DenoiserWeights {
    let data = data();
    let network = DiffusionConfig {
        data_dim: 2,
        condition_dim: 2,
        width: 48,
        hidden: 96,
        blocks: 2,
        time_dim: 16,
        timesteps: 1000,
    };
    let training = TrainConfig {
        steps: 1200,
        batch_size: 128,
        learning_rate: 3e-3,
        ema_decay: 0.99,
        dropout: 0.0,
        ..TrainConfig::default()
    };
    let mut trainer = Trainer::new(network, training, Backend::Flex, &data).expect("trainer");
    let first = trainer.train_step(&data);
    for _ in 1..1200 {
        trainer.train_step(&data);
    }
    let log = trainer.loss_log();
    assert!(
        log.last().unwrap().loss < 0.5 * first,
        "loss {first} → {:?}",
        log.last()
    );
    trainer.ema_weights().clone()
}

fn noise(n: usize, seed: u64) -> Vec<f32> {
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    (0..2 * n).map(|_| rng.sample(StandardNormal)).collect()
}

fn nearest_mode(x: &[f32], condition: f32) -> Option<usize> {
    modes(condition)
        .iter()
        .position(|m| ((x[0] - m[0]).powi(2) + (x[1] - m[1]).powi(2)).sqrt() < 0.2)
}

#[test]
fn samples_land_in_both_modes_of_their_condition_and_w0_ignores_it() {
    let weights = trained();
    let sampler = DdimSampler::new(&weights);
    let mut workspace = Default::default();
    let n = 200;
    for condition in [1.0f32, -1.0] {
        let mut samples = noise(n, 1);
        let config = SampleConfig {
            steps: 20,
            guidance_scale: 1.5,
            ..SampleConfig::default()
        };
        sampler
            .sample(&[condition, 0.5], &config, &mut samples, &mut workspace)
            .unwrap();
        let mut counts = [0usize; 2];
        for x in samples.chunks_exact(2) {
            if let Some(m) = nearest_mode(x, condition) {
                counts[m] += 1;
            }
        }
        let wrong = samples
            .chunks_exact(2)
            .filter(|x| nearest_mode(x, -condition).is_some())
            .count();
        assert!(
            counts[0] + counts[1] >= 170,
            "condition {condition}: {counts:?} of {n} in the right modes, {wrong} in the wrong ones: {:?}",
            &samples[..16]
        );
        assert!(
            counts[0] >= 40 && counts[1] >= 40,
            "condition {condition}: both modes must be hit, got {counts:?}"
        );
        assert!(
            wrong <= 10,
            "condition {condition}: {wrong} samples in the other condition's modes"
        );
    }

    // w = 0: the condition is ignored, bit for bit, and samples reach the modes of both
    // conditions (the null branch saw only p_drop = 10 % of the steps, so it is less sharp).
    let unguided = SampleConfig {
        steps: 20,
        guidance_scale: 0.0,
        ..SampleConfig::default()
    };
    let (mut plus, mut minus) = (noise(n, 2), noise(n, 2));
    sampler
        .sample(&[1.0, 0.5], &unguided, &mut plus, &mut workspace)
        .unwrap();
    sampler
        .sample(&[-1.0, 0.5], &unguided, &mut minus, &mut workspace)
        .unwrap();
    assert_eq!(plus, minus);
    let in_plus = plus
        .chunks_exact(2)
        .filter(|x| nearest_mode(x, 1.0).is_some())
        .count();
    let in_minus = plus
        .chunks_exact(2)
        .filter(|x| nearest_mode(x, -1.0).is_some())
        .count();
    assert!(
        in_plus >= 10 && in_minus >= 10,
        "unconditional samples: {in_plus} / {in_minus}"
    );
}
