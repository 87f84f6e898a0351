//! The reader itself on programs and poses made by hand: the closed-form inverse kinematics
//! against the checker, rotation vectors and slerp, `movep` blends, and the parser of both
//! forms; the joint stream's reader on a motion and programs made by hand.

use std::f64::consts::PI;
use std::path::Path;

use emg_io::{JointTrajectoryPoint, TimeFromStart, TimingLimits};
use emg_kinematics::Vec3;
use emg_ur_check::{
    Form, JointPiece, PATH_STEP_M, Piece, Pose, Rotation, Statement, TimedMotion, checker_tcp,
    movej_path, movep_path, parse_program, read_servoj_motion, ur5e_flange, ur5e_inverse, wrap,
};
use emg_verify::ReferenceModel;
use rand::{RngExt, SeedableRng};
use rand_chacha::ChaCha8Rng;

/// The shipped UR5e's checker, base `base_link`, tip `pen_tip`.
fn ur5e_checker() -> ReferenceModel {
    ReferenceModel::from_urdf_file(
        &Path::new(env!("CARGO_MANIFEST_DIR")).join("../../data/robots/ur5e_pen.urdf"),
        "base_link",
        "pen_tip",
    )
    .expect("the UR5e's checker")
}

/// The shipped pen's TCP in the flange frame: 0.2034 m along its z-axis.
fn pen() -> Pose {
    Pose::from_ur(&[0.0, 0.0, 0.2034, 0.0, 0.0, 0.0])
}

#[test]
fn the_closed_form_inverse_gives_eight_configurations_of_the_checkers_pose() {
    let checker = ur5e_checker();
    let mut stream = ChaCha8Rng::seed_from_u64(0x0005_E5EE_D0FA_11CE);
    let mut eight = 0;
    for _ in 0..200 {
        let q: [f64; 6] = std::array::from_fn(|i| {
            // The elbow within ±π, as its limits; the others over a full turn and more.
            let span = if i == 2 { 3.0 } else { 6.0 };
            stream.random_range(-span..span)
        });
        let tcp = checker_tcp(&checker, &q);
        // The DH chain and the pen are the checker's tip.
        let (distance, angle) = ur5e_flange(&q).then(&pen()).difference(&tcp);
        assert!(
            distance < 1e-12 && angle < 1e-12,
            "{q:?}: {distance}, {angle}"
        );
        let flange = tcp.then(&pen().inverse());
        let solutions = ur5e_inverse(&flange);
        // Near a stretched elbow the other shoulder's or wrist's arm may fall short: 8
        // solutions, else an even number of them.
        assert!(
            [2, 4, 6, 8].contains(&solutions.len()),
            "{q:?}: {solutions:?}"
        );
        eight += usize::from(solutions.len() == 8);
        for (i, a) in solutions.iter().enumerate() {
            let (distance, angle) = checker_tcp(&checker, &a.q).difference(&tcp);
            assert!(distance < 1e-9 && angle < 1e-9, "{q:?} → {a:?}");
            for b in &solutions[i + 1..] {
                assert_ne!(a.branch, b.branch);
            }
        }
        let original = solutions
            .iter()
            .any(|s| s.q.iter().zip(&q).all(|(x, y)| wrap(x - y).abs() < 1e-7));
        assert!(original, "{q:?} is not among {solutions:?}");
    }
    assert!(eight >= 100, "8 solutions at {eight} of 200 configurations");
}

