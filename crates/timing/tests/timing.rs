//! Timing real rollouts of the shipped FR3 and checking the result independently: every sample
//! against the task constraints with `emg-verify`'s own kinematics, and the limits by divided
//! differences.

use std::path::PathBuf;

use emg_control::{ClassicalController, RolloutConfig, Task, rollout};
use emg_kinematics::{JointVector, Robot, Vec3};
use emg_timing::{
    DynamicLimits, GridPoint, LimitsError, Scaling, TimingRequest, first_breach, profile_duration,
    time_motion, topp_ra,
};
use emg_verify::{Bounds, Line, ReferenceModel};

fn data(file: &str) -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("../../data/robots")
        .join(file)
}

fn fr3() -> (Robot, ReferenceModel) {
    let path = data("fr3_pen.urdf");
    (
        Robot::from_urdf_file(&path, "link0", "pen_tip").unwrap(),
        ReferenceModel::from_urdf_file(&path, "link0", "pen_tip").unwrap(),
    )
}

/// A classical rollout along +y from the mid-range pose.
fn planned(robot: &Robot) -> (Task, Vec<JointVector>, RolloutConfig) {
    let seed = robot.mid_range();
    let kin = robot.forward(&seed);
    let task = Task::new(robot, kin.tcp(), Vec3::y(), kin.tool_axis(), Some(seed)).unwrap();
    let config = RolloutConfig::default();
    let trajectory = rollout(
        robot,
        &task,
        &seed,
        &mut ClassicalController::default(),
        &config,
    );
    assert!(trajectory.steps.len() > 20);
    (task, trajectory.steps.iter().map(|s| s.q).collect(), config)
}

fn shipped_limits(robot: &Robot) -> DynamicLimits {
    DynamicLimits::read(data("fr3_pen.joint_limits.yaml"), robot).unwrap()
}

#[test]
fn a_rollout_becomes_a_rest_to_rest_motion_within_every_limit() {
    let (robot, checker) = fr3();
    let (task, waypoints, config) = planned(&robot);
    let request = TimingRequest {
        limits: shipped_limits(&robot),
        tool_speed_m_per_s: 0.2,
        rate_hz: 1000.0,
    };
    let motion = time_motion(&robot, &task, &config.constraints, &waypoints, &request).unwrap();
    let samples = &motion.samples;
    let (first, last) = (&samples[0], &samples[samples.len() - 1]);
    assert_eq!(first.q, waypoints[0]);
    assert_eq!(last.q, *waypoints.last().unwrap());
    for end in [first, last] {
        assert_eq!(end.qd, JointVector::zeros());
        assert_eq!(end.qdd, JointVector::zeros());
    }
    assert!(
        samples
            .windows(2)
            .all(|w| w[1].time_ns - w[0].time_ns == 1_000_000)
    );
    assert_eq!(first_breach(samples, &request.limits), None);
    let report = &motion.report;
    assert!(report.cut.is_none(), "{report:?}");
    assert!(report.duration_s >= report.time_optimal_s);
    // The tool moves at the requested speed for most of a long, easy line.
    assert!(report.tool_speed_share > 0.5, "{report:?}");
    // Every sample holds the task's constraints by the independent checker's kinematics.
    let line = Line::straight(task.p0, task.d, task.n);
    let bounds = Bounds {
        line_tolerance_m: config.constraints.line_tolerance_m,
        theta_max_deg: config.constraints.theta_max_deg,
        collision_margin_m: config.constraints.collision_margin_m,
        velocity_limit_fraction: None,
        work_surface: None,
        obstacles: Vec::new(),
    };
    for sample in samples {
        let (tcp, axis) = checker.tcp_pose(&sample.q);
        assert!(line.lateral_distance(&tcp) <= bounds.line_tolerance_m);
        assert!(axis.angle(&task.n).to_degrees() <= bounds.theta_max_deg);
        assert!(checker.min_clearance(&sample.q).0 >= 0.0);
    }
    // Declared velocities are the derivatives of the positions (central differences).
    for w in samples.windows(3) {
        let fd = (w[2].q - w[0].q) / 2e-3;
        assert!((fd - w[1].qd).norm() < 1e-3, "{fd} vs {}", w[1].qd);
        let fd = (w[2].qd - w[0].qd) / 2e-3;
        assert!((fd - w[1].qdd).norm() < 5.0, "{fd} vs {}", w[1].qdd);
    }
}

