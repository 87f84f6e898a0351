//! Helpers shared by the integration tests of `emg-seeding`: the shipped robot, the independent
//! checker, the first tasks of the shipped evaluation set and a small, fast labelling config.
#![allow(dead_code)]

use emg_control::Task;
use emg_io::read_tasks;
use emg_kinematics::Robot;
use emg_seeding::LabelConfig;
use emg_verify::ReferenceModel;

/// The FR3-with-pen chain of the shipped robot file.
pub fn robot() -> Robot {
    Robot::from_urdf_file(fr3_path(), "link0", "pen_tip").expect("robot loads")
}

/// The independent checker built from the same file.
pub fn checker() -> ReferenceModel {
    ReferenceModel::from_urdf_file(&fr3_path(), "link0", "pen_tip").expect("checker loads")
}

/// Path of the shipped evaluation set.
pub fn eval_path() -> std::path::PathBuf {
    std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../../data/tasks/eval-v1.tasks")
}

/// The first `count` tasks of the shipped evaluation set.
pub fn eval_tasks(robot: &Robot, count: usize) -> Vec<Task> {
    let mut tasks = read_tasks(&eval_path(), robot).expect("evaluation set reads");
    tasks.truncate(count);
    tasks
}

/// The default labelling config with fewer restarts and shorter walks (fast in debug tests).
pub fn small_config() -> LabelConfig {
    let mut config = LabelConfig::default();
    config.ik.restarts = 12;
    config.branch.max_steps = 24;
    config.stability.perturbations = 2;
    config
}

/// A fresh temporary directory for one test, removed when dropped.
pub fn temporary_dir(name: &str) -> tempfile::TempDir {
    tempfile::Builder::new()
        .prefix(&format!("emg-seeding-{name}-"))
        .tempdir()
        .expect("temporary directory")
}

/// The workspace's shipped data directory.
pub fn data_dir() -> std::path::PathBuf {
    std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../../data")
}

/// The shipped FR3 robot file.
pub fn fr3_path() -> std::path::PathBuf {
    data_dir().join("robots/fr3_pen.urdf")
}
