//! Round trips and error messages of the trajectory formats, and the replay check of what they
//! hold.

use emg_control::{
    ClassicalController, ClassicalGains, RolloutConfig, Task, Trajectory, VelocityLimitFraction,
    rollout,
};
use emg_io::{
    FormatError, JointTrajectory, RolloutRecord, TRAJECTORY_FORMAT, TimeFromStart, TimingLimits,
    TrajectoryFile, csv_header, read_csv, trajectory_csv,
};
use emg_kinematics::{JointVector, MAX_DOF, Robot, Vec3};
use emg_timing::{DynamicLimits, TimingRequest, time_motion};
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
        Some(&file.limits.dynamics()),
    )
}

/// Velocity-limit fraction of [`planned`]: low enough to slow most steps.
const FRACTION: f64 = 0.03;

/// A short classical rollout of the demo-style task with a small fraction of the velocity
/// limits, so that most steps are slowed and the times are not uniform.
fn planned() -> (Robot, Task, RolloutConfig, Trajectory) {
    let robot = Robot::from_urdf_file(robot_path(), "link0", "pen_tip").unwrap();
    let mut config = RolloutConfig {
        max_steps: 30,
        ..RolloutConfig::default()
    };
    config.constraints.velocity_limit_fraction =
        Some(VelocityLimitFraction::new(FRACTION).unwrap());
    from_mid_range(robot, config)
}