#[test]
fn turning_the_pen_about_its_axis_while_the_tcp_stands_still_is_timed() {
    // The FR3's pen lies on its last joint's axis: turning that joint moves no TCP. Ten
    // waypoints of such a turn in the middle of a line stand for a wrist turning through a
    // singularity while the tool barely moves; the path parameter advances with the joints.
    let (robot, _) = fr3();
    let (task, waypoints, config) = planned(&robot);
    let middle = waypoints.len() / 2;
    let turn = |q: &JointVector, angle: f64| {
        let mut turned = *q;
        turned[6] += angle;
        turned
    };
    let mut turning: Vec<JointVector> = waypoints[..=middle].to_vec();
    turning.extend((1..=10).map(|i| turn(&waypoints[middle], 0.02 * f64::from(i))));
    turning.extend(waypoints[middle + 1..].iter().map(|q| turn(q, 0.2)));
    let tcp = |q: &JointVector| robot.forward(q).tcp();
    assert!((tcp(&turning[middle + 10]) - tcp(&waypoints[middle])).norm() < 1e-12);
    let request = TimingRequest {
        limits: shipped_limits(&robot),
        tool_speed_m_per_s: 0.2,
        rate_hz: 1000.0,
    };
    let plain = time_motion(&robot, &task, &config.constraints, &waypoints, &request).unwrap();
    let motion = time_motion(&robot, &task, &config.constraints, &turning, &request).unwrap();
    assert_eq!(first_breach(&motion.samples, &request.limits), None);
    assert!(motion.report.cut.is_none(), "{:?}", motion.report);
    // The turn of 0.2 rad costs a fraction of a second, not the hours a parameter of TCP
    // distance alone would give it.
    let extra = motion.report.duration_s - plain.report.duration_s;
    assert!((0.0..2.0).contains(&extra), "{extra} s");
}

#[test]
fn scaling_slows_the_motion_down() {
    let (robot, _) = fr3();
    let (task, waypoints, config) = planned(&robot);
    let time = |scaling: Scaling, tool: f64| {
        let request = TimingRequest {
            limits: shipped_limits(&robot).scaled(scaling),
            tool_speed_m_per_s: tool,
            rate_hz: 500.0,
        };
        let motion = time_motion(&robot, &task, &config.constraints, &waypoints, &request).unwrap();
        assert_eq!(first_breach(&motion.samples, &request.limits), None);
        motion.report.duration_s
    };
    let request = TimingRequest {
        limits: shipped_limits(&robot),
        tool_speed_m_per_s: 0.2,
        rate_hz: 1e8,
    };
    let error = time_motion(&robot, &task, &config.constraints, &waypoints, &request)
        .unwrap_err()
        .to_string();
    assert!(error.contains("lower the rate"), "{error}");
    let full = time(Scaling::default(), 2.0);
    let slow = time(Scaling::new(0.1, 0.05).unwrap(), 2.0);
    let slow_tool = time(Scaling::default(), 0.05);
    assert!(slow > 1.5 * full, "{slow} vs {full}");
    assert!(slow_tool > 1.5 * full, "{slow_tool} vs {full}");
}

/// On a straight joint-space path (`q'' = 0`) TOPP-RA is the bang-bang profile: accelerate at
/// the limit to the speed limit, cruise, brake. Duration `D/v + v/a` when `D > v²/a`.
#[test]
fn topp_ra_matches_the_bang_bang_optimum_on_a_straight_path() {
    let direction = JointVector::from_column_slice(&[1.0, 0.5, 0.0, 0.0, 0.0, 0.0, 0.0]);
    let (v, a, length) = (2.0, 10.0, 1.5);
    let intervals = 3000;
    let grid: Vec<GridPoint> = (0..=intervals)
        .map(|i| GridPoint {
            s: length * i as f64 / intervals as f64,
            dq: direction,
            ddq: JointVector::zeros(),
            x_max: (v / direction[0]).powi(2),
        })
        .collect();
    let x = topp_ra(&grid, &JointVector::from_element(a), &vec![1.0; grid.len()]);
    // Joint 1 moves D = 1.5 rad at most 2 rad/s and 10 rad/s².
    let expected = 1.5 / v + v / a;
    let duration = profile_duration(&grid, &x);
    assert!(
        (duration - expected).abs() < 2e-3 * expected,
        "{duration} vs {expected}"
    );
    assert_eq!((x[0], x[intervals]), (0.0, 0.0));
    assert!(
        x.iter()
            .all(|x| *x <= (v / direction[0]).powi(2) * (1.0 + 1e-12))
    );
}

