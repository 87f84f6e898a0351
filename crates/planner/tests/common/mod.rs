//! What the tests that time plans share: a shipped arm's planner, its independent checker and
//! its timing as `emg plan` sets them up, and a plan's files written as `emg plan` writes them
//! and verified as `emg check` verifies them.

use emg_control::Task;
use emg_io::TrajectoryContents;
use emg_kinematics::Robot;
use emg_planner::{
    DataDir, Models, MotionTiming, Plan, PlanFiles, PlanRecord, PlanRequest, Planner,
    PlannerConfig, ShippedRobot, limits_file_beside,
};
use emg_timing::Scaling;
use emg_verify::ReferenceModel;

/// The repository's `data/`.
pub fn data() -> DataDir {
    DataDir::new(std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../../data"))
}

/// A shipped arm set up as `emg plan` sets it up.
pub struct TimedArm {
    /// The arm's name.
    pub name: &'static str,
    /// Its planner, with the given config.
    pub planner: Planner,
    /// The independent checker of its robot file.
    pub checker: ReferenceModel,
    /// Its timing: the shipped joint limits, the rollout's line speed, 1 kHz.
    pub timing: MotionTiming,
}

impl TimedArm {
    /// `arm` with its shipped models and `config`.
    pub fn new(arm: ShippedRobot, config: PlannerConfig) -> Self {
        let file = arm.path(&data());
        let robot = Robot::from_chain_file(&file).expect("robot loads");
        let models = Models::shipped(&robot, &arm.data_dir(&data())).expect("shipped models");
        let planner = Planner::new(robot, models, config).expect("valid config");
        let checker = ReferenceModel::from_urdf_file(
            &file,
            planner.robot().base_link(),
            planner.robot().tip_link(),
        )
        .expect("checker");
        let timing = MotionTiming::new(
            planner.robot(),
            &limits_file_beside(&file),
            Scaling::default(),
            planner.config().rollout.speed_m_per_s,
            1000.0,
            &planner.config().rollout.constraints,
        )
        .expect("shipped joint limits");
        Self {
            name: arm.name,
            planner,
            checker,
            timing,
        }
    }

    /// The files of `plan` (of `task`, planned for `request`), each read back and verified with
    /// every sample's constraints; panics naming `what` when one fails.
    pub fn checked_files(
        &self,
        what: &str,
        task: &Task,
        plan: &Plan,
        request: &PlanRequest,
    ) -> PlanFiles {
        let record = PlanRecord {
            robot: self.name,
            request,
            bound: None,
            timing: &self.timing,
        };
        let files = PlanFiles::new(&self.planner, task, plan, &record).expect("timed");
        for text in [&files.json, &files.joint_trajectory] {
            TrajectoryContents::parse(text)
                .expect("a trajectory file")
                .verify(
                    &self.checker,
                    self.planner.robot().joint_names(),
                    task,
                    &self.planner.config().rollout.constraints,
                    true,
                    None,
                )
                .unwrap_or_else(|e| panic!("{what}: {e}"));
        }
        files
    }
}
