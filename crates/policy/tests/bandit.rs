//! PPO learns a problem with a known optimum: a one-step continuous bandit whose reward
//! `1 − mean((a − a*)²)` peaks at the action `a*`.

use emg_policy::{
    ACTION_DIM, Backend, Environment, EpisodeEnd, NetworkConfig, OBSERVATION_DIM, PlainPolicy,
    PpoConfig, Trainer, Transition,
};
use rand_chacha::ChaCha8Rng;

const OPTIMUM: [f32; ACTION_DIM] = [0.6, -0.4, 0.2, -0.7];

/// Every episode is one step from the same observation.
struct Bandit;

impl Environment for Bandit {
    fn reset(&mut self, _rng: &mut ChaCha8Rng) {}

    fn observe(&self, out: &mut [f32; OBSERVATION_DIM]) {
        *out = [0.0; OBSERVATION_DIM];
        out[0] = 1.0;
    }

    fn step(&mut self, action: &[f32; ACTION_DIM]) -> Transition {
        let error: f32 = action
            .iter()
            .zip(OPTIMUM)
            .map(|(a, b)| (a - b) * (a - b))
            .sum::<f32>()
            / ACTION_DIM as f32;
        Transition {
            reward: f64::from(1.0 - error),
            end: Some(EpisodeEnd::Terminated),
        }
    }

    fn score(&self) -> f64 {
        0.0
    }
}

fn greedy_action(trainer: &Trainer) -> [f32; ACTION_DIM] {
    let policy = PlainPolicy::new(&trainer.weights());
    let mut observation = [0.0; OBSERVATION_DIM];
    Bandit.observe(&mut observation);
    policy
        .actor(&observation, &mut policy.scratch())
        .deterministic_action()
}

#[test]
fn ppo_finds_the_optimum_of_a_bandit() {
    let ppo = PpoConfig {
        seed: 11,
        envs: 32,
        rollout_steps: 8,
        minibatches: 4,
        epochs: 5,
        total_env_steps: 32 * 8 * 80,
        learning_rate: 3e-3,
        entropy_coefficient: 0.0,
        ..PpoConfig::default()
    };
    let mut trainer = Trainer::new(
        NetworkConfig {
            hidden: vec![16],
            ..NetworkConfig::default()
        },
        ppo,
        Backend::Flex,
    )
    .unwrap();
    let start = greedy_action(&trainer);
    assert!(
        start.iter().zip(OPTIMUM).any(|(a, b)| (a - b).abs() > 0.3),
        "the untrained policy is already near the optimum: {start:?}"
    );
    let mut envs = trainer
        .start_envs((0..32).map(|_| Bandit).collect())
        .unwrap();
    while !trainer.is_done() {
        trainer.iterate(&mut envs).unwrap();
    }
    let learned = greedy_action(&trainer);
    for (k, (a, b)) in learned.iter().zip(OPTIMUM).enumerate() {
        assert!(
            (a - b).abs() < 0.1,
            "action {k}: learned {a}, optimum {b} ({learned:?})"
        );
    }
}