#[test]
fn rotation_vectors_round_trip_and_slerp_turns_evenly() {
    let mut stream = ChaCha8Rng::seed_from_u64(0x0000_0A11_CE5E_ED00);
    for k in 0..500 {
        let axis = Vec3::new(
            stream.random_range(-1.0..1.0),
            stream.random_range(-1.0..1.0),
            stream.random_range(-1.0..1.0),
        )
        .normalize();
        // Angles across (0, π), the last ones within 1e-9 of a half turn.
        let angle = if k < 450 {
            stream.random_range(1e-6..PI - 1e-3)
        } else {
            PI - stream.random_range(0.0..1e-9)
        };
        let rotation = Rotation::from_rotation_vector(&(axis * angle));
        let m = rotation.0;
        let orthonormal = rotation.transpose().then(&rotation);
        for (r, row) in orthonormal.0.iter().enumerate() {
            for (c, value) in row.iter().enumerate() {
                assert!((value - f64::from(u8::from(r == c))).abs() < 1e-14);
            }
        }
        assert!((rotation.apply(&axis) - axis).norm() < 1e-14);
        let back = rotation.rotation_vector();
        if angle < PI - 1e-6 {
            assert!((back - axis * angle).norm() < 1e-12, "{angle}: {back:?}");
        } else {
            // At a half turn ±axis are the same rotation.
            assert!((back.norm() - angle).abs() < 1e-9);
            let again = Rotation::from_rotation_vector(&back).0;
            for r in 0..3 {
                for c in 0..3 {
                    assert!((again[r][c] - m[r][c]).abs() < 1e-8, "{angle}");
                }
            }
        }
        // A pose in URScript's form and back.
        let values = [0.3, -0.2, 0.1, back.x, back.y, back.z];
        let pose = Pose::from_ur(&values);
        let (distance, turn) = Pose::from_ur(&pose.to_ur()).difference(&pose);
        assert!(distance == 0.0 && turn < 1e-9);
        // Slerp from a random rotation to this one: the ends, and the turn shared evenly.
        let start = Rotation::from_rotation_vector(&Vec3::new(
            stream.random_range(-1.0..1.0),
            stream.random_range(-1.0..1.0),
            stream.random_range(-1.0..1.0),
        ));
        let whole = start.angle_to(&rotation);
        assert!(start.slerp(&rotation, 0.0).angle_to(&start) < 1e-12);
        if whole < PI - 1e-3 {
            assert!(start.slerp(&rotation, 1.0).angle_to(&rotation) < 1e-12);
            for s in [0.25, 0.5, 0.9] {
                let between = start.slerp(&rotation, s);
                assert!((start.angle_to(&between) - s * whole).abs() < 1e-12);
                assert!((between.angle_to(&rotation) - (1.0 - s) * whole).abs() < 1e-12);
            }
        }
    }
}

/// A pose at `(x, y, z)` turned `angle` about z from the pen pointing down.
fn down(x: f64, y: f64, z: f64, angle: f64) -> Pose {
    Pose {
        position: Vec3::new(x, y, z),
        rotation: Rotation::from_rotation_vector(&Vec3::new(PI, 0.0, 0.0))
            .then(&Rotation::from_rotation_vector(&Vec3::new(0.0, 0.0, angle))),
    }
}

