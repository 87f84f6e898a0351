//! The program file (`emg-job/3`): it holds what defines the motion, not its samples; read back,
//! it gives the samples its motion was timed with; a program of another version, or a motion
//! that cannot be sampled, is refused naming what is wrong.

mod common;

use emg_io::{Placement, SvgOptions, read_svg_file};
use emg_job::{JOB_FILE_FORMAT, Job, JobFile, Motion, SegmentKind};
use emg_kinematics::JointVector;
use emg_timing::{TimedSample, time_blended_move, time_free_move};

#[test]
fn a_program_read_back_gives_the_samples_its_motion_was_timed_with() {
    let (planner, timing, _, file) = common::setup("fr3");
    let icon = common::workspace().join("crates/io/tests/data/icons/pencil.svg");
    let strokes = read_svg_file(&icon, &Placement::default(), &SvgOptions::default())
        .expect("icon")
        .strokes;
    let job = Job::from_strokes(strokes, planner.robot()).expect("a valid job");
    let program = common::plan(&planner, &timing, &file, &job);
    let text = serde_json::to_string(&program).expect("a program serialises");
    let read = JobFile::parse(&text).expect("the program reads back");
    assert_eq!(read, program, "the file holds the program exactly");
    let points = read.points();
    // One sample per period from rest to rest.
    assert_eq!(read.format, JOB_FILE_FORMAT);
    let duration_s = program.summary.duration_s;
    assert_eq!(
        points.len() as f64,
        (duration_s * read.rate_hz).round() + 1.0
    );
    // The file grows with the motion's paths, not its duration: far less than the samples'
    // 490 kB a second.
    let per_s = text.len() as f64 / duration_s;
    assert!(per_s < 20_000.0, "{per_s:.0} bytes a second of program");
    // Each move's samples are those its vertices are timed with, to 1e-9 rad.
    let robot = planner.robot();
    let times: Vec<u64> = points.iter().map(nanoseconds).collect();
    let mut moves = 0;
    for segment in &read.segments {
        let vertices: Vec<JointVector> = segment
            .vertices
            .iter()
            .map(|q| robot.joint_vector(q))
            .collect();
        let timed = match &segment.motion {
            Motion::Splines { .. } => continue,
            Motion::Polyline { .. } => time_free_move(&vertices, timing.request()).samples,
            Motion::Blended { share, .. } => {
                time_blended_move(&vertices, timing.request(), *share)
                    .expect("a blended move")
                    .samples
            }
        };
        moves += 1;
        let start_ns = (segment.start_s * 1e9).round() as u64;
        let first = times.partition_point(|t| *t < start_ns);
        assert_eq!(times[first], start_ns);
        assert_same_samples(&points[first..first + timed.len()], &timed, start_ns);
    }
    assert!(
        moves > 2
            && program
                .segments
                .iter()
                .any(|s| s.kind == SegmentKind::Travel)
    );
    // A motion that cannot be sampled is refused naming the segment and the field.
    let stroke = program
        .segments
        .iter()
        .position(|s| matches!(s.kind, SegmentKind::Stroke { .. }))
        .expect("a stroke segment");
    let refused = |edit: &dyn Fn(&mut serde_json::Value)| {
        let mut value = serde_json::to_value(&program).expect("a program serialises");
        edit(&mut value);
        JobFile::parse(&value.to_string()).unwrap_err().to_string()
    };
    let error = refused(&|v| {
        let knots = &mut v["segments"][stroke]["motion"]["stretches"][0]["knots"];
        knots[1] = knots[0].clone();
    });
    assert!(
        error.contains(&format!("segments[{stroke}].motion.stretches[0].knots")),
        "{error}"
    );
    let error = refused(&|v| {
        v["segments"][stroke]["motion"]["stretches"][0]["profile"]["x"][1] = (-1.0).into()
    });
    assert!(
        error.contains(&format!(
            "segments[{stroke}].motion.stretches[0].profile: x"
        )),
        "{error}"
    );
    let error = refused(&|v| v["rate_hz"] = 0.0.into());
    assert!(error.contains("rate_hz"), "{error}");
}

/// The time of `point` (ns from the start).
fn nanoseconds(point: &emg_io::JointTrajectoryPoint) -> u64 {
    let time = &point.time_from_start;
    u64::try_from(time.sec).expect("a time after the start") * 1_000_000_000
        + u64::from(time.nanosec)
}

/// Asserts that `points` (from `start_ns`) are the samples `timed` (from 0), to 1e-9.
fn assert_same_samples(
    points: &[emg_io::JointTrajectoryPoint],
    timed: &[TimedSample],
    start_ns: u64,
) {
    assert_eq!(points.len(), timed.len());
    for (point, sample) in points.iter().zip(timed) {
        let at = nanoseconds(point);
        assert_eq!(at, start_ns + sample.time_ns);
        for (values, vector) in [
            (&point.positions, sample.q),
            (&point.velocities, sample.qd),
            (&point.accelerations, sample.qdd),
        ] {
            for (j, value) in values.iter().enumerate() {
                assert!((value - vector[j]).abs() <= 1e-9, "at {at} ns, joint {j}");
            }
        }
    }
}

#[test]
fn a_program_of_another_version_is_refused_naming_it() {
    let old = r#"{"format": "emg-job/2", "points": []}"#;
    let error = JobFile::parse(old).unwrap_err().to_string();
    assert!(
        error.contains("emg-job/2") && error.contains(JOB_FILE_FORMAT),
        "{error}"
    );
}
