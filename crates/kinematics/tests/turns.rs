//! Whole turns of revolute joints: a motion moved among its 2π-equivalents toward a reference
//! configuration, within the limits, moving the tool exactly as before.

use std::f64::consts::{PI, TAU};

use emg_kinematics::{JointLimits, JointVector, Robot};

/// The UR5e's ranges: ±2π for every joint but the elbow's ±π.
fn ur5e_limits() -> JointLimits {
    let upper = JointVector::from_column_slice(&[TAU, TAU, PI, TAU, TAU, TAU, PI]);
    JointLimits {
        lower: -upper,
        upper,
        velocity: JointVector::from_element(PI),
    }
}

fn configuration(values: [f64; 6]) -> JointVector {
    let mut q = JointVector::zeros();
    q.as_mut_slice()[..6].copy_from_slice(&values);
    q
}

#[test]
fn a_motion_turns_whole_turns_toward_the_reference_within_the_limits() {
    let limits = ur5e_limits();
    let home = configuration([0.0, -PI / 2.0, 0.0, -PI / 2.0, 0.0, 0.0]);
    // Shoulder lift a turn up (5.04 = −1.24 + 2π), wrist 1 a turn down, wrist 3 near a turn
    // (6 to 6.25 rad), the elbow (±π) with no other choice.
    let start = configuration([0.3, -1.24 + TAU, 3.0, -1.0 - TAU, 0.2, 6.0]);
    let motion = [
        start,
        start + configuration([0.1, 0.1, 0.1, -0.2, 0.0, 0.25]),
    ];
    let turns = limits.turns_toward(&motion, &home);
    let expected = configuration([0.0, -TAU, 0.0, TAU, 0.0, -TAU]);
    assert_eq!(turns, expected);
    let turned: Vec<JointVector> = motion.iter().map(|q| q + turns).collect();
    for q in &turned {
        assert!(limits.first_violation(q, 0.0).is_none(), "{q}");
    }
    for (i, q) in turned[0].iter().take(6).enumerate() {
        assert!(
            (q - home[i]).abs() <= PI,
            "joint {i}: {q} vs home {}",
            home[i]
        );
    }
}

#[test]
fn a_motion_that_spans_the_range_is_not_turned() {
    let limits = ur5e_limits();
    let reference = JointVector::zeros();
    // The shoulder pan sweeps from −5 to 5.5 rad: no whole turn keeps it within ±2π.
    let motion = [
        configuration([-5.0, 0.0, 0.0, 0.0, 0.0, 4.0]),
        configuration([5.5, 0.0, 0.0, 0.0, 0.0, 4.5]),
    ];
    let turns = limits.turns_toward(&motion, &reference);
    assert_eq!(turns[0], 0.0);
    // Wrist 3 from 4 to 4.5 rad turns once down, to −2.28.
    assert!((turns[5] + TAU).abs() < 1e-15, "{}", turns[5]);
    assert_eq!(limits.turns_toward(&[], &reference), JointVector::zeros());
}

/// The shipped arms' files.
fn shipped(name: &str) -> Robot {
    let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../../data/robots")
        .join(name);
    Robot::from_file_between(path, None, None).expect("a shipped robot file loads")
}

#[test]
fn the_shipped_pens_spin_on_the_last_joint_which_moves_neither_tcp_nor_tool_axis() {
    for name in ["fr3_pen.urdf", "iiwa14_pen.urdf", "ur5e_pen.urdf"] {
        let robot = shipped(name);
        let roll = robot.tool_roll_joint();
        assert_eq!(roll, Some(robot.dof() - 1), "{name}");
        let roll = roll.unwrap();
        let limits = robot.limits();
        for share in [0.2, 0.5, 0.8] {
            let q = limits.lower + (limits.upper - limits.lower) * share;
            let mut turned = q;
            turned[roll] += 1.3;
            let (a, b) = (robot.forward(&q), robot.forward(&turned));
            assert!((a.tcp() - b.tcp()).norm() < 1e-12, "{name}");
            assert!((a.tool_axis() - b.tool_axis()).norm() < 1e-12, "{name}");
        }
    }
}

#[test]
fn a_tool_off_the_last_axis_has_no_roll_joint() {
    let path =
        std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../../data/robots/ur5e_pen.urdf");
    let text = std::fs::read_to_string(path).expect("the UR5e file reads");
    // The pen tip 1 cm off the flange axis.
    let offset = text.replace(
        "<child link=\"pen_tip\"/>\n    <origin xyz=\"0 0 0.2034\"",
        "<child link=\"pen_tip\"/>\n    <origin xyz=\"0.01 0 0.2034\"",
    );
    assert_ne!(offset, text);
    let robot = Robot::from_urdf_str(&offset, "base_link", "pen_tip").expect("the file loads");
    assert_eq!(robot.tool_roll_joint(), None);
}

#[test]
fn a_motion_sweeping_past_the_half_turn_is_turned_by_its_middle() {
    let limits = ur5e_limits();
    let reference = JointVector::zeros();
    // Wrist 3 from 2.5 to 3.8 rad: its middle, 3.15, is nearer −3.13 (a turn down), but either
    // way the motion crosses ±π; from its first value it would stay.
    let motion = [
        configuration([0.0, 0.0, 0.0, 0.0, 0.0, 2.5]),
        configuration([0.0, 0.0, 0.0, 0.0, 0.0, 3.8]),
    ];
    let turns = limits.turns_toward(&motion, &reference);
    assert!((turns[5] + TAU).abs() < 1e-15, "{}", turns[5]);
}

#[test]
fn limits_wider_than_a_turn_are_narrowed_to_a_band_about_the_reference() {
    let limits = ur5e_limits();
    let home = configuration([0.0, -PI / 2.0, 0.0, -PI / 2.0, 5.0, 0.0]);
    for w in [PI / 2.0, PI - 2e-3] {
        let band = limits.within(&home, w);
        // Every ±2π joint keeps w either side of the home, cut by its limit (wrist 2's home
        // lies near its upper limit); the elbow's ±π, no wider than a turn, is kept; so are the
        // speeds.
        let lower = configuration([-w, -PI / 2.0 - w, -PI, -PI / 2.0 - w, 5.0 - w, -w]);
        let upper = configuration([w, -PI / 2.0 + w, PI, -PI / 2.0 + w, TAU.min(5.0 + w), w]);
        for joint in 0..6 {
            assert!(
                (band.lower[joint] - lower[joint]).abs() < 1e-12,
                "joint {joint}, {w}"
            );
            assert!(
                (band.upper[joint] - upper[joint]).abs() < 1e-12,
                "joint {joint}, {w}"
            );
        }
        assert_eq!(band.velocity, limits.velocity);
    }
    // A band of half a turn narrowed again about the same reference stays as it is: its range
    // is no wider than a turn.
    let band = limits.within(&home, PI);
    assert_eq!(band.within(&home, PI / 2.0), band);
    // A reference outside a joint's limits leaves that joint as it was.
    let away = configuration([0.0, 0.0, 0.0, 0.0, 0.0, 3.0 * TAU]);
    assert_eq!(limits.within(&away, PI).lower[5], -TAU);
    // An arm whose joints all span less than a turn keeps its limits.
    for name in ["fr3_pen.urdf", "iiwa14_pen.urdf"] {
        let robot = shipped(name);
        let narrowed = robot.within(&robot.mid_range(), PI / 2.0);
        assert_eq!(narrowed.limits(), robot.limits(), "{name}");
    }
}