#[test]
fn a_movep_run_blends_its_corners_on_tangent_circular_arcs() {
    let start = down(0.0, 0.0, 0.1, 0.0);
    // A left turn of 90° blended 20 mm, a right turn of 90° blended 30 mm, a turn of 45°
    // blended 10 mm, and the run's end.
    let corner = down(0.1, 0.0, 0.1, 0.2);
    let second = down(0.1, 0.1, 0.1, 0.4);
    let third = down(0.2, 0.1, 0.1, 0.1);
    let end = down(0.3, 0.2, 0.1, -0.3);
    let targets = [
        (corner, 0.02, 11),
        (second, 0.03, 12),
        (third, 0.01, 13),
        (end, 0.0, 14),
    ];
    let pieces = movep_path(&start, &targets).expect("a valid run");
    let lines: Vec<usize> = pieces.iter().map(|(_, line)| *line).collect();
    assert_eq!(lines, [11, 11, 12, 12, 13, 13, 14]);
    // Each blend: its centre, radius and ends as the geometry of the corner gives them.
    let expect_arc = |piece: &Piece, centre: Vec3, radius: f64, from: Vec3, to: Vec3| {
        let Piece::Arc {
            centre: c,
            sweep_rad,
            ..
        } = piece
        else {
            panic!("{piece:?} is not an arc");
        };
        assert!((c - centre).norm() < 1e-12, "{c:?} vs {centre:?}");
        assert!((piece.at(0.0).position - from).norm() < 1e-12);
        assert!((piece.at(1.0).position - to).norm() < 1e-12);
        for sample in piece.samples() {
            assert!(((sample.position - centre).norm() - radius).abs() < 1e-12);
        }
        assert!((piece.extent().0 - radius * sweep_rad).abs() < 1e-12);
    };
    expect_arc(
        &pieces[1].0,
        Vec3::new(0.08, 0.02, 0.1),
        0.02,
        Vec3::new(0.08, 0.0, 0.1),
        Vec3::new(0.1, 0.02, 0.1),
    );
    expect_arc(
        &pieces[3].0,
        Vec3::new(0.13, 0.07, 0.1),
        0.03,
        Vec3::new(0.1, 0.07, 0.1),
        Vec3::new(0.13, 0.1, 0.1),
    );
    // The 45° corner at (0.2, 0.1): the circle's radius is r·cot(22.5°), its centre on the
    // inner side of the incoming line at the tangent point 10 mm before the corner.
    let radius = 0.01 / libm::tan(PI / 8.0);
    expect_arc(
        &pieces[5].0,
        Vec3::new(0.19, 0.1 + radius, 0.1),
        radius,
        Vec3::new(0.19, 0.1, 0.1),
        Vec3::new(0.2, 0.1, 0.1) + Vec3::new(1.0, 1.0, 0.0).normalize() * 0.01,
    );
    // The orientation at a blend's ends is the lines' slerp there, and it turns continuously.
    let on_line = |a: &Pose, b: &Pose, s: f64| a.rotation.slerp(&b.rotation, s);
    let blend = &pieces[1].0;
    assert!(
        blend
            .at(0.0)
            .rotation
            .angle_to(&on_line(&start, &corner, 0.8))
            < 1e-12
    );
    assert!(
        blend
            .at(1.0)
            .rotation
            .angle_to(&on_line(&corner, &second, 0.2))
            < 1e-12
    );
    // The path is continuous and sampled at most 0.1 mm apart.
    let mut previous = start;
    for (piece, _) in &pieces {
        for sample in piece.samples() {
            let (distance, turn) = sample.difference(&previous);
            assert!(distance <= PATH_STEP_M + 1e-12 && turn <= 1e-3 + 1e-12);
            previous = sample;
        }
    }
    assert!(previous.difference(&end).0 < 1e-12);
    // A radius over half of a line is refused at its line, and so is a blend at the end.
    let too_wide = [(corner, 0.051, 21), (second, 0.0, 22)];
    assert_eq!(
        movep_path(&start, &too_wide).expect_err("too wide").line,
        21
    );
    let blended_end = [(corner, 0.01, 31), (second, 0.01, 32)];
    assert_eq!(
        movep_path(&start, &blended_end)
            .expect_err("blended end")
            .line,
        32
    );
}

