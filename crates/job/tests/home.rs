//! A job's program starts and ends at the arm's home, its joint values chosen among their whole
//! turns nearest the home: the UR5e, whose joints span ±2π, drawing `../shared/cases/house.svg`.

use std::f64::consts::PI;
use std::path::PathBuf;

use emg_io::{Placement, SvgOptions, read_svg_file};
use emg_job::{Job, JobCheckError, plan_job, verify_job};
use emg_kinematics::Robot;
use emg_planner::{DataDir, Models, PlanRequest, Planner, ShippedRobot};
use emg_verify::ReferenceModel;

fn workspace() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../..")
}

#[test]
fn the_ur5e_house_starts_and_ends_at_home_every_joint_within_half_a_turn_of_it() {
    let data = DataDir::new(workspace().join("data"));
    let shipped = ShippedRobot::by_name("ur5e").expect("the UR5e");
    let file = shipped.path(&data);
    let robot = Robot::from_chain_file(&file).expect("robot loads");
    let checker = ReferenceModel::from_urdf_file(&file, robot.base_link(), robot.tip_link())
        .expect("checker loads");
    let models = Models::shipped(&robot, &shipped.data_dir(&data)).expect("shipped models");
    let config = emg_job::job_config(emg_job::JOB_TOLERANCE_M);
    let timing = emg_job::job_timing(&robot, &file, &config).expect("timing");
    let strokes = read_svg_file(
        &workspace().join("../shared/cases/house.svg"),
        &Placement::default(),
        &SvgOptions::default(),
    )
    .expect("the drawing")
    .strokes;
    let job = Job::from_strokes(strokes, &robot)
        .and_then(|job| job.with_home(shipped.home, &robot))
        .expect("a valid job");
    let planner = Planner::new(robot, models, config).expect("planner");
    let program = plan_job(
        &planner,
        &PlanRequest::default(),
        &job,
        &timing,
        &file.display().to_string(),
        &|_, _| {},
    )
    .expect("the job plans");
    let home = shipped.home;
    assert_eq!(program.home.as_deref(), Some(home));
    assert!(program.summary.ends_at_home);
    let first = &program.points[0].positions;
    let last = &program.points[program.points.len() - 1].positions;
    assert_eq!((first.as_slice(), last.as_slice()), (home, home));
    for point in &program.points {
        for (joint, (q, h)) in point.positions.iter().zip(home).enumerate() {
            assert!(
                (q - h).abs() <= PI,
                "joint {joint} at {q} rad, {} rad from home",
                q - h
            );
        }
    }
    let joints = planner.robot().joint_names();
    verify_job(&program, &checker, joints).expect("the program holds up");
    // A program said to start at home that starts elsewhere is refused.
    let mut elsewhere = program.clone();
    elsewhere.home.as_mut().expect("a home")[0] += 0.1;
    let error = verify_job(&elsewhere, &checker, joints).unwrap_err();
    assert!(
        matches!(&error, JobCheckError::Summary(why) if why.contains("does not start at its home")),
        "{error}"
    );
}