#[test]
fn limits_files_name_what_is_wrong() {
    let (robot, _) = fr3();
    let limits = shipped_limits(&robot);
    assert_eq!(limits.acceleration, JointVector::from_element(10.0));
    assert_eq!(limits.jerk, JointVector::from_element(5000.0));
    assert_eq!(limits.velocity[5], 4.18);
    let iiwa = Robot::from_chain_file(data("iiwa14_pen.urdf")).unwrap();
    let iiwa_limits = DynamicLimits::read(data("iiwa14_pen.joint_limits.yaml"), &iiwa).unwrap();
    assert_eq!(iiwa_limits.velocity, iiwa.limits().velocity);

    let text = std::fs::read_to_string(data("fr3_pen.joint_limits.yaml")).unwrap();
    let error = |text: &str| {
        DynamicLimits::parse(text, "edited.yaml", &robot)
            .unwrap_err()
            .to_string()
    };
    let missing_joint = text.replace("fr3_joint4:", "fr3_joint9:");
    assert!(error(&missing_joint).contains("'joint_limits.fr3_joint4' is missing"));
    let no_jerk = text.replacen("has_jerk_limits: true", "has_jerk_limits: false", 1);
    assert!(error(&no_jerk).contains("joint_limits.fr3_joint1.has_jerk_limits' must be true"));
    let negative = text.replacen("max_acceleration: 10.0", "max_acceleration: -1", 1);
    assert!(error(&negative).contains("joint_limits.fr3_joint1.max_acceleration' is -1"));
    assert!(error("joint_limits: [1, 2").contains("not a MoveIt joint_limits.yaml"));
    assert!(matches!(
        Scaling::new(0.0, 1.0),
        Err(LimitsError::Scaling {
            field: "velocity_scaling",
            ..
        })
    ));
    assert!(matches!(
        Scaling::new(1.0, 1.5),
        Err(LimitsError::Scaling {
            field: "acceleration_scaling",
            ..
        })
    ));
}

/// A rectangle of `a × b` from the mid-range pose's TCP on its tool plane, corners unblended.
fn rectangle_task(robot: &Robot, a: f64, b: f64) -> Task {
    let seed = robot.mid_range();
    let kin = robot.forward(&seed);
    let (p, n) = (kin.tcp(), kin.tool_axis());
    let d = (Vec3::y() - n * Vec3::y().dot(&n)).normalize();
    let e = n.cross(&d);
    let line = |to: Vec3| emg_control::SegmentSpec::Line { to: to.into() };
    let spec = emg_control::PathSpec {
        version: 1,
        start: p.into(),
        normal: n.into(),
        blend_radius_m: 0.0,
        segments: vec![
            line(p + d * a),
            line(p + d * a + e * b),
            line(p + e * b),
            line(p),
        ],
    };
    Task::on_path(robot, emg_control::Path::new(spec).unwrap(), Some(seed)).unwrap()
}

