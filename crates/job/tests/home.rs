//! A job's program starts and ends at the arm's home, its joint values chosen among their whole
//! turns nearest the home: the UR5e, whose joints span ±2π, drawing `../shared/cases/house.svg`,
//! drawings straight ahead of it, where its base joint turns half a turn from home on the
//! branch the search finds first, and seams that no one branch draws as each stroke's search
//! finds it.

mod common;

use std::f64::consts::PI;

use emg_control::{PATH_FORMAT_VERSION, PathSpec, SegmentSpec};
use emg_io::Placement;
use emg_job::{Job, JobCheckError, JobFile, SegmentKind, verify_job};
use emg_kinematics::Vec3;
use emg_planner::ShippedRobot;

/// Asserts that every sample of `program` holds each joint within half a turn of `home`.
fn assert_within_half_a_turn_of(home: &[f64], program: &JobFile, what: &str) {
    for point in &program.points() {
        for (joint, (q, h)) in point.positions.iter().zip(home).enumerate() {
            assert!(
                (q - h).abs() <= PI,
                "{what}: joint {joint} at {q} rad, {} rad from home",
                q - h
            );
        }
    }
}

/// Asserts that no pen-up move of `program` turns a joint more than half a turn in all.
fn assert_no_move_turns_half_a_turn(program: &JobFile, what: &str) {
    for segment in &program.segments {
        if matches!(segment.kind, SegmentKind::Stroke { .. }) {
            continue;
        }
        for (joint, turned) in program.joint_travel_rad(segment).into_iter().enumerate() {
            assert!(
                turned <= PI,
                "{what}: a move at {} s turns joint {joint} by {turned} rad",
                segment.start_s
            );
        }
    }
}

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
    assert_within_half_a_turn_of(home, &program, "house");
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

#[test]
fn ur5e_drawings_half_a_turn_from_home_are_drawn_within_half_a_turn_and_no_move_turns_further() {
    let (planner, timing, checker, file) = common::setup("ur5e");
    let shipped = ShippedRobot::by_name("ur5e").expect("the UR5e");
    let home = shipped.home;
    // Planned in the joints' whole range, the pencil's base joint stood 3.19 rad from home and no
    // move back home was found; the anchor, planned within half a turn alone, flipped the wrist
    // between strokes.
    for (icon, width_m) in [("pencil.svg", 0.3), ("anchor.svg", 0.15)] {
        let placement = Placement {
            origin_m: [0.45, 0.0, 0.25],
            width_m: Some(width_m),
            ..Placement::default()
        };
        let svg = common::workspace()
            .join("crates/io/tests/data/icons")
            .join(icon);
        let job = common::drawing(planner.robot(), &svg, &placement)
            .with_home(home, planner.robot())
            .expect("the home fits");
        let program = common::plan(&planner, &timing, &file, &job);
        let summary = &program.summary;
        assert_eq!(
            summary.complete + summary.resumed,
            job.strokes.len(),
            "{icon}"
        );
        assert!(summary.ends_at_home, "{icon}");
        assert_within_half_a_turn_of(home, &program, icon);
        assert_no_move_turns_half_a_turn(&program, icon);
        verify_job(&program, &checker, planner.robot().joint_names())
            .expect("the program holds up");
    }
}

#[test]
fn ur5e_seams_that_one_branch_draws_are_all_drawn_on_it() {
    let (planner, timing, checker, file) = common::setup("ur5e");
    let home = ShippedRobot::by_name("ur5e").expect("the UR5e").home;
    // Five parallel 0.2 m seams 3 cm apart on a surface tilted 40°, as job-eval's. Each planned
    // alone, the first four took the branch nearest the home, on which the fifth cannot be
    // drawn whole: the wrist flipped before it, turning wrist 2 by 4.1 rad.
    let tilt = 40_f64.to_radians();
    let normal = Vec3::new(0.0, libm::sin(tilt), -libm::cos(tilt));
    let along = normal.cross(&Vec3::x()).normalize();
    let seams = (0..5)
        .map(|k| {
            let start = Vec3::new(0.39 + 0.03 * k as f64, 0.0, 0.25) - along * 0.1;
            PathSpec {
                version: PATH_FORMAT_VERSION,
                start: start.into(),
                normal: normal.into(),
                blend_radius_m: 0.0,
                segments: vec![SegmentSpec::Line {
                    to: (start + along * 0.2).into(),
                }],
            }
        })
        .collect();
    let job = Job::from_strokes(seams, planner.robot())
        .and_then(|job| job.with_home(home, planner.robot()))
        .expect("a valid job");
    let program = common::plan(&planner, &timing, &file, &job);
    assert_eq!(program.summary.complete, 5);
    assert!(program.summary.ends_at_home);
    assert_within_half_a_turn_of(home, &program, "seams");
    assert_no_move_turns_half_a_turn(&program, "seams");
    verify_job(&program, &checker, planner.robot().joint_names()).expect("the program holds up");
}
