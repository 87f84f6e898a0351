//! PPO on the real arm environment: a short run improves the policy, and a run resumed from a
//! checkpoint continues the very same learning curve.

mod common;

use emg_control::{RolloutConfig, Task, rollout};
use emg_kinematics::Robot;
use emg_policy::{
    Backend, EnvConfig, NetworkConfig, PolicyWeights, PpoConfig, RlController, Trainer,
    TrainingPool,
};

fn pool(robot: &Robot, tasks: usize) -> TrainingPool {
    TrainingPool::new(
        robot.clone(),
        common::tasks(robot, tasks),
        None,
        RolloutConfig::default(),
        EnvConfig::default(),
    )
    .unwrap()
}

fn small_ppo(iterations: u64) -> PpoConfig {
    PpoConfig {
        seed: 5,
        envs: 16,
        rollout_steps: 32,
        minibatches: 4,
        epochs: 4,
        total_env_steps: 16 * 32 * iterations,
        learning_rate: 1e-3,
        ..PpoConfig::default()
    }
}

/// Mean undiscounted return `Σ clip(Δp·d / (v·Δt), 0, 1)` of the deterministic policy from each
/// task's `q0_seed`.
fn mean_return(robot: &Robot, tasks: &[Task], weights: &PolicyWeights) -> f64 {
    let config = RolloutConfig::default();
    let step_m = config.speed_m_per_s * config.dt_s;
    let total: f64 = tasks
        .iter()
        .map(|task| {
            let mut controller = RlController::new(weights);
            let seed = task.q0_seed.unwrap();
            let trajectory = rollout(robot, task, &seed, &mut controller, &config);
            trajectory
                .steps
                .windows(2)
                .map(|w| ((w[1].tcp - w[0].tcp).dot(&task.d) / step_m).clamp(0.0, 1.0))
                .sum::<f64>()
        })
        .sum();
    total / tasks.len() as f64
}

#[test]
fn a_short_run_raises_the_mean_return_above_the_untrained_policy() {
    let robot = common::robot();
    let pool = pool(&robot, 8);
    let tasks = common::tasks(&robot, 8);
    let network = NetworkConfig {
        hidden: vec![32, 32],
        ..NetworkConfig::default()
    };
    let mut trainer = Trainer::new(network, small_ppo(40), Backend::Flex).unwrap();
    let untrained = mean_return(&robot, &tasks, &trainer.weights());
    let mut envs = trainer.start_envs(pool.environments(16)).unwrap();
    while !trainer.is_done() {
        trainer.iterate(&mut envs).unwrap();
    }
    let trained = mean_return(&robot, &tasks, &trainer.weights());
    assert!(
        trained > untrained + 1.0,
        "mean return {trained:.2} after training, {untrained:.2} before"
    );
}

/// The same episodes, epochs and learning rates, the same statistics to rounding (Burn's CPU
/// reductions may round differently from run to run in the last bit) and the same weights.
#[test]
fn a_resumed_run_continues_the_same_curve() {
    let robot = common::robot();
    let pool = pool(&robot, 6);
    let network = NetworkConfig {
        hidden: vec![16],
        ..NetworkConfig::default()
    };
    let ppo = small_ppo(4);

    let mut straight = Trainer::new(network.clone(), ppo.clone(), Backend::Flex).unwrap();
    let mut envs = straight.start_envs(pool.environments(16)).unwrap();
    for _ in 0..4 {
        straight.iterate(&mut envs).unwrap();
    }

    let tmp = tempfile::tempdir().unwrap();
    let dir = tmp.path().join("checkpoint");
    let mut first = Trainer::new(network.clone(), ppo.clone(), Backend::Flex).unwrap();
    let mut envs = first.start_envs(pool.environments(16)).unwrap();
    for _ in 0..2 {
        first.iterate(&mut envs).unwrap();
    }
    first.save_checkpoint(&dir, &envs).unwrap();
    drop((first, envs));
    let (mut resumed, mut envs) = Trainer::resume(
        &dir,
        network.clone(),
        ppo.clone(),
        Backend::Flex,
        pool.environments(16),
    )
    .unwrap();
    for _ in 0..2 {
        resumed.iterate(&mut envs).unwrap();
    }
    assert_eq!(resumed.log().len(), straight.log().len());
    for (a, b) in resumed.log().iter().zip(straight.log()) {
        assert_eq!(
            (a.iteration, a.env_steps, a.episodes, a.epochs),
            (b.iteration, b.env_steps, b.episodes, b.epochs)
        );
        let pairs = [
            (a.mean_return.unwrap_or(0.0), b.mean_return.unwrap_or(0.0)),
            (a.mean_score.unwrap_or(0.0), b.mean_score.unwrap_or(0.0)),
            (a.policy_loss, b.policy_loss),
            (a.value_loss, b.value_loss),
            (a.entropy, b.entropy),
            (a.approx_kl, b.approx_kl),
            (a.learning_rate, b.learning_rate),
        ];
        for (x, y) in pairs {
            assert!(
                (x - y).abs() <= 1e-9 * (1.0 + y.abs()),
                "iteration {}: {x} vs {y}",
                a.iteration
            );
        }
    }
    let (a, b) = (resumed.weights(), straight.weights());
    let largest = a
        .values()
        .iter()
        .zip(b.values())
        .map(|(x, y)| (x - y).abs())
        .fold(0.0, f32::max);
    assert!(largest < 1e-6, "weights differ by up to {largest}");

    let other = PpoConfig { clip: 0.3, ..ppo };
    let error = Trainer::resume(&dir, network, other, Backend::Flex, pool.environments(16))
        .err()
        .expect("a changed configuration is refused");
    assert!(error.to_string().contains("PPO config"), "{error}");
}
