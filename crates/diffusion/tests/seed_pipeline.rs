//! The DP seed pipeline: every returned seed is on the exact start pose and breaks no
//! constraint, or is the fallback `q0_seed`; the batching never changes the result.

use emg_control::{RolloutConfig, Task, first_violation};
use emg_diffusion::{
    Backend, DenoiserWeights, DiffusionConfig, DpSeedConfig, DpSeeder, SampleConfig, SeedOrigin,
    SeedWorkspace, TrainConfig, Trainer, TrainingSet,
};
use emg_kinematics::{JointVector, Robot, Vec3};

fn robot() -> Robot {
    Robot::from_urdf_file(fr3_path(), "link0", "pen_tip").unwrap()
}

/// Tasks generated from a few configurations around mid-range.
fn tasks(robot: &Robot) -> Vec<Task> {
    (0..4)
        .map(|k| {
            let q =
                robot.mid_range() + JointVector::from_fn(|i, _| 0.15 * libm::sin((i + k) as f64));
            let kin = robot.forward(&q);
            let n = kin.tool_axis();
            let d = (Vec3::y() - n * n.dot(&Vec3::y())).normalize();
            Task::new(robot, kin.tcp(), d, n, Some(q)).unwrap()
        })
        .collect()
}

/// An (almost) untrained network: the pipeline must still only return valid seeds.
fn weights() -> DenoiserWeights {
    let data = TrainingSet::new(vec![0.1; 9 * 8], vec![0.0; 7 * 8], 9, 7, "zeros").unwrap();
    let network = DiffusionConfig {
        width: 16,
        hidden: 32,
        blocks: 1,
        time_dim: 8,
        ..DiffusionConfig::default()
    };
    let mut trainer = Trainer::new(
        network,
        TrainConfig {
            batch_size: 8,
            ..TrainConfig::default()
        },
        Backend::Flex,
        &data,
    )
    .unwrap();
    trainer.train_step(&data);
    trainer.ema_weights().clone()
}

/// A seeder over `weights`; both seeders of a comparison share one set of weights, since Burn's
/// random generator is process-wide and tests training in parallel would make two trainings differ.
fn seeder(robot: &Robot, weights: &DenoiserWeights, first_batch: usize) -> DpSeeder {
    let config = DpSeedConfig {
        sample: SampleConfig {
            steps: 5,
            ..SampleConfig::default()
        },
        first_batch,
        ..DpSeedConfig::default()
    };
    DpSeeder::new(robot, weights, config).unwrap()
}

#[test]
fn seeds_are_valid_or_the_fallback_and_independent_of_batching() {
    let robot = robot();
    let constraints = RolloutConfig::default().constraints;
    let weights = weights();
    let (one, all) = (seeder(&robot, &weights, 1), seeder(&robot, &weights, 32));
    let mut workspace = SeedWorkspace::default();
    for task in tasks(&robot) {
        let seed = one
            .seed(&robot, &task, &constraints, &mut workspace)
            .unwrap();
        assert!((1..=32).contains(&seed.tries));
        match seed.origin {
            SeedOrigin::Diffusion => {
                let kin = robot.forward(&seed.q);
                assert!((kin.tcp() - task.p0).norm() < 1e-6);
                assert!(first_violation(&robot, &task, &kin, &constraints).is_none());
            }
            SeedOrigin::Fallback => {
                assert_eq!(seed.tries, 32);
                assert_eq!(Some(seed.q), task.q0_seed);
            }
        }
        let batched = all
            .seed(&robot, &task, &constraints, &mut workspace)
            .unwrap();
        assert_eq!(
            (batched.q, batched.origin, batched.tries),
            (seed.q, seed.origin, seed.tries)
        );
    }
}

#[test]
fn a_task_without_fallback_and_no_valid_candidate_is_a_clear_error() {
    let robot = robot();
    let constraints = RolloutConfig::default().constraints;
    // A start inside the base: no candidate can be projected there without a collision.
    let mut task = tasks(&robot).remove(0);
    task.q0_seed = None;
    task.p0 = Vec3::new(0.0, 0.0, 0.2);
    let config = DpSeedConfig {
        max_tries: 2,
        sample: SampleConfig {
            steps: 3,
            ..SampleConfig::default()
        },
        ..DpSeedConfig::default()
    };
    let seeder = DpSeeder::new(&robot, &weights(), config).unwrap();
    let error = seeder
        .seed(&robot, &task, &constraints, &mut SeedWorkspace::default())
        .unwrap_err();
    assert!(error.to_string().contains("no q0_seed"), "{error}");
}

/// The workspace's shipped data directory.
fn data_dir() -> std::path::PathBuf {
    std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../../data")
}

/// The shipped FR3 robot file.
fn fr3_path() -> std::path::PathBuf {
    data_dir().join("robots/fr3_pen.urdf")
}