/// A classical rollout of `robot` under `config` from the middle of its joint ranges, along
/// the line through its TCP there that runs across `y`, with the tool axis as `n`.
fn from_mid_range(robot: Robot, config: RolloutConfig) -> (Robot, Task, RolloutConfig, Trajectory) {
    let seed = robot.mid_range();
    let kin = robot.forward(&seed);
    let n = kin.tool_axis();
    let d = (Vec3::y() - n * n.y).normalize();
    let task = Task::new(&robot, kin.tcp(), d, n, Some(seed)).unwrap();
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

/// Samples per second of [`export`].
const RATE_HZ: f64 = 1000.0;

/// [`planned`] timed rest to rest within the shipped FR3 limits (velocities capped at
/// [`FRACTION`] of the robot file's, as the rollout's steps are) and written as a file.
fn export() -> (JointTrajectory, Trajectory) {
    let (robot, task, config, trajectory) = planned();
    let limits_file = robot_path().with_file_name("fr3_pen.joint_limits.yaml");
    let limits = DynamicLimits::read(&limits_file, &robot)
        .unwrap()
        .with_velocity_ceiling(&(robot.limits().velocity * FRACTION));
    let request = TimingRequest {
        limits: limits.clone(),
        tool_speed_m_per_s: 0.2,
        rate_hz: RATE_HZ,
    };
    let waypoints: Vec<JointVector> = trajectory.steps.iter().map(|s| s.q).collect();
    let motion = time_motion(&robot, &task, &config.constraints, &waypoints, &request).unwrap();
    let record = TimingLimits {
        joint_limits_file: limits_file.display().to_string(),
        velocity_scaling: 1.0,
        acceleration_scaling: 1.0,
        tool_speed_m_per_s: 0.2,
        max_velocity: limits.velocity.as_slice().to_vec(),
        max_acceleration: limits.acceleration.as_slice().to_vec(),
        max_jerk: limits.jerk.as_slice().to_vec(),
    };
    let file = JointTrajectory::new(
        "fr3_pen.urdf",
        robot.joint_names(),
        &task,
        &config.constraints,
        record,
        &motion,
        RATE_HZ,
    )
    .unwrap();
    (file, trajectory)
}

#[test]
fn json_round_trip_keeps_every_value_bit_for_bit() {
    let (file, trajectory) = export();
    let text = file.to_json();
    assert!(!text.contains('\n'));
    let back = JointTrajectory::from_json(&text).unwrap();
    assert_eq!(back, file);
    let bits = |v: &[f64]| v.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
    let (first, last) = (&back.points[0], &back.points[back.points.len() - 1]);
    assert_eq!(
        bits(&first.positions),
        bits(trajectory.steps[0].q.as_slice())
    );
    let end = trajectory.steps.last().unwrap();
    assert_eq!(bits(&last.positions), bits(end.q.as_slice()));
    for point in [first, last] {
        assert!(
            point
                .velocities
                .iter()
                .chain(&point.accelerations)
                .all(|v| *v == 0.0)
        );
    }
    for (k, point) in back.points.iter().enumerate() {
        assert_eq!(
            point.time_from_start,
            TimeFromStart::from_nanoseconds(k as u64 * 1_000_000).unwrap()
        );
    }
    let report = replay(&checker(), &back, &back.samples()).unwrap();
    assert_eq!(report.points, back.points.len());
    assert_eq!(report.max_declared_velocity_error, None);
    assert!((report.path_length_m - trajectory.path_length_m).abs() < 1e-12);
    // Joint speeds stay within the fraction of the robot file's limits the steps hold.
    let peak = report
        .peak_speed_fraction
        .iter()
        .copied()
        .fold(0.0, f64::max);
    assert!(
        peak > 0.9 * FRACTION && peak <= FRACTION * (1.0 + 1e-9),
        "{peak}"
    );
    let dynamics = report.dynamics.unwrap();
    assert!(
        dynamics
            .peak_velocity_fraction
            .iter()
            .all(|f| *f <= 1.0 + 1e-6)
    );
    assert!(
        dynamics
            .peak_acceleration_fraction
            .iter()
            .all(|f| *f <= 1.0 + 1e-6)
    );
    assert!(dynamics.peak_jerk_fraction.iter().all(|f| *f <= 1.0 + 1e-6));
}

#[test]
fn time_from_start_splits_whole_seconds() {
    let time = TimeFromStart::from_nanoseconds(2_500_000_001).unwrap();
    assert_eq!((time.sec, time.nanosec), (2, 500_000_001));
    assert_eq!(time.seconds(), 2.500000001);
    assert_eq!(TimeFromStart::from_nanoseconds(u64::MAX), None);
}

#[test]
fn csv_round_trip_keeps_times_and_positions_bit_for_bit() {
    let (_, _, _, trajectory) = planned();
    let text = trajectory_csv(&trajectory.steps, 7);
    assert!(text.starts_with(&csv_header(7)));
    assert!(text.starts_with("time_s,q1,q2,q3,q4,q5,q6,q7,qd1,"));
    let samples = read_csv(&text).unwrap();
    assert_eq!(samples.len(), trajectory.steps.len());
    for (k, step) in trajectory.steps.iter().enumerate() {
        assert_eq!(samples.time_s[k].to_bits(), step.time_s.to_bits());
        for i in 0..MAX_DOF {
            assert_eq!(samples.q[k][i].to_bits(), step.q[i].to_bits());
        }
    }
    let rule = point_velocities(&samples.time_s, &samples.q);
    assert_eq!(samples.qd.as_ref().unwrap(), &rule);
    let row = text.lines().nth(1).unwrap();
    assert_eq!(row.split(',').count(), csv_header(7).split(',').count());
    assert!(row.ends_with(",classical"));
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
    let e = error(&|d| d["format"] = "emg-joint-trajectory/1".into());
    assert!(
        e.contains("'format'") && e.contains("emg-joint-trajectory/2"),
        "{e}"
    );
    let e = error(&|d| {
        d["points"][2]
            .as_object_mut()
            .unwrap()
            .remove("accelerations");
    });
    assert!(e.contains("'points[2].accelerations' is missing"), "{e}");
    let e = error(&|d| {
        d["limits"]["max_jerk"].as_array_mut().unwrap().pop();
    });
    assert!(
        e.contains("'limits.max_jerk'") && e.contains("7 positive numbers"),
        "{e}"
    );
    let e = error(&|d| {
        d["joint_names"].as_array_mut().unwrap().pop();
    });
    assert!(
        e.contains("'limits.max_velocity'") && e.contains("expected 6 positive numbers"),
        "{e}"
    );
    let e = error(&|d| {
        d["joint_names"].as_array_mut().unwrap().truncate(5);
    });
    assert!(
        e.contains("'joint_names' has 5 entries, expected 6 or 7"),
        "{e}"
    );
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
    let text = trajectory_csv(&trajectory.steps, 7);
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
        e.starts_with("point 5: joint 4: position change") && e.contains("declared velocities"),
        "{e}"
    );

    let mut samples = file.samples();
    samples.qdd.as_mut().unwrap()[0][1] = 1e-3;
    let e = run(&samples);
    assert!(
        e.starts_with("point 0: the first point is not at rest"),
        "{e}"
    );

    // A point moved in time: its neighbours' joint speeds, from positions and times, break
    // the fraction of the limits.
    let mut samples = file.samples();
    let middle = samples.len() / 2;
    samples.time_s[middle] =
        samples.time_s[middle - 1] + 0.01 * (samples.time_s[middle] - samples.time_s[middle - 1]);
    let e = run(&samples);
    assert!(e.starts_with(&format!("point {middle}: joint")), "{e}");

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
    let csv = trajectory_csv(&trajectory.steps, 7);
    assert!(matches!(
        TrajectoryContents::parse(&csv),
        Ok(TrajectoryContents::Csv(_))
    ));
}

