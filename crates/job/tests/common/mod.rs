//! Helpers shared by the job tests: a shipped arm set up as `emg job` sets it up, drawings read
//! and planned.
#![allow(dead_code)]

use std::path::PathBuf;

use emg_io::{Placement, read_svg_file};
use emg_job::{Job, JobFile, plan_job};
use emg_kinematics::Robot;
use emg_planner::{DataDir, Models, MotionTiming, PlanRequest, Planner, ShippedRobot};
use emg_verify::ReferenceModel;

/// The workspace's root.
pub fn workspace() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../..")
}

/// A drawing of `../shared/cases/`.
pub fn case(name: &str) -> PathBuf {
    workspace().join("../shared/cases").join(name)
}

/// A shipped arm's planner as `emg job` builds it (the cell's plate, 0.5 mm), its timing, its
/// checker and its robot file.
pub fn setup(name: &str) -> (Planner, MotionTiming, ReferenceModel, PathBuf) {
    let data = DataDir::new(workspace().join("data"));
    let shipped = ShippedRobot::by_name(name).expect("a shipped robot");
    let file = shipped.path(&data);
    let robot = Robot::from_chain_file(&file).expect("robot loads");
    let checker = ReferenceModel::from_urdf_file(&file, robot.base_link(), robot.tip_link())
        .expect("checker loads");
    let models = Models::shipped(&robot, &shipped.data_dir(&data)).expect("shipped models");
    let config = emg_job::job_config(emg_job::JOB_TOLERANCE_M);
    let timing = emg_job::job_timing(&robot, &file, &config).expect("timing");
    let planner = Planner::new(robot, models, config).expect("planner");
    (planner, timing, checker, file)
}

/// The job of the drawing `svg` placed as `placement` says, its corners rounded as `emg job`
/// rounds them at the job's tolerance.
pub fn drawing(robot: &Robot, svg: &std::path::Path, placement: &Placement) -> Job {
    let tolerance =
        emg_job::DrawingTolerance::new(emg_job::JOB_TOLERANCE_M, 0.0).expect("a tolerance");
    let drawing = read_svg_file(svg, placement, &tolerance.svg_options()).expect("the drawing");
    tolerance.job(drawing, robot).expect("a valid job")
}

/// `job` planned as `emg job` plans it.
pub fn plan(
    planner: &Planner,
    timing: &MotionTiming,
    file: &std::path::Path,
    job: &Job,
) -> JobFile {
    plan_job(
        planner,
        &PlanRequest::default(),
        job,
        timing,
        &file.display().to_string(),
        &emg_job::Unwatched,
    )
    .expect("the job plans")
}
