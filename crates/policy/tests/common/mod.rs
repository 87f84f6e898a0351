//! Shared fixtures of the policy tests.

use emg_control::{ClassicalGains, RolloutConfig, SamplerConfig, Task, TaskSampler};
use emg_kinematics::Robot;

/// The FR3 with the pen tool.
pub fn robot() -> Robot {
    Robot::from_urdf_file(fr3_path(), "link0", "pen_tip").expect("the robot file loads")
}

/// `count` tasks from the standard population (fixed seed).
pub fn tasks(robot: &Robot, count: usize) -> Vec<Task> {
    let rollout = RolloutConfig::default();
    let gains = ClassicalGains::default();
    let config = SamplerConfig {
        seed: 7,
        batch_size: 64,
        ..SamplerConfig::default()
    };
    TaskSampler::new(robot, &rollout, &gains, &config).take(count, u64::MAX, &|_| {})
}

/// The workspace's shipped data directory.
pub fn data_dir() -> std::path::PathBuf {
    std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../../data")
}

/// The shipped FR3 robot file.
pub fn fr3_path() -> std::path::PathBuf {
    data_dir().join("robots/fr3_pen.urdf")
}