#[test]
fn a_path_motion_comes_to_rest_at_every_unblended_corner_within_every_limit() {
    let (robot, checker) = fr3();
    let task = rectangle_task(&robot, 0.08, 0.05);
    let config = RolloutConfig::default();
    let seed = task.q0_seed.unwrap();
    let trajectory = rollout(
        &robot,
        &task,
        &seed,
        &mut ClassicalController::default(),
        &config,
    );
    assert_eq!(trajectory.termination, emg_control::Termination::Completed);
    let waypoints: Vec<JointVector> = trajectory.steps.iter().map(|s| s.q).collect();
    let progress = emg_timing::waypoint_progress(&robot, &task, &waypoints);
    let rests = emg_timing::rest_waypoints(&task, &progress);
    assert_eq!(rests.len(), 3, "three corners inside a closed rectangle");
    let request = TimingRequest {
        limits: shipped_limits(&robot),
        tool_speed_m_per_s: 0.2,
        rate_hz: 1000.0,
    };
    let motion = time_motion(&robot, &task, &config.constraints, &waypoints, &request).unwrap();
    assert_eq!(motion.paths.len(), 4);
    assert_eq!(first_breach(&motion.samples, &request.limits), None);
    assert!(
        motion
            .samples
            .windows(2)
            .all(|w| w[1].time_ns - w[0].time_ns == 1_000_000)
    );
    let path = task.path.as_ref().unwrap();
    for rest in rests {
        let corner = waypoints[rest];
        let at = motion
            .samples
            .iter()
            .find(|sample| sample.q == corner)
            .expect("the motion passes the corner's waypoint exactly");
        assert_eq!(at.qd, JointVector::zeros(), "at rest on the corner");
        let tcp = robot.forward(&corner).tcp();
        let nearest = path
            .corners_m()
            .map(|c| (path.point_at(c) - tcp).norm())
            .fold(f64::INFINITY, f64::min);
        assert!(nearest < 1e-3, "rest {nearest} m from a corner");
    }
    let line: Line = (&task).into();
    for sample in &motion.samples {
        let (tcp, _) = checker.tcp_pose(&sample.q);
        assert!(line.distance(&tcp) <= config.constraints.line_tolerance_m + 1e-9);
    }
    assert!(
        (line.reached(motion.samples.iter().map(|s| checker.tcp_pose(&s.q).0)) - path.length_m())
            .abs()
            < 2e-4
    );
}

/// Asserts that `again` holds the samples of `timed`: the same times, and positions, velocities
/// and accelerations within 1e-9.
fn assert_same_samples(again: &[emg_timing::TimedSample], timed: &[emg_timing::TimedSample]) {
    assert_eq!(again.len(), timed.len());
    for (a, b) in again.iter().zip(timed) {
        assert_eq!(a.time_ns, b.time_ns);
        for (x, y) in [(a.q, b.q), (a.qd, b.qd), (a.qdd, b.qdd)] {
            assert!(
                (x - y).amax() <= 1e-9,
                "at {} ns: {x:?} vs {y:?}",
                a.time_ns
            );
        }
    }
}

#[test]
fn a_motion_definition_gives_its_samples_again() {
    let (robot, _) = fr3();
    let (line, waypoints, config) = planned(&robot);
    let rectangle = rectangle_task(&robot, 0.08, 0.05);
    let seed = rectangle.q0_seed.unwrap();
    let around = rollout(
        &robot,
        &rectangle,
        &seed,
        &mut ClassicalController::default(),
        &config,
    );
    let around: Vec<JointVector> = around.steps.iter().map(|s| s.q).collect();
    for rate_hz in [1000.0, 333.0] {
        let request = TimingRequest {
            limits: shipped_limits(&robot),
            tool_speed_m_per_s: 0.2,
            rate_hz,
        };
        for (task, waypoints) in [(&line, &waypoints), (&rectangle, &around)] {
            let motion =
                time_motion(&robot, task, &config.constraints, waypoints, &request).unwrap();
            let definition = &motion.definition;
            assert_eq!(definition.check(rate_hz), Ok(()));
            assert_same_samples(&definition.samples(rate_hz), &motion.samples);
        }
        // Moves through free space, kept to their edges and blended.
        let vertices = [
            waypoints[0],
            around[around.len() / 2],
            waypoints[waypoints.len() - 1],
        ];
        let kept = emg_timing::time_free_move(&vertices, &request);
        assert_same_samples(&kept.definition.samples(rate_hz), &kept.samples);
        let blended = emg_timing::time_blended_move(&vertices, &request, 0.5).unwrap();
        assert_same_samples(&blended.definition.samples(rate_hz), &blended.samples);
    }
}
