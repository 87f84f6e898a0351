//! Shared fixtures of the criterion benchmarks in `benches/benches/`.
//!
//! ```
//! let fixture = emg_benches::Fixture::load();
//! assert!(!fixture.tasks.is_empty());
//! ```

use emg_control::Task;
use emg_io::read_tasks;
use emg_kinematics::Robot;

/// The shipped robot and the first tasks of the shipped evaluation set.
pub struct Fixture {
    /// FR3 with the pen.
    pub robot: Robot,
    /// The first 100 evaluation tasks.
    pub tasks: Vec<Task>,
}

impl Fixture {
    /// Loads the robot file and the evaluation set from `data/`.
    pub fn load() -> Self {
        let robot = Robot::from_urdf_file(fr3_path(), "link0", "pen_tip")
            .expect("shipped robot file loads");
        let path = Self::data_dir().join("tasks/eval-v1.tasks");
        let mut tasks = read_tasks(&path, &robot)
            .expect("shipped evaluation set loads (cargo xtask make-tasks)");
        tasks.truncate(100);
        Self { robot, tasks }
    }

    /// The workspace's shipped data directory.
    pub fn data_dir() -> std::path::PathBuf {
        std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../data")
    }
}

/// The shipped FR3 robot file.
fn fr3_path() -> std::path::PathBuf {
    Fixture::data_dir().join("robots/fr3_pen.urdf")
}
