//! The files of one planned task, built and written the same way by every front end (`emg plan`,
//! the Python package): `emg-trajectory/1` JSON, the CSV table and `emg-joint-trajectory/2` JSON
//! (the plan timed rest to rest by [`MotionTiming`]).

use emg_control::Task;
use emg_io::{
    FormatError, JointTrajectory, PlanPaths, TRAJECTORY_FORMAT, TimingSummary, TrajectoryFile,
    trajectory_csv, write_atomically,
};
use emg_timing::TimingError;

use crate::planner::{Plan, PlanRequest, Planner};
use crate::reach::BoundNote;
use crate::timing::MotionTiming;

/// How a plan was asked for, as its files record it.
#[derive(Clone, Copy, Debug)]
pub struct PlanRecord<'a> {
    /// The robot as the files name it: a shipped robot's file, or the path the user gave.
    pub robot: &'a str,
    /// The request the plan answered (its planner and controller are recorded).
    pub request: &'a PlanRequest,
    /// What the files say of the task's reachability bound, when it was computed
    /// ([`Planner::bound_note`]).
    pub bound: Option<&'a BoundNote>,
    /// How the joint trajectory is timed.
    pub timing: &'a MotionTiming,
}

/// The text of the three files of one planned task.
#[derive(Clone, Debug, PartialEq)]
pub struct PlanFiles {
    /// `emg-trajectory/1` JSON: task, settings, every step, why it ended.
    pub json: String,
    /// The CSV table of the steps.
    pub csv: String,
    /// `emg-joint-trajectory/2` JSON, for a robot stack to replay.
    pub joint_trajectory: String,
    /// How the joint trajectory was timed.
    pub timing: TimingSummary,
    /// When the timed motion passes each planned step (s): the planned steps played at the
    /// executed motion's pace ([`emg_timing::TimedMotion::passing_times_s`]).
    pub step_times_s: Vec<f64>,
}

/// Why a plan's files could not be written.
#[derive(Debug, thiserror::Error)]
pub enum PlanFilesError {
    /// The trajectory does not make a valid joint trajectory.
    #[error("cannot build the joint trajectory: {0}")]
    JointTrajectory(#[from] FormatError),
    /// The trajectory could not be timed within the limits.
    #[error("cannot time the joint trajectory: {0}")]
    Timing(#[from] TimingError),
    /// Writing a file failed.
    #[error("cannot write {path}: {source}")]
    Write {
        /// The file.
        path: String,
        /// The operating system's error.
        source: std::io::Error,
    },
}

impl PlanFiles {
    /// The files of `plan`, made by `planner` for `task` as `record` says.
    pub fn new(
        planner: &Planner,
        task: &Task,
        plan: &Plan,
        record: &PlanRecord<'_>,
    ) -> Result<Self, PlanFilesError> {
        let robot = planner.robot();
        let config = planner.config();
        let trajectory = &plan.trajectory;
        let file = TrajectoryFile {
            format: TRAJECTORY_FORMAT,
            robot: record.robot.to_string(),
            joint_names: robot.joint_names(),
            task,
            seed_source: plan.seed.source,
            planner: record.request.planner.name(),
            controller: record.request.controller.name(),
            config: &config.rollout,
            gains: &config.gains,
            steps: &trajectory.steps,
            termination: &trajectory.termination,
            path_length_m: trajectory.path_length_m,
            reachable_m: record.bound.map(|bound| bound.reachable_m),
            below_bound: record.bound.and_then(|bound| bound.shortfall.clone()),
        };
        let constraints = &config.rollout.constraints;
        let motion = record.timing.time(robot, task, constraints, trajectory)?;
        let joint = JointTrajectory::new(
            record.robot,
            robot.joint_names(),
            task,
            constraints,
            record.timing.record(),
            &motion,
            record.timing.request().rate_hz,
        )?;
        let mut joint_trajectory = joint.to_json();
        joint_trajectory.push('\n');
        let planned: Vec<_> = trajectory.steps.iter().map(|step| step.q).collect();
        Ok(Self {
            json: file.to_json(),
            csv: trajectory_csv(&trajectory.steps, robot.dof()),
            timing: joint.timing.clone(),
            joint_trajectory,
            step_times_s: motion.passing_times_s(&planned),
        })
    }

    /// Writes the three files to `paths`, each atomically, creating parent directories.
    pub fn write(&self, paths: &PlanPaths) -> Result<(), PlanFilesError> {
        for (path, text) in [
            (&paths.json, &self.json),
            (&paths.csv, &self.csv),
            (&paths.joint_trajectory, &self.joint_trajectory),
        ] {
            write_atomically(path, text).map_err(|source| PlanFilesError::Write {
                path: path.display().to_string(),
                source,
            })?;
        }
        Ok(())
    }
}