/// A program in the grammar, by hand.
const HAND_PROGRAM: &str = "# made by hand
def emg_job():
  set_tcp(p[0.0, 0.0, 0.2034, 0.0, 0.0, 0.0])
  set_standard_digital_out(0, False)  # the pen up
  home = [0.0, -1.5707963267948966, 1.5707963267948966, -1.5707963267948966, -1.5707963267948966, 0.0]
  actual = get_actual_joint_positions()
  joint = 0
  while joint < 6:
    if norm(actual[joint] - home[joint]) > 0.01:
      popup(\"not at the home # of the job\", title=\"emg\", error=True, blocking=True)
      halt
    end
    joint = joint + 1
  end
  movej([0.1, -1.5, 1.5, -1.5, -1.5, 0.0], a=1.4, v=1.05)
  movel(p[-0.4, -0.2, 0.1, 3.141592653589793, 0.0, 0.0], a=1.2, v=0.25)
  set_standard_digital_out(0, True)
  movep(p[-0.4, -0.1, 0.1, 3.141592653589793, 0.0, 0.0], a=1.2, v=0.25, r=0.002)
  movep(p[-0.3, -0.1, 0.1, 3.141592653589793, -1.2e-5, 0.0], a=1.2, v=0.25, r=0.0)
  set_standard_digital_out(0, False)
  sleep(0.1)
end
# after the program
";

#[test]
fn the_parser_reads_the_grammar_and_names_the_line_of_anything_else() {
    let program = parse_program(HAND_PROGRAM, Form::Native).expect("the hand-made program parses");
    let kinds: Vec<(usize, &str)> = program
        .statements
        .iter()
        .map(|(line, s)| {
            let kind = match s {
                Statement::SetTcp(_) => "tcp",
                Statement::DigitalOut { level: true, .. } => "on",
                Statement::DigitalOut { level: false, .. } => "off",
                Statement::HomeCheck { tolerance_rad, .. } => {
                    assert_eq!(*tolerance_rad, 0.01);
                    "home"
                }
                Statement::MoveJ { .. } => "movej",
                Statement::MoveL { .. } => "movel",
                Statement::MoveP { radius_m, .. } => {
                    assert!(*radius_m == 0.002 || *radius_m == 0.0);
                    "movep"
                }
                Statement::Sleep => "sleep",
                Statement::ServoJ { .. } | Statement::StopJ => panic!("{s:?} in a native program"),
            };
            (*line, kind)
        })
        .collect();
    assert_eq!(
        kinds,
        [
            (3, "tcp"),
            (4, "off"),
            (5, "home"),
            (15, "movej"),
            (16, "movel"),
            (17, "on"),
            (18, "movep"),
            (19, "movep"),
            (20, "off"),
            (21, "sleep"),
        ]
    );
    assert_eq!(program.code_lines, 21);
    // Each change below breaks line `line` of the program.
    for (line, from, to) in [
        (15, "movej([0.1, -1.5,", "movej([-1.5,"),
        (15, "a=1.4", "a=-1.4"),
        (16, "movel(", "servoj("),
        (18, ", r=0.002", ""),
        (19, "-1.2e-5", "1.2e-5e"),
        (9, "> 0.01", "> 0.0"),
        (11, "halt", "stop"),
        (21, "sleep(0.1)", "sleep(0.1"),
        (
            22,
            "end\n# after",
            "end\nmovej([0, 0, 0, 0, 0, 0], a=1, v=1)\n# after",
        ),
    ] {
        let broken = HAND_PROGRAM.replacen(from, to, 1);
        assert_ne!(broken, HAND_PROGRAM);
        let error = parse_program(&broken, Form::Native).expect_err(to);
        let expected = if line == 22 { 23 } else { line };
        assert_eq!(error.line, expected, "{from} → {to}: {error}");
    }
    let unclosed = HAND_PROGRAM.replace("  sleep(0.1)\nend\n", "  sleep(0.1)\n");
    assert_eq!(
        parse_program(&unclosed, Form::Native)
            .expect_err("unclosed")
            .line,
        0
    );
}

/// The joints of the hand-made motion at `t` (s) and their velocities and accelerations: each
/// joint from its start `0.1·(j + 1)` rad by `0.05·(j + 1)` rad along the quintic
/// `10τ³ − 15τ⁴ + 6τ⁵` of `τ = t / 0.2 s`, from rest to rest.
fn smooth(t: f64) -> [[f64; 6]; 3] {
    const T: f64 = 0.2;
    let tau = t / T;
    let s = [
        tau.powi(3) * (10.0 - 15.0 * tau + 6.0 * tau * tau),
        30.0 * tau * tau * (1.0 - tau) * (1.0 - tau) / T,
        60.0 * tau * (1.0 - tau) * (1.0 - 2.0 * tau) / (T * T),
    ];
    std::array::from_fn(|order| {
        std::array::from_fn(|j| {
            let amplitude = 0.05 * (j + 1) as f64;
            let start = if order == 0 {
                0.1 * (j + 1) as f64
            } else {
                0.0
            };
            start + amplitude * s[order]
        })
    })
}

/// The hand-made motion sampled every `step_ns` from 0, and at its end, 0.2 s.
fn smooth_points(step_ns: u64) -> Vec<JointTrajectoryPoint> {
    (0..200_000_000_u64.div_ceil(step_ns))
        .map(|k| k * step_ns)
        .chain([200_000_000])
        .map(|t_ns| {
            let [q, v, a] = smooth(t_ns as f64 * 1e-9);
            let rest = t_ns == 0 || t_ns == 200_000_000;
            JointTrajectoryPoint {
                positions: q.to_vec(),
                velocities: if rest { vec![0.0; 6] } else { v.to_vec() },
                accelerations: a.to_vec(),
                time_from_start: TimeFromStart::from_nanoseconds(t_ns).expect("a time"),
            }
        })
        .collect()
}

/// Limits the hand-made motion holds: 3 rad/s and 50 rad/s² per joint.
fn smooth_limits() -> TimingLimits {
    TimingLimits {
        joint_limits_file: "by hand".to_string(),
        velocity_scaling: 1.0,
        acceleration_scaling: 1.0,
        tool_speed_m_per_s: 1.0,
        max_velocity: vec![3.0; 6],
        max_acceleration: vec![50.0; 6],
        max_jerk: vec![1000.0; 6],
    }
}

/// A joint list as URScript reads it.
fn list(q: &[f64; 6]) -> String {
    let values: Vec<String> = q.iter().map(|v| format!("{v:?}")).collect();
    format!("[{}]", values.join(", "))
}

/// A joint stream of the hand-made motion written here, targets `from..=to` (each the motion
/// at `2·k` ms) after a `movej` to target `from - 1`.
fn stream(from: usize, to: usize) -> String {
    let at = |k: usize| smooth(k as f64 * 2e6 * 1e-9)[0];
    let mut text = format!(
        "# by hand\ndef emg_motion():\n  movej({}, a=1.4, v=1.05)\n",
        list(&at(from - 1))
    );
    for k in from..=to {
        text.push_str(&format!(
            "  servoj({}, 0, 0, 0.002, 0.1, 300)\n",
            list(&at(k))
        ));
    }
    text.push_str(&format!(
        "  servoj({}, 0, 0, 0.2, 0.1, 300)\n  stopj(1.4)\nend\n",
        list(&at(to))
    ));
    text
}

#[test]
fn a_joint_stream_reads_back_against_its_samples_or_the_quintic_between_them() {
    let checker = ur5e_checker();
    let limits = smooth_limits();
    let script = stream(1, 100);
    // Sampled at 1 kHz every target is a sample; at one every 3 ms two in three lie between
    // samples, on the quintic through them (which is the motion itself).
    for step_ns in [1_000_000, 3_000_000] {
        let points = smooth_points(step_ns);
        let motion = TimedMotion {
            points: &points,
            limits: &limits,
            home: None,
        };
        let report = read_servoj_motion(&[&script], &motion, &checker)
            .unwrap_or_else(|e| panic!("{step_ns}: {e}"));
        assert_eq!((report.programs, report.targets), (1, 100));
        assert!(!report.home_checked);
        assert!(report.worst_speed_fraction > 0.4 && report.worst_speed_fraction < 1.0);
        assert!(report.worst_acceleration_fraction < 1.0);
    }
    let points = smooth_points(1_000_000);
    let motion = TimedMotion {
        points: &points,
        limits: &limits,
        home: None,
    };
    let refused = |scripts: &[&str], program: Option<usize>, line: usize, why: &str| {
        let error = read_servoj_motion(scripts, &motion, &checker).expect_err(why);
        assert_eq!((error.program, error.line), (program, line), "{error}");
        assert!(error.problem.contains(why), "{error}");
    };
    // A target 1 µrad off its sample, at its line.
    let lines: Vec<&str> = script.lines().collect();
    let target = smooth(50.0 * 2e6 * 1e-9)[0];
    let mut off = target;
    off[2] += 1e-6;
    let edited = script.replacen(&list(&target), &list(&off), 1);
    let line = lines
        .iter()
        .position(|l| l.contains(&list(&target)))
        .expect("target 50")
        + 1;
    refused(
        &[&edited],
        Some(1),
        line,
        "is not the motion at t = 0.100 s",
    );
    // The stream ends early, is split where the arm moves, or stops without stopj.
    refused(&[&stream(1, 99)], Some(1), 103, "does not rest");
    refused(
        &[&stream(1, 50), &stream(51, 100)],
        Some(1),
        54,
        "does not rest",
    );
    refused(
        &[&script.replace("  stopj(1.4)\n", "")],
        Some(1),
        0,
        "does not hold its last target and stopj",
    );
    // A limit halved: the stream is refused where it first goes faster.
    let slow = TimingLimits {
        max_velocity: vec![1.5; 6],
        ..smooth_limits()
    };
    let error = read_servoj_motion(
        &[&script],
        &TimedMotion {
            limits: &slow,
            ..motion
        },
        &checker,
    )
    .expect_err("too fast");
    assert!(error.problem.contains("its limit is 1.5 rad/s"), "{error}");
    // A motion starting at the arm's home: the program must check it rather than move there.
    let home = smooth(0.0)[0];
    let at_home = TimedMotion {
        home: Some(&home),
        ..motion
    };
    let error = read_servoj_motion(&[&script], &at_home, &checker).expect_err("no home check");
    assert_eq!(error.line, 3, "{error}");
    let checked = script.replace(
        &format!("  movej({}, a=1.4, v=1.05)\n", list(&home)),
        &format!(
            "  home = {}\n  actual = get_actual_joint_positions()\n  joint = 0\n  while joint < \
             6:\n    if norm(actual[joint] - home[joint]) > 0.01:\n      popup(\"not home\", \
             title=\"emg\", error=True, blocking=True)\n      halt\n    end\n    joint = joint + \
             1\n  end\n",
            list(&home)
        ),
    );
    let report = read_servoj_motion(&[&checked], &at_home, &checker).expect("home checked");
    assert!(report.home_checked);
}

#[test]
fn each_form_refuses_the_other_forms_calls() {
    let stream_text = stream(1, 3);
    let program = parse_program(&stream_text, Form::Servoj).expect("a joint stream");
    assert_eq!(program.statements.len(), 6);
    assert!(matches!(
        program.statements[1].1,
        Statement::ServoJ { time_s, .. } if time_s == 0.002
    ));
    assert_eq!(
        parse_program(&stream_text, Form::Native)
            .expect_err("no emg_job")
            .line,
        2
    );
    let renamed = stream_text.replace("emg_motion", "emg_job");
    let error = parse_program(&renamed, Form::Native).expect_err("servoj in a native program");
    assert_eq!(error.line, 4, "{error}");
    let native = HAND_PROGRAM.replace("emg_job", "emg_motion");
    let error = parse_program(&native, Form::Servoj).expect_err("set_tcp in a joint stream");
    assert_eq!(error.line, 3, "{error}");
    // servoj's lookahead_time and gain within URScript's ranges.
    for (from, to) in [("0.1, 300", "0.01, 300"), ("0.1, 300", "0.1, 5000")] {
        let error = parse_program(&stream_text.replacen(from, to, 1), Form::Servoj)
            .expect_err("out of range");
        assert_eq!(error.line, 4, "{error}");
    }
}

#[test]
fn a_blended_movej_run_leaves_and_joins_its_lines_where_the_tcp_is_the_radius_away() {
    // A TCP that is the first three joints: distances in joint space and at the TCP agree.
    let tcp_of = |q: &[f64; 6]| Vec3::new(q[0], q[1], q[2]);
    let at = |x: f64, y: f64| [x, y, 0.0, 0.0, 0.0, 0.0];
    let start = at(0.0, 0.0);
    let targets = [(at(0.1, 0.0), 0.02, 7), (at(0.1, 0.1), 0.0, 8)];
    let pieces = movej_path(&start, &targets, &tcp_of).expect("a valid run");
    let lines: Vec<usize> = pieces.iter().map(|(_, line)| *line).collect();
    assert_eq!(lines, [7, 7, 8]);
    let JointPiece::Blend { entry, exit, .. } = pieces[1].0 else {
        panic!("{:?} is not a blend", pieces[1].0);
    };
    let near = |a: [f64; 6], b: [f64; 6]| a.iter().zip(&b).all(|(x, y)| (x - y).abs() < 1e-9);
    assert!(near(entry, at(0.08, 0.0)), "{entry:?}");
    assert!(near(exit, at(0.1, 0.02)), "{exit:?}");
    // The path is continuous: each piece starts where the one before it ends.
    let mut previous = start;
    for (piece, _) in &pieces {
        assert!(near(piece.at(0.0), previous), "{piece:?}");
        previous = piece.at(1.0);
    }
    assert!(near(previous, at(0.1, 0.1)));
    // A radius holding a whole move, overlapping blends, and a blend at a run's end are
    // refused at their lines.
    let wide = [(at(0.1, 0.0), 0.2, 11), (at(0.1, 0.1), 0.0, 12)];
    assert_eq!(
        movej_path(&start, &wide, &tcp_of).expect_err("wide").line,
        11
    );
    let overlapping = [
        (at(0.1, 0.0), 0.06, 21),
        (at(0.1, 0.1), 0.06, 22),
        (at(0.2, 0.1), 0.0, 23),
    ];
    assert_eq!(
        movej_path(&start, &overlapping, &tcp_of)
            .expect_err("overlapping")
            .line,
        22
    );
    let open = [(at(0.1, 0.0), 0.01, 31)];
    assert_eq!(
        movej_path(&start, &open, &tcp_of).expect_err("open").line,
        31
    );
}
