//! The corrected step (`Tracking::Corrected`) against the paper's (`Tracking::FirstOrder`).
//!
//! - On a circle the paper's explicit step follows the tangent: each step of length
//!   `h = v Δt` lands `h² / 2R` off the circle (the curvature term), which the lateral gain only
//!   works off over later steps, so its error is never below that term; at 0.1 mm, five times
//!   below it, the paper's step stops within a few steps, the corrected step goes round with
//!   every step within half the tolerance and the independent checker agrees.
//! - Where the paper's step tracks within half the tolerance (the 20 mm benchmark's lines), the
//!   corrected step is the paper's, bit for bit.
//! - On lines at 0.1 mm, the tolerance ends most motions of the paper's step and at most a
//!   quarter as many of the corrected step's, every one of them checked, and they go further.
//! - Near a singularity, where the step's own damping would leave most of an offset in place,
//!   the corrections (the Jacobian at each corrected configuration, lightly damped) still bring
//!   the TCP onto the line.

mod common;

use emg_control::{
    CORRECTION_TRIGGER, CheckRollout, MAX_CORRECTIONS, Path, PathSpec, RolloutConfig, SegmentSpec,
    Task, Termination, Tracking, Trajectory, correct_onto_task,
};
use emg_kinematics::{DampingConfig, damped_pseudo_inverse};

use common::{checker, classical, random_q, rng, robot, tasks};

const RADIUS_M: f64 = 0.1;

fn config(tolerance_m: f64, tracking: Tracking) -> RolloutConfig {
    let mut config = RolloutConfig {
        tracking,
        ..RolloutConfig::default()
    };
    config.constraints.line_tolerance_m = tolerance_m;
    config
}

/// The largest distance of a recorded TCP from the task's line or path.
fn largest_error(task: &Task, trajectory: &Trajectory) -> f64 {
    trajectory
        .steps
        .iter()
        .map(|step| task.distance(&step.tcp))
        .fold(0.0, f64::max)
}

/// A full circle of radius [`RADIUS_M`] from the first sampled task's start, on its surface,
/// starting along its direction.
fn circle() -> (emg_kinematics::Robot, Task) {
    let robot = robot();
    let (_, task) = tasks(&robot, 1).remove(0);
    let centre = task.p0 + task.n.cross(&task.d) * RADIUS_M;
    let spec = PathSpec {
        version: 1,
        start: task.p0.into(),
        normal: task.n.into(),
        blend_radius_m: 0.0,
        segments: vec![SegmentSpec::Arc {
            centre: Some(centre.into()),
            through: None,
            to: None,
            sweep_deg: Some(360.0),
        }],
    };
    let on_circle = Task::on_path(&robot, Path::new(spec).unwrap(), task.q0_seed).unwrap();
    (robot, on_circle)
}

#[test]
fn on_a_circle_the_paper_step_errs_by_its_curvature_term_and_the_corrected_step_holds_a_tenth_of_a_millimetre()
 {
    let (robot, task) = circle();
    let loose = config(0.02, Tracking::FirstOrder);
    let step_m = loose.speed_m_per_s * loose.dt_s;
    let curvature_term_m = step_m * step_m / (2.0 * RADIUS_M);

    let paper = classical(&robot, &task, &loose);
    checker().check(&task, &paper, &loose.constraints).unwrap();
    assert_eq!(paper.termination, Termination::Completed);
    let paper_error = largest_error(&task, &paper);
    assert!(
        paper_error >= curvature_term_m,
        "the paper's step errs {paper_error} m on a circle, less than h²/2R = {curvature_term_m} m"
    );

    let tight = 1e-4;
    assert!(tight < curvature_term_m / 4.0);
    let paper_tight = classical(&robot, &task, &config(tight, Tracking::FirstOrder));
    assert_eq!(paper_tight.termination.label(), "line_tolerance");
    assert!(
        paper_tight.path_length_m < 0.05,
        "{}",
        paper_tight.path_length_m
    );

    let corrected_config = config(tight, Tracking::Corrected);
    let corrected = classical(&robot, &task, &corrected_config);
    checker()
        .check(&task, &corrected, &corrected_config.constraints)
        .unwrap();
    assert_eq!(corrected.termination, Termination::Completed);
    let corrected_error = largest_error(&task, &corrected);
    assert!(
        corrected_error <= CORRECTION_TRIGGER * tight,
        "the corrected step errs {corrected_error} m"
    );
}

