//! A job's program starts and ends at the arm's home, its joint values chosen among their whole
//! turns nearest the home: the UR5e, whose joints span ±2π, drawing `../shared/cases/house.svg`.

mod common;

use std::f64::consts::PI;

use emg_io::Placement;
use emg_job::{JobCheckError, verify_job};
use emg_planner::ShippedRobot;

#[test]
fn the_ur5e_house_starts_and_ends_at_home_every_joint_within_half_a_turn_of_it() {
    let (planner, timing, checker, file) = common::setup("ur5e");
    let shipped = ShippedRobot::by_name("ur5e").expect("the UR5e");
    let job = common::drawing(
        planner.robot(),
        &common::case("house.svg"),
        &Placement::default(),
    )
    .with_home(shipped.home, planner.robot())
    .expect("the home fits");
    let program = common::plan(&planner, &timing, &file, &job);
    let home = shipped.home;
    assert_eq!(program.home.as_deref(), Some(home));
    assert!(program.summary.ends_at_home);
    let points = program.points();
    let first = &points[0].positions;
    let last = &points[points.len() - 1].positions;
    assert_eq!((first.as_slice(), last.as_slice()), (home, home));
    for point in &points {
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
