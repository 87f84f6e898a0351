//! Round trips and error messages of the trajectory formats, and the replay check of what they
//! hold.

use emg_control::{
    ClassicalController, RolloutConfig, Task, Trajectory, VelocityLimitFraction, rollout,
};
use emg_io::{
    CSV_HEADER, FormatError, JointTrajectory, TimeFromStart, read_csv, times_from_start,
    trajectory_csv,
};
use emg_kinematics::{DOF, Robot, Vec3};
use emg_verify::{JointSamples, ReferenceModel, check_joint_names, check_replay, point_velocities};
use serde_json::Value;

fn robot_path() -> std::path::PathBuf {
    std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../../data/robots/fr3_pen.urdf")
}

/// The replay check of `samples` against the file's own task and constraints.
fn replay(
    model: &ReferenceModel,
    file: &JointTrajectory,
    samples: &JointSamples,
) -> Result<emg_verify::ReplayReport, emg_verify::ReplayError> {
    check_replay(
        model,
        &(&file.task).into(),
        &(&file.constraints).into(),
        samples,
        None,
    )
}

/// Velocity-limit fraction of [`planned`]: low enough to slow most steps.
const FRACTION: f64 = 0.03;

/// A short classical rollout of the demo-style task with a small fraction of the velocity
/// limits, so that most steps are slowed and the times are not uniform.
fn planned() -> (Robot, Task, RolloutConfig, Trajectory) {
    let robot = Robot::from_urdf_file(robot_path(), "link0", "pen_tip").unwrap();
    let seed = robot.mid_range();
    let kin = robot.forward(&seed);
    let n = kin.tool_axis();
    let d = (Vec3::y() - n * n.y).normalize();
    let task = Task::new(&robot, kin.tcp(), d, n, Some(seed)).unwrap();
    let mut config = RolloutConfig {
        max_steps: 30,
        ..RolloutConfig::default()
    };
    config.constraints.velocity_limit_fraction =
        Some(VelocityLimitFraction::new(FRACTION).unwrap());
    let trajectory = rollout(
        &robot,
        &task,
        &seed,
        &mut ClassicalController::default(),
        &config,
    );
    (robot, task, config, trajectory)
}

fn checker() -> ReferenceModel {
    ReferenceModel::from_urdf_file(&robot_path(), "link0", "pen_tip").unwrap()
}

fn export() -> (JointTrajectory, Trajectory) {
    let (robot, task, config, trajectory) = planned();
    let file = JointTrajectory::new(
        "fr3_pen.urdf",
        robot.joint_names(),
        &task,
        &config.constraints,
        &trajectory,
    )
    .unwrap();
    (file, trajectory)
}

#[test]
fn json_round_trip_keeps_every_position_bit_for_bit() {
    let (file, trajectory) = export();
    let gaps: Vec<f64> = trajectory
        .steps
        .windows(2)
        .map(|w| w[1].time_s - w[0].time_s)
        .collect();
    assert!(
        gaps.iter().any(|g| (g - 0.05).abs() > 1e-6),
        "the slowed steps make the times non-uniform: {gaps:?}"
    );
    let text = file.to_json();
    assert!(!text.contains('\n'));
    let back = JointTrajectory::from_json(&text).unwrap();
    assert_eq!(back, file);
    assert_eq!(back.points.len(), trajectory.steps.len());
    for (point, step) in back.points.iter().zip(&trajectory.steps) {
        let bits = |v: &[f64]| v.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
        assert_eq!(bits(&point.positions), bits(step.q.as_slice()));
        // Never shorter than planned, at most 1 ns per point later.
        let drift = point.time_from_start.seconds() - step.time_s;
        assert!(drift > -1e-12 && drift < 1e-9 * trajectory.steps.len() as f64);
    }
    let report = replay(&checker(), &back, &back.samples()).unwrap();
    assert_eq!(report.points, trajectory.steps.len());
    assert_eq!(report.max_declared_velocity_error, Some(0.0));
    assert!((report.path_length_m - trajectory.path_length_m).abs() < 1e-12);
    let peak = report
        .peak_speed_fraction
        .iter()
        .copied()
        .fold(0.0, f64::max);
    assert!(
        peak > 0.99 * FRACTION && peak <= FRACTION * (1.0 + 1e-9),
        "{peak}"
    );
    // The first and last points move at their segment's speed, within the peak.
    let [first, last] = report.boundary_speed_fraction;
    assert!(first > 0.0 && first <= peak && last > 0.0 && last <= peak);
    assert!(report.peak_acceleration_rad_s2.iter().all(|a| *a > 0.0));
}

