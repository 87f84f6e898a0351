//! Helpers shared by the integration tests of `emg-control`: the shipped robot, the independent
//! checker, a seeded generator and a small deterministic set of sampled tasks.
#![allow(dead_code)]

use emg_control::{
    ClassicalController, RolloutConfig, SamplerConfig, Task, Trajectory, candidate, rollout,
};
use emg_kinematics::{JointVector, Robot};
use emg_verify::ReferenceModel;
use rand::{RngExt, SeedableRng};
use rand_chacha::ChaCha8Rng;

/// The FR3-with-pen chain of the shipped robot file.
pub fn robot() -> Robot {
    Robot::from_urdf_file(fr3_path(), "link0", "pen_tip").expect("shipped robot file loads")
}

/// The independent checker built from the same file.
pub fn checker() -> ReferenceModel {
    ReferenceModel::from_urdf_file(&fr3_path(), "link0", "pen_tip").expect("checker loads")
}

/// A deterministic generator.
pub fn rng(seed: u64) -> ChaCha8Rng {
    ChaCha8Rng::seed_from_u64(seed)
}

/// A configuration drawn uniformly within the joint limits.
pub fn random_q(rng: &mut ChaCha8Rng, robot: &Robot) -> JointVector {
    let limits = robot.limits();
    JointVector::from_fn(|i, _| rng.random_range(limits.lower[i]..limits.upper[i]))
}

/// The first `count` candidate tasks of the default population (skipping rejected indices),
/// with their candidate indices.
pub fn tasks(robot: &Robot, count: usize) -> Vec<(u64, Task)> {
    let config = SamplerConfig::default();
    let mut out = Vec::with_capacity(count);
    let mut index = 0;
    while out.len() < count {
        if let Some(task) = candidate(robot, &config, index) {
            out.push((index, task));
        }
        index += 1;
        assert!(
            index < 100 * count as u64 + 1000,
            "the sampler rejects almost every candidate"
        );
    }
    out
}

/// The classical rollout of `task` from its `q0_seed`.
pub fn classical(robot: &Robot, task: &Task, config: &RolloutConfig) -> Trajectory {
    let seed = task.q0_seed.expect("sampled tasks keep their seed");
    rollout(
        robot,
        task,
        &seed,
        &mut ClassicalController::default(),
        config,
    )
}

/// The workspace's shipped data directory.
pub fn data_dir() -> std::path::PathBuf {
    std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../../data")
}

/// The shipped FR3 robot file.
pub fn fr3_path() -> std::path::PathBuf {
    data_dir().join("robots/fr3_pen.urdf")
}
