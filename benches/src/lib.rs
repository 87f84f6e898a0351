//! Shared fixtures of the criterion benchmarks in `benches/benches/`.
//!
//! ```
//! let fixture = emg_benches::Fixture::load();
//! assert!(!fixture.tasks.is_empty());
//! ```

use emg_control::{ClassicalController, RolloutConfig, Task, rollout};
use emg_io::read_tasks;
use emg_kinematics::{JointVector, Robot};

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

    /// The task whose classical rollout from its seed (default [`RolloutConfig`]) takes the
    /// most steps: the rollout of the `full_step` benchmark and of the instruction count of
    /// `cargo xtask bench-report`, long so that the per-rollout set-up is a small share of a
    /// step's cost.
    pub fn long_rollout(&self) -> LongRollout<'_> {
        let config = RolloutConfig::default();
        self.tasks
            .iter()
            .filter_map(|task| {
                let seed = task.q0_seed?;
                let mut controller = ClassicalController::default();
                let steps = rollout(&self.robot, task, &seed, &mut controller, &config)
                    .steps
                    .len()
                    - 1;
                Some(LongRollout { task, seed, steps })
            })
            .max_by_key(|long| long.steps)
            .expect("evaluation tasks keep their seed")
    }

    /// The workspace's shipped data directory.
    pub fn data_dir() -> std::path::PathBuf {
        std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../data")
    }
}

/// The rollout of [`Fixture::long_rollout`].
#[derive(Clone, Copy, Debug)]
pub struct LongRollout<'a> {
    /// Its task.
    pub task: &'a Task,
    /// The task's seed, where the rollout starts.
    pub seed: JointVector,
    /// Steps it accepts after the seed.
    pub steps: usize,
}

/// The shipped FR3 robot file.
fn fr3_path() -> std::path::PathBuf {
    Fixture::data_dir().join("robots/fr3_pen.urdf")
}