#[test]
fn csv_round_trip_keeps_times_and_positions_bit_for_bit() {
    let (_, _, _, trajectory) = planned();
    let text = trajectory_csv(&trajectory.steps);
    assert!(text.starts_with(CSV_HEADER));
    let samples = read_csv(&text).unwrap();
    assert_eq!(samples.len(), trajectory.steps.len());
    for (k, step) in trajectory.steps.iter().enumerate() {
        assert_eq!(samples.time_s[k].to_bits(), step.time_s.to_bits());
        for i in 0..DOF {
            assert_eq!(samples.q[k][i].to_bits(), step.q[i].to_bits());
        }
    }
    let rule = point_velocities(&samples.time_s, &samples.q);
    assert_eq!(samples.qd.as_ref().unwrap(), &rule);
    let row = text.lines().nth(1).unwrap();
    assert_eq!(row.split(',').count(), CSV_HEADER.split(',').count());
    assert!(row.ends_with(",classical"));
}

#[test]
fn times_are_rounded_up_per_gap_to_whole_nanoseconds() {
    // Accumulated 0.05 s steps land exactly on the grid despite float noise.
    let mut t = vec![0.0];
    for _ in 0..10 {
        t.push(t.last().unwrap() + 0.05);
    }
    t.push(t.last().unwrap() + 1.0 / 30.0);
    let times = times_from_start(&t).unwrap();
    assert_eq!(
        times[10],
        TimeFromStart {
            sec: 0,
            nanosec: 500_000_000
        }
    );
    assert_eq!(
        times[11],
        TimeFromStart {
            sec: 0,
            nanosec: 533_333_334
        }
    );
    for k in 1..t.len() {
        assert!(times[k].seconds() - times[k - 1].seconds() >= (t[k] - t[k - 1]) - 1e-12);
    }
    let error = times_from_start(&[0.0, 0.1, 0.1]).unwrap_err().to_string();
    assert!(
        error.contains("points[2]") && error.contains("does not come after"),
        "{error}"
    );
    let error = times_from_start(&[-0.1]).unwrap_err().to_string();
    assert!(error.contains("points[0]"), "{error}");
}

#[test]
fn malformed_json_names_the_field() {
    let (file, _) = export();
    let good: Value = serde_json::from_str(&file.to_json()).unwrap();
    let error = |edit: &dyn Fn(&mut Value)| {
        let mut doc = good.clone();
        edit(&mut doc);
        JointTrajectory::from_json(&doc.to_string())
            .unwrap_err()
            .to_string()
    };
    let e = error(&|d| d["format"] = "emg-trajectory/1".into());
    assert!(
        e.contains("'format'") && e.contains("emg-joint-trajectory/1"),
        "{e}"
    );
    let e = error(&|d| {
        d["joint_names"].as_array_mut().unwrap().pop();
    });
    assert!(e.contains("'joint_names' has 6 entries, expected 7"), "{e}");
    let e = error(&|d| {
        d["points"][1]["positions"].as_array_mut().unwrap().pop();
    });
    assert!(e.contains("'points[1].positions' has 6 values"), "{e}");
    let e = error(&|d| d["points"][0]["velocities"][2] = "fast".into());
    assert!(
        e.contains("'points[0].velocities[2]'") && e.contains("\"fast\""),
        "{e}"
    );
    let e = error(&|d| d["points"][3]["time_from_start"]["nanosec"] = 1_000_000_000.into());
    assert!(e.contains("'points[3].time_from_start.nanosec'"), "{e}");
    let e = error(&|d| {
        d.as_object_mut().unwrap().remove("constraints");
    });
    assert!(e.contains("'constraints' is missing"), "{e}");
    let e = error(&|d| d["constraints"]["velocity_limit_fraction"] = 2.0.into());
    assert!(
        e.contains("'constraints'") && e.contains("velocity_limit_fraction"),
        "{e}"
    );
    assert!(matches!(
        JointTrajectory::from_json("{\"format\": "),
        Err(FormatError::Json(_))
    ));
}

