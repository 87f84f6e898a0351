//! Whole turns of revolute joints: a motion moved among its 2π-equivalents toward a reference
//! configuration, within the limits, moving the tool exactly as before.

use std::f64::consts::{PI, TAU};

use emg_kinematics::{JointLimits, JointVector};

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