/// A short classical rollout of the six-joint UR5e from the middle of its joint ranges.
fn planned_on_six_joints() -> (Robot, Task, RolloutConfig, Trajectory) {
    let path = robot_path().with_file_name("ur5e_pen.urdf");
    let robot = Robot::from_urdf_file(path, "base_link", "pen_tip").unwrap();
    let config = RolloutConfig {
        max_steps: 20,
        ..RolloutConfig::default()
    };
    from_mid_range(robot, config)
}

#[test]
fn rollout_json_of_a_six_joint_arm_holds_six_values_per_joint_vector_and_reads_back() {
    let (robot, task, config, trajectory) = planned_on_six_joints();
    let file = TrajectoryFile {
        format: TRAJECTORY_FORMAT,
        robot: "ur5e_pen.urdf".into(),
        joint_names: robot.joint_names(),
        task: &task,
        seed_source: "given",
        planner: "controller",
        controller: "classical",
        config: &config,
        gains: &ClassicalGains::default(),
        steps: &trajectory.steps,
        termination: &trajectory.termination,
        path_length_m: trajectory.path_length_m,
        reachable_m: None,
        below_bound: None,
    };
    let text = file.to_json();
    // The fields keep the layout's order, the format first.
    assert!(
        text.starts_with(r#"{"format":"emg-trajectory/1","robot":"#),
        "{text}"
    );
    let doc: Value = serde_json::from_str(&text).unwrap();
    let steps = doc["steps"].as_array().unwrap();
    assert!(steps.len() > 1);
    for step in steps {
        assert_eq!(step["q"].as_array().unwrap().len(), 6);
    }
    assert_eq!(doc["task"]["q0_seed"].as_array().unwrap().len(), 6);
    let back = RolloutRecord::from_value(&doc).unwrap();
    assert_eq!(back.trajectory, trajectory);
    assert_eq!(back.task, task);

    // A step with the seventh (absent) value, or one value short, is refused by its field.
    for length in [7, 5] {
        let mut wrong = doc.clone();
        let q = wrong["steps"][1]["q"].as_array_mut().unwrap();
        q.resize(length, Value::from(0.0));
        let message = RolloutRecord::from_value(&wrong).unwrap_err().to_string();
        assert!(
            message.contains("steps[1].q") && message.contains(&format!("has {length} values")),
            "{message}"
        );
    }
}