#[test]
fn malformed_csv_names_line_and_column() {
    let (_, _, _, trajectory) = planned();
    let text = trajectory_csv(&trajectory.steps);
    let bad = text.replacen("0.0,", "zero,", 1);
    let e = read_csv(&bad).unwrap_err().to_string();
    assert_eq!(
        e,
        "CSV line 2, column 1 ('time_s'): 'zero' is not a finite number"
    );
    let mut lines: Vec<String> = text.lines().map(str::to_string).collect();
    let mut cells: Vec<String> = lines[3].split(',').map(str::to_string).collect();
    cells[9] = "NaN".into();
    lines[3] = cells.join(",");
    let e = read_csv(&lines.join("\n")).unwrap_err().to_string();
    assert!(e.starts_with("CSV line 4, column 10 ('qd2')"), "{e}");
    let old_header = text.replacen("qd1,qd2,qd3,qd4,qd5,qd6,qd7,", "", 1);
    let e = read_csv(&old_header).unwrap_err().to_string();
    assert!(e.contains("column 9 is 'tcp_x', expected 'qd1'"), "{e}");
}

#[test]
fn check_replay_blames_the_point_and_the_constraint() {
    let (file, _) = export();
    let model = checker();
    let run = |samples: &JointSamples| replay(&model, &file, samples).unwrap_err().to_string();
    let mut samples = file.samples();
    samples.qd.as_mut().unwrap()[5][3] += 0.01;
    let e = run(&samples);
    assert!(
        e.starts_with("point 5: declared velocity of joint 4"),
        "{e}"
    );

    let mut samples = file.samples();
    samples.time_s[7] = samples.time_s[6] + 0.5 * (samples.time_s[7] - samples.time_s[6]);
    let e = run(&samples);
    assert!(
        e.starts_with("point 7: joint") && e.contains("rad/s, above"),
        "{e}"
    );

    let mut samples = file.samples();
    samples.time_s[4] = samples.time_s[3];
    assert!(run(&samples).starts_with("point 4: timestamps must increase"));

    let mut names = file.joint_names.clone();
    names.swap(0, 1);
    let e = check_joint_names(&names, &file.joint_names)
        .unwrap_err()
        .to_string();
    assert!(e.contains("same order"), "{e}");
    assert!(check_joint_names(&file.joint_names, &file.joint_names).is_ok());
}

#[test]
fn files_are_told_apart_by_content_and_json_errors_give_their_position() {
    use emg_io::TrajectoryContents;
    // Not valid JSON: the JSON reader's own error, with its line and column.
    let error = TrajectoryContents::parse("{\"format\": ")
        .unwrap_err()
        .to_string();
    assert!(
        error.starts_with("not valid JSON") && error.contains("line 1 column"),
        "{error}"
    );
    let error = TrajectoryContents::parse("[1, 2").unwrap_err().to_string();
    assert!(error.starts_with("not valid JSON"), "{error}");
    // Neither JSON nor the CSV: said so, with what the file opens with.
    let error = TrajectoryContents::parse("hello, world")
        .unwrap_err()
        .to_string();
    assert!(
        error.contains("not a trajectory file") && error.contains("hello"),
        "{error}"
    );
    // The CSV is recognised by its header.
    let (_, _, _, trajectory) = planned();
    let csv = trajectory_csv(&trajectory.steps);
    assert!(matches!(
        TrajectoryContents::parse(&csv),
        Ok(TrajectoryContents::Csv(_))
    ));
}