#[test]
fn where_the_paper_step_tracks_within_half_the_tolerance_the_corrected_step_is_the_same() {
    let robot = robot();
    let paper_config = config(0.02, Tracking::FirstOrder);
    let corrected_config = config(0.02, Tracking::Corrected);
    let mut compared = 0;
    for (_, task) in tasks(&robot, 24) {
        let paper = classical(&robot, &task, &paper_config);
        // Compare the motions whose every step, the rejected last one included, tracked.
        let rejected_error = match &paper.termination {
            Termination::Violation { rejected_q, .. } => {
                task.distance(&robot.forward(rejected_q).tcp())
            }
            _ => 0.0,
        };
        if largest_error(&task, &paper).max(rejected_error) > CORRECTION_TRIGGER * 0.02 {
            continue;
        }
        let corrected = classical(&robot, &task, &corrected_config);
        assert_eq!(corrected, paper, "task {task:?}");
        compared += 1;
    }
    assert!(compared >= 12, "{compared} motions compared");
}

#[test]
fn on_lines_at_a_tenth_of_a_millimetre_the_tolerance_ends_few_corrected_motions() {
    let robot = robot();
    let tight = 1e-4;
    let (mut paper_ended, mut corrected_ended, mut longer) = (0, 0, 0.0);
    let sampled = tasks(&robot, 16);
    for (_, task) in &sampled {
        let paper = classical(&robot, task, &config(tight, Tracking::FirstOrder));
        let corrected_config = config(tight, Tracking::Corrected);
        let corrected = classical(&robot, task, &corrected_config);
        checker()
            .check(task, &corrected, &corrected_config.constraints)
            .unwrap();
        paper_ended += usize::from(paper.termination.label() == "line_tolerance");
        corrected_ended += usize::from(corrected.termination.label() == "line_tolerance");
        longer += corrected.path_length_m - paper.path_length_m;
    }
    assert!(
        paper_ended * 2 > sampled.len(),
        "the paper's step: {paper_ended} of {} ended by the tolerance",
        sampled.len()
    );
    assert!(
        corrected_ended * 4 <= paper_ended,
        "the corrected step: {corrected_ended} ended by the tolerance, the paper's {paper_ended}"
    );
    assert!(longer > 0.0);
}

#[test]
fn near_a_singularity_the_corrections_converge_where_the_steps_damping_would_not() {
    let robot = robot();
    let damping = DampingConfig::default();
    // The first of a seeded draw of configurations whose Jacobian's smallest singular value
    // lies well inside the step's damped band, `σ_min < σ_0`.
    let mut draw = rng(54);
    let (q, eigen) = std::iter::repeat_with(|| random_q(&mut draw, &robot))
        .take(1_000_000)
        .map(|q| (q, robot.forward(&q).jacobian_gram().symmetric_eigen()))
        .find(|(_, eigen)| {
            let sigma_min = eigen.eigenvalues.min().max(0.0).sqrt();
            (0.2 * damping.sigma_threshold..0.4 * damping.sigma_threshold).contains(&sigma_min)
        })
        .expect("a configuration near a singularity");
    let kinematics = robot.forward(&q);
    let weakest = eigen.eigenvalues.imin();
    // Lines 1 mm from the TCP on either side, along the direction the arm moves it least.
    let weak = eigen.eigenvectors.column(weakest).into_owned();
    let n = kinematics.tool_axis();
    let d = n.cross(&weak).normalize();
    let offset_m = 1e-3;
    // Half of a 0.1 mm tolerance, where the corrected step stops correcting.
    let target_m = CORRECTION_TRIGGER * 1e-4;
    let step_inverse = damped_pseudo_inverse(kinematics.jacobian(), &damping);
    for side in [1.0, -1.0] {
        let task = Task::new(
            &robot,
            kinematics.tcp() + weak * side * offset_m,
            d,
            n,
            None,
        )
        .unwrap();
        assert!((task.distance(&kinematics.tcp()) - offset_m).abs() < 1e-9);

        let mut corrected = q;
        let mut at = kinematics.clone();
        assert!(correct_onto_task(
            &robot,
            &task,
            0.0,
            target_m,
            &mut corrected,
            &mut at
        ));
        assert!(task.distance(&at.tcp()) <= target_m);
        let moved = (corrected - q).amax();
        assert!(moved < 0.15, "the corrections moved a joint {moved} rad");

        // The step's own pseudo-inverse, as many times, leaves most of the offset.
        let mut chord = q;
        for _ in 0..MAX_CORRECTIONS {
            chord += step_inverse.matrix * task.offset(&robot.forward(&chord).tcp());
        }
        let left = task.distance(&robot.forward(&chord).tcp());
        assert!(left > 0.5 * offset_m, "the step's damping left {left} m");
    }
}
